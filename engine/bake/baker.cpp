#include "layout/bake_mesh_gl.h"
#include "bake/baker.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <numeric>

#include "bake/bundle_tracer.h"
#include "bake/directions.h"
#include "core/check.h"
#include "core/log.h"
#include "core/memory.h"
#include "gl/gl.h"
#include <glm/gtc/matrix_transform.hpp>
#include "gl/objects.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "importance/importance_gl.h"
#include "tiler/tiler.h"

namespace bb {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }


// Per texel of every page, the covered texel whose value it shows: itself if
// covered, else the nearest covered texel within `radius` texels (Chebyshev
// rings, Euclidean nearest, ties to the lowest index), else -1. Packed x | y << 16.
std::vector<int32_t> dilationSources(const std::vector<uint8_t>& covered, int res, int pages, int radius) {
    std::vector<int32_t> source(covered.size(), -1);
    for (int p = 0; p < pages; ++p) {
        const size_t base = size_t(p) * res * res;
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                if (covered[base + size_t(y) * res + x]) {
                    source[base + size_t(y) * res + x] = x | (y << 16);
                    continue;
                }
                int best = -1, bestD2 = 1 << 30;
                for (int dy = -radius; dy <= radius; ++dy)
                    for (int dx = -radius; dx <= radius; ++dx) {
                        int qx = x + dx, qy = y + dy;
                        if (qx < 0 || qy < 0 || qx >= res || qy >= res) continue;
                        if (!covered[base + size_t(qy) * res + qx]) continue;
                        int d2 = dx * dx + dy * dy;
                        if (d2 < bestD2) {
                            bestD2 = d2;
                            best = qx | (qy << 16);
                        }
                    }
                source[base + size_t(y) * res + x] = best;
            }
    }
    return source;
}

}  // namespace

struct Baker::Impl {
    BakeOptions options;
    BakeMesh mesh;
    Layout layout;
    std::vector<Material> materials;
    std::vector<DirectionalLight> lights;
    BakeStats stats;
    std::vector<glm::vec3> directions;

    // scene frame
    glm::vec3 sphereCenter{0.0f};
    float sphereRadius = 1.0f;
    float pixelSize = 1.0f;
    int gridSize = 1;         // pixels across the uniform bundle (--tiling uniform, captures)
    int maxTileSize = 2048;   // largest head image side the budget allows
    float depthBias = 0.0f;
    double historyPower = 0.0;
    double accumScale = 1.0;  // stored sums are true sums / accumScale
    std::vector<double> projectedArea;  // per triangle world area
    std::vector<Cluster> clusters;      // the mesh in culling units (engine/tiler)
    TilerOptions tilerOptions;

    // GL objects
    gl::Buffer vertexBuffer, triangleBuffer, metaIndexBuffer;
    gl::VertexArray vao;
    gl::Texture albedoMap, emissionMap, accum, sunMap, radiance, resolved, envTexture, dilationSource;
    gl::Framebuffer pageFbo, metaFbo;
    gl::Program updateProgram, sunProgram, resolveProgram, rescaleProgram, metaProgram, distanceProgram,
        emitterProgram;
    gl::Texture emitterMap;
    std::vector<glm::vec3> textureMeans;  // mean linear RGB of each scene texture (explicit emitters)
    std::vector<gl::Texture> materialTextures;
    int64_t nodeCapacity = 0;     // nodes the budget allows in one tile
    int subpixelBits = 8;         // GL_SUBPIXEL_BITS
    std::unique_ptr<BundleTracer> tracer;
    // the direction in progress (Baker::stepTiles can stop between its tiles)
    bool directionActive = false;
    BundleTracer::UpdateFn directionUpdate;

    Status init(const Scene& scene);
    Status buildPrograms();
    void uploadMesh();
    void metaPass(const Scene& scene);
    void bakeSun();
    bool useExplicitEmitters() const;
    void bakeEmitters();
    // The root square of direction d: the uniform grid, or the adaptive root.
    BundleFrame bundleFrame(const glm::vec3& d, glm::vec2 jitter, bool uniformGrid) const;
    // All tiles of direction d (bundle_tracer.h), each followed by `update`.
    template <class UpdateFn>
    void traceBundle(const glm::vec3& d, glm::vec2 jitter, uint32_t seed, UpdateFn update, bool recordStats);
    // Direction k: the history ramp, then its tiles one by one, then the radiance refresh.
    void beginDirection(int k);
    void stepTile();
    void finishDirection(int k);
    void resolveInto(bool radianceOut, gl::Texture& target);
    void dispatchPages(GLuint program);
};

nlohmann::json BakeStats::toJson() const {
    nlohmann::json j;
    j["directions"] = {{"done", directionsDone}, {"total", directionsTotal}};
    j["bundle"] = {{"resolution_pixels", bundleResolution}, {"pixel_size_scene_units", pixelSize},
                   {"history_power", historyPower}};
    auto sorted = predictedOverActual;
    std::sort(sorted.begin(), sorted.end());
    auto pct = [&](double q) { return sorted.empty() ? 0.0 : sorted[size_t(q * (sorted.size() - 1))]; };
    int maxTiles = tilesPerDirection.empty() ? 0 : *std::max_element(tilesPerDirection.begin(), tilesPerDirection.end());
    double meanTiles = tilesPerDirection.empty() ? 0.0
        : std::accumulate(tilesPerDirection.begin(), tilesPerDirection.end(), 0.0) / tilesPerDirection.size();
    auto sizes = tilePixelSizes;
    std::sort(sizes.begin(), sizes.end());
    auto size = [&](double q) { return sizes.empty() ? 0.0 : double(sizes[size_t(q * (sizes.size() - 1))]); };
    double meanLeaves = leavesPerDirection.empty() ? 0.0
        : std::accumulate(leavesPerDirection.begin(), leavesPerDirection.end(), 0.0) / leavesPerDirection.size();
    const double drawnTiles = double(std::max<int64_t>(tilesDrawn, 1)) * double(std::max<int64_t>(triangles, 1));
    j["tiles"] = {{"drawn", tilesDrawn}, {"per_direction_mean", meanTiles}, {"per_direction_max", maxTiles},
                  {"leaves_per_direction_mean", meanLeaves},
                  {"overflows_redrawn", overflows},
                  {"predicted_over_actual_nodes", {{"min", pct(0)}, {"p10", pct(0.1)}, {"median", pct(0.5)},
                                                   {"p90", pct(0.9)}, {"max", pct(1)}, {"count", sorted.size()}}},
                  {"pixel_size_scene_units", {{"min", size(0)}, {"median", size(0.5)}, {"max", size(1)}}}};
    j["culling"] = {{"clusters", clusters}, {"triangles", triangles},
                    {"bundle_pass_triangles_drawn_fraction", double(bundleTrianglesDrawn) / drawnTiles},
                    {"update_pass_triangles_drawn_fraction", double(updateTrianglesDrawn) / drawnTiles}};
    j["memory"] = {{"node_capacity", nodeCapacity}, {"peak_nodes_per_tile", peakNodesPerTile},
                   {"node_buffer_bytes", nodeBufferBytes}, {"head_image_bytes", headImageBytes},
                   {"peak_gpu_bytes", peakGpuBytes}, {"bytes_per_node", 12}, {"bytes_per_lightmap_texel", 8}};
    j["lightmap"] = {{"texels", lightmapTexels}, {"covered_texels", coveredTexels}};
    j["direct_light"] = {{"explicit_emitters", explicitEmitters}, {"emitter_samples", emitterSampleCount}};
    double bundleSeconds = secondsBundle > 0 ? secondsBundle : 1e-9;
    double updateSeconds = secondsUpdate > 0 ? secondsUpdate : 1e-9;
    j["throughput"] = {{"fragments", fragments}, {"fragments_per_second_bundle_pass", fragments / bundleSeconds},
                       {"texel_samples", updatedTexels}, {"texel_samples_per_second_update_pass", updatedTexels / updateSeconds}};
    j["seconds"] = {{"setup", secondsSetup}, {"importance", secondsImportance}, {"tiling", secondsTiling}, {"sun", secondsSun}, {"emitters", secondsEmitters}, {"bundle", secondsBundle}, {"update", secondsUpdate},
                    {"resolve", secondsResolve}, {"total", secondsTotal()}};
    return j;
}

Status Baker::Impl::buildPrograms() {
    std::string rounding = options.rounding == Rounding::Nearest ? "#define ROUNDING_NEAREST 1\n" : "";
    struct Spec {
        gl::Program* target;
        std::vector<std::string> files;
        std::string defines;
    } specs[] = {
        {&updateProgram, {"lightmap/update.vert", "lightmap/update.frag"}, rounding},
        {&sunProgram, {"lightmap/update.vert", "lightmap/update.frag"}, "#define SUN_PASS 1\n"},
        {&resolveProgram, {"lightmap/resolve.comp"}, ""},
        {&rescaleProgram, {"lightmap/rescale.comp"}, rounding},
        {&metaProgram, {"lightmap/meta.vert", "lightmap/meta.frag"}, ""},
        {&distanceProgram, {"direct/distance.vert", "direct/distance.frag"}, ""},
        {&emitterProgram, {"direct/emitter.vert", "direct/emitter.frag"}, ""},
    };
    for (auto& s : specs) {
        auto p = gl::buildProgram(s.files, s.defines);
        if (!p) return p.status();
        *s.target = std::move(p.value());
    }
    return Status::ok();
}

void Baker::Impl::uploadMesh() {
    vertexBuffer = gl::Buffer::create("bake vertices", int64_t(mesh.vertices.size() * sizeof(BakeVertex)),
                                      mesh.vertices.data(), 0);
    triangleBuffer = gl::Buffer::create("bake triangles", int64_t(mesh.triangles.size() * sizeof(BakeTriangle)),
                                        mesh.triangles.data(), 0);
    vao = createBakeVertexArray("bake vertex array", vertexBuffer);
}

void Baker::Impl::dispatchPages(GLuint program) {
    glUniform1i(glGetUniformLocation(program, "pageCount"), layout.pageCount);
    glUniform2i(glGetUniformLocation(program, "pageSize"), layout.resolution, layout.resolution);
    glDispatchCompute((layout.resolution + 7) / 8, (layout.resolution + 7) / 8, layout.pageCount);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

void Baker::Impl::metaPass(const Scene& scene) {
    gl::DebugGroup group("meta pass");
    // upload material textures (linear RGBA float, mipmapped)
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const Texture& t = scene.textures[i];
        int levels = 1 + int(std::floor(std::log2(std::max(t.width, t.height))));
        gl::Texture tex = gl::Texture::create2DLevels("material texture " + t.name, GL_RGBA16F, t.width, t.height, levels);
        // glTF images have row 0 at the top and v = 0 at the top: uploading rows in order makes v = texture t.
        glTextureSubImage2D(tex.id(), 0, 0, 0, t.width, t.height, GL_RGBA, GL_FLOAT, t.texels.data());
        glGenerateTextureMipmap(tex.id());
        glTextureParameteri(tex.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTextureParameteri(tex.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTextureParameteri(tex.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
        materialTextures.push_back(std::move(tex));
    }
    // triangles of each page sorted by material: one draw per (page, material) run
    std::vector<uint32_t> order(mesh.triangles.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const auto& ta = mesh.triangles[a];
        const auto& tb = mesh.triangles[b];
        return ta.page != tb.page ? ta.page < tb.page : ta.material < tb.material;
    });
    std::vector<uint32_t> indices;
    indices.reserve(order.size() * 3);
    for (uint32_t t : order)
        for (uint32_t k = 0; k < 3; ++k) indices.push_back(t * 3 + k);
    metaIndexBuffer = gl::Buffer::create("meta indices", int64_t(indices.size() * 4), indices.data(), 0);
    glVertexArrayElementBuffer(vao.id(), metaIndexBuffer.id());

    metaFbo = gl::Framebuffer::create("meta framebuffer");
    glUseProgram(metaProgram.id());
    glBindVertexArray(vao.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, triangleBuffer.id());
    glViewport(0, 0, layout.resolution, layout.resolution);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    const float zero[4] = {0, 0, 0, 0};
    size_t run = 0;
    for (int page = 0; page < layout.pageCount; ++page) {
        glNamedFramebufferTextureLayer(metaFbo.id(), GL_COLOR_ATTACHMENT0, albedoMap.id(), 0, page);
        glNamedFramebufferTextureLayer(metaFbo.id(), GL_COLOR_ATTACHMENT1, emissionMap.id(), 0, page);
        glNamedFramebufferDrawBuffers(metaFbo.id(), 2, buffers);
        CHECK_EQ(glCheckNamedFramebufferStatus(metaFbo.id(), GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
        glBindFramebuffer(GL_FRAMEBUFFER, metaFbo.id());
        glClearBufferfv(GL_COLOR, 0, zero);
        glClearBufferfv(GL_COLOR, 1, zero);
        while (run < order.size() && mesh.triangles[order[run]].page == uint32_t(page)) {
            size_t end = run;
            uint32_t m = mesh.triangles[order[run]].material;
            while (end < order.size() && mesh.triangles[order[end]].page == uint32_t(page) &&
                   mesh.triangles[order[end]].material == m)
                ++end;
            const Material& mat = materials[m];
            glUniform3fv(metaProgram.uniform("albedo"), 1, &mat.albedo.x);
            glUniform3fv(metaProgram.uniform("emission"), 1, &mat.emission.x);
            glUniform1i(metaProgram.uniform("hasAlbedoTexture"), mat.albedoTexture >= 0);
            glUniform1i(metaProgram.uniform("hasEmissionTexture"), mat.emissionTexture >= 0);
            if (mat.albedoTexture >= 0) glBindTextureUnit(2, materialTextures[mat.albedoTexture].id());
            if (mat.emissionTexture >= 0) glBindTextureUnit(3, materialTextures[mat.emissionTexture].id());
            glDrawElements(GL_TRIANGLES, GLsizei((end - run) * 3), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(run * 3 * sizeof(uint32_t)));
            run = end;
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

Status Baker::Impl::init(const Scene& scene) {
    auto t0 = Clock::now();
    materials = scene.materials;
    for (const auto& t : scene.textures) {
        glm::dvec3 sum(0.0);
        for (const auto& texel : t.texels) sum += glm::dvec3(texel);
        textureMeans.push_back(t.texels.empty() ? glm::vec3(1.0f) : glm::vec3(sum / double(t.texels.size())));
    }
    lights = scene.lights;
    stats.directionsTotal = options.directions;
    if (options.directions < 1) return Status::error("--directions must be at least 1");
    if (mesh.triangles.empty()) return Status::error("nothing to bake: the scene has no triangles");

    GLint maxTex = 0, maxLayers = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTex);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    if (layout.resolution > maxTex)
        return Status::error("--resolution " + std::to_string(layout.resolution) + " exceeds GL_MAX_TEXTURE_SIZE " +
                             std::to_string(maxTex));
    if (layout.pageCount > maxLayers)
        return Status::error(std::to_string(layout.pageCount) + " light map pages exceed GL_MAX_ARRAY_TEXTURE_LAYERS " +
                             std::to_string(maxLayers) + "; raise --resolution or lower --texel-density");

    // scene frame: bounding sphere of the bounds box
    sphereCenter = mesh.bounds.center();
    sphereRadius = std::max(0.5f * glm::length(mesh.bounds.size()), 1e-6f) * 1.001f;
    depthBias = 4e-6f * (glm::length(sphereCenter) + sphereRadius);

    // culling units: the triangles reordered into spatially coherent clusters
    clusters = clusterMesh(mesh);
    stats.triangles = int64_t(mesh.triangles.size());
    stats.clusters = int64_t(clusters.size());

    // bundle pixel from the light map's texel density: sqrt(texel area / world area)
    double worldArea = 0, texelArea = 0;
    projectedArea.resize(mesh.triangles.size());
    const double r = layout.resolution;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto& a = mesh.vertices[3 * t];
        const auto& b = mesh.vertices[3 * t + 1];
        const auto& c = mesh.vertices[3 * t + 2];
        glm::vec3 n = glm::cross(glm::vec3(b.position - a.position), glm::vec3(c.position - a.position));
        double area = 0.5 * glm::length(n);
        projectedArea[t] = area;
        worldArea += area;
        glm::vec2 e1 = (b.lightmapUv - a.lightmapUv) * float(r), e2 = (c.lightmapUv - a.lightmapUv) * float(r);
        texelArea += 0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x);
    }
    double density = worldArea > 0 && texelArea > 0 ? std::sqrt(texelArea / worldArea) : 1.0 / sphereRadius;
    if (options.bundleResolution > 0) {
        gridSize = options.bundleResolution;
        pixelSize = 2.0f * sphereRadius / float(gridSize);
    } else {
        pixelSize = float(0.5 / density);
        gridSize = std::max(1, int(std::ceil(2.0 * sphereRadius / pixelSize)));
        pixelSize = 2.0f * sphereRadius / float(gridSize);
    }
    GLint vp[2] = {0, 0};
    glGetIntegerv(GL_MAX_VIEWPORT_DIMS, vp);
    const int maxViewport = std::min(vp[0], vp[1]);
    glGetIntegerv(GL_SUBPIXEL_BITS, &subpixelBits);
    subpixelBits = std::clamp(subpixelBits, 0, 12);
    if (options.tiling == BakeOptions::Tiling::Uniform && gridSize > maxViewport)
        return Status::error("the bundle would be " + std::to_string(gridSize) + " pixels across, beyond GL_MAX_VIEWPORT_DIMS " +
                             std::to_string(maxViewport) + "; use --tiling adaptive, or lower --bundle-res, --resolution or --texel-density");
    stats.bundleResolution = gridSize;
    stats.pixelSize = pixelSize;

    // tile limits, all read from GL: a leaf's grid is one viewport; a tile's
    // side is the head image's; the node buffer is one SSBO binding; the
    // budget holds the head image and the node buffer of one tile
    maxTileSize = std::min({maxTex, maxViewport, 2048});
    while (maxTileSize > 64 && int64_t(maxTileSize) * maxTileSize * 4 > options.memoryBudget / 4) maxTileSize /= 2;
    int64_t headBytes = int64_t(maxTileSize) * maxTileSize * 4;
    GLint64 maxSsbo = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxSsbo);
    nodeCapacity = std::min<int64_t>({(options.memoryBudget - headBytes) / 12, maxSsbo / 12, int64_t(0xFFFFFFFEll)});
    if (nodeCapacity < 1024)
        return Status::error("--memory-budget is too small: the node buffer would hold fewer than 1024 nodes");
    stats.nodeCapacity = nodeCapacity;
    tilerOptions.uniform = options.tiling == BakeOptions::Tiling::Uniform;
    tilerOptions.fixedPixelSize = tilerOptions.uniform || options.bundleResolution > 0 ? pixelSize : 0.0;
    tilerOptions.maxLeafPixels = std::min(1024, maxViewport);
    tilerOptions.maxTilePixels = maxTileSize;
    tilerOptions.nodeCapacity = options.predictTiles ? double(nodeCapacity) : 1e300;
    tilerOptions.cull = options.cull;

    // importance (supplement §1) decides each leaf's pixel size
    {
        auto t = Clock::now();
        auto analyzer = ImportanceAnalyzer::create();
        if (!analyzer) return analyzer.status();
        auto result = (*analyzer)->analyze(mesh, layout.resolution);
        if (!result) return result.status();
        setClusterImportance(clusters, result->importance.importance);
        stats.secondsImportance = secondsSince(t);
    }

    // history ramp power from the largest albedo
    if (options.historyPower >= 0) {
        historyPower = options.historyPower;
    } else {
        float rho = 0;
        for (const auto& m : materials) rho = std::max({rho, m.albedo.r, m.albedo.g, m.albedo.b});
        rho = std::min(rho, 0.99f);
        historyPower = std::clamp(std::round(2.0 * rho / (1.0 - rho)), 1.0, 32.0);
    }
    stats.historyPower = historyPower;
    directions = makeDirections(options.directions, options.seed);

    Status s = buildPrograms();
    if (!s) return s;
    uploadMesh();
    const int pages = layout.pageCount, res = layout.resolution;
    albedoMap = gl::Texture::create2DArray("albedo map", GL_RGBA16F, res, res, pages);
    emissionMap = gl::Texture::create2DArray("emission map", GL_RGBA16F, res, res, pages);
    accum = gl::Texture::create2DArray("accumulators (fp16 RGB+W)", GL_RG32UI, res, res, pages);
    sunMap = gl::Texture::create2DArray("direct sun map", GL_RGBA32F, res, res, pages);
    emitterMap = gl::Texture::create2DArray("direct emitter map", GL_RGBA32F, res, res, pages);
    radiance = gl::Texture::create2DArray("outgoing radiance map", GL_RGBA32F, res, res, pages);
    resolved = gl::Texture::create2DArray("resolved light map", GL_RGBA32F, res, res, pages);
    glTextureParameteri(radiance.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(radiance.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    const uint32_t zeroU[4] = {0, 0, 0, 0};
    const float zeroF[4] = {0, 0, 0, 0};
    glClearTexImage(accum.id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, zeroU);
    glClearTexImage(sunMap.id(), 0, GL_RGBA, GL_FLOAT, zeroF);
    glClearTexImage(emitterMap.id(), 0, GL_RGBA, GL_FLOAT, zeroF);
    glClearTexImage(radiance.id(), 0, GL_RGBA, GL_FLOAT, zeroF);
    pageFbo = gl::Framebuffer::create("light map page framebuffer (no attachments)");
    glNamedFramebufferParameteri(pageFbo.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, res);
    glNamedFramebufferParameteri(pageFbo.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, res);
    {
        // the bundle pass: its buffers start small and grow to what the tiles predict
        const BundleScene scene{&mesh, &clusters, vao.id(), vertexBuffer.id(), triangleBuffer.id(), radiance.id(),
                                pageFbo.id(), res};
        const BundleLimits limits{nodeCapacity, maxTileSize, subpixelBits, options.predictTiles};
        auto t = BundleTracer::create(scene, limits,
                                      options.rounding == Rounding::Nearest ? "#define ROUNDING_NEAREST 1\n" : "", &stats);
        if (!t) return t.status();
        tracer = std::move(t.value());
    }

    if (options.environment) {
        const auto& env = *options.environment;
        envTexture = gl::Texture::create2D("environment", GL_RGBA32F, env.width, env.height);
        std::vector<glm::vec4> rgba(env.pixels.size());
        for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = glm::vec4(env.pixels[i], 1.0f);
        // file row 0 is the top (theta = 0): texture t = theta / pi, so upload rows top-down as t = 0..1
        glTextureSubImage2D(envTexture.id(), 0, 0, 0, env.width, env.height, GL_RGBA, GL_FLOAT, rgba.data());
        glTextureParameteri(envTexture.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(envTexture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(envTexture.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
    }

    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    metaPass(scene);

    // coverage
    std::vector<glm::u16vec4> texels(size_t(res) * res * pages);
    glGetTextureImage(albedoMap.id(), 0, GL_RGBA, GL_HALF_FLOAT, GLsizei(texels.size() * 8), texels.data());
    stats.lightmapTexels = int64_t(texels.size());
    std::vector<uint8_t> covered(texels.size());
    for (size_t i = 0; i < texels.size(); ++i) {
        covered[i] = texels[i].w != 0;
        stats.coveredTexels += covered[i];
    }
    std::vector<int32_t> source = dilationSources(covered, res, pages, std::max(layout.padding, 1) + 1);
    dilationSource = gl::Texture::create2DArray("dilation source texels", GL_R32I, res, res, pages);
    glTextureSubImage3D(dilationSource.id(), 0, 0, 0, 0, res, res, pages, GL_RED_INTEGER, GL_INT, source.data());
    stats.secondsSetup = secondsSince(t0);

    stats.explicitEmitters = useExplicitEmitters();
    auto te = Clock::now();
    if (stats.explicitEmitters) bakeEmitters();
    glFinish();
    stats.secondsEmitters = secondsSince(te);
    auto ts = Clock::now();
    bakeSun();
    stats.secondsSun = secondsSince(ts);
    auto tr = Clock::now();
    resolveInto(true, radiance);
    stats.secondsResolve += secondsSince(tr);
    return Status::ok();
}

BundleFrame Baker::Impl::bundleFrame(const glm::vec3& d, glm::vec2 jitter, bool uniformGrid) const {
    BundleFrame frame;
    frame.dir = d;
    orthonormalBasis(d, frame.u, frame.v);
    const glm::dvec2 centre(glm::dot(glm::dvec3(sphereCenter), glm::dvec3(frame.u)),
                            glm::dot(glm::dvec3(sphereCenter), glm::dvec3(frame.v)));
    if (uniformGrid) {
        // the uniform grid: gridSize pixels across the bounding sphere
        frame.size = double(gridSize) * pixelSize;
        frame.origin = centre - glm::dvec2(sphereRadius) + glm::dvec2(jitter) * double(pixelSize);
    } else {
        // the bounding sphere's square, with a (uniform) pixel of margin for the sun's jitter
        frame.size = 2.0 * (double(sphereRadius) + pixelSize);
        frame.origin = centre - glm::dvec2(sphereRadius + pixelSize) + glm::dvec2(jitter) * double(pixelSize);
    }
    return frame;
}

template <class UpdateFn>
void Baker::Impl::traceBundle(const glm::vec3& d, glm::vec2 jitter, uint32_t seed, UpdateFn update, bool recordStats) {
    tracer->run(bundleFrame(d, jitter, tilerOptions.uniform), tilerOptions, seed, recordStats, update);
}

void Baker::Impl::bakeSun() {
    if (lights.empty()) return;
    int j = std::max(1, options.sunJitter);
    for (size_t li = 0; li < lights.size(); ++li) {
        const auto& light = lights[li];
        glm::vec3 irradiance = light.irradiance;
        for (int jy = 0; jy < j; ++jy)
            for (int jx = 0; jx < j; ++jx) {
                glm::vec2 jitter((jx + 0.5f) / j - 0.5f, (jy + 0.5f) / j - 0.5f);
                traceBundle(glm::normalize(light.direction), jitter, uint32_t(li * 1000 + jy * j + jx),
                    [&](const TileFrame&, uint32_t) -> GLuint {
                        glUseProgram(sunProgram.id());
                        glUniform3fv(sunProgram.uniform("sunIrradiance"), 1, &irradiance.x);
                        glUniform1f(sunProgram.uniform("depthBias"), depthBias);
                        glBindImageTexture(BINDING_SUN, sunMap.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
                        return sunProgram.id();
                    },
                    false);
            }
    }
}

bool Baker::Impl::useExplicitEmitters() const {
    using D = BakeOptions::DirectLight;
    if (options.directLight != D::Auto) return options.directLight == D::Explicit;
    size_t emitters = 0;
    double emitterArea = 0, area = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        area += projectedArea[t];
        if (mesh.triangles[t].flags & TRIANGLE_EMISSIVE) {
            ++emitters;
            emitterArea += projectedArea[t];
        }
    }
    return emitters > 0 && emitters <= 1024 && emitterArea <= 0.25 * area;
}

void Baker::Impl::bakeEmitters() {
    gl::DebugGroup group("explicit emitters");
    // emitters and their sample counts, proportional to area x luminance (>= 1 each)
    struct Emitter {
        size_t triangle;
        glm::vec3 radiance;
        double power;
        int samples = 1;
    };
    std::vector<Emitter> emitters;
    double totalPower = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!(mesh.triangles[t].flags & TRIANGLE_EMISSIVE)) continue;
        const Material& m = materials[mesh.triangles[t].material];
        glm::vec3 le = m.emission * (m.emissionTexture >= 0 ? textureMeans[size_t(m.emissionTexture)] : glm::vec3(1.0f));
        double power = projectedArea[t] * (0.2126 * le.r + 0.7152 * le.g + 0.0722 * le.b);
        emitters.push_back({t, le, power});
        totalPower += power;
    }
    if (emitters.empty()) return;
    for (auto& e : emitters)
        e.samples = std::max(1, int(std::lround(options.emitterSamples * (totalPower > 0 ? e.power / totalPower : 0.0))));

    // auto: 4 cube texels per bundle pixel across (gridSize pixels span the
    // scene's diameter). Measured on the Cornell box at 64^2 texels: 64^2
    // faces raise the error from 4.3 % to 5.0 %, 256^2 and 512^2 give 4.3 %
    // and 256^2 costs 0.3 s instead of 0.5 s.
    int size = options.emitterShadowSize;
    if (size <= 0) {
        size = 64;
        while (size < 4 * gridSize && size < 512) size *= 2;
    }
    gl::Texture cube = gl::Texture::createCube("emitter sample distances", GL_R32F, size);
    glTextureParameteri(cube.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(cube.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl::Texture depth = gl::Texture::create2D("emitter sample depth", GL_DEPTH_COMPONENT32F, size, size);
    gl::Framebuffer fbo = gl::Framebuffer::create("emitter sample cube face");
    glNamedFramebufferTexture(fbo.id(), GL_DEPTH_ATTACHMENT, depth.id(), 0);

    const glm::vec3 faceDir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const glm::vec3 faceUp[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    const float nearPlane = 1e-4f * sphereRadius, farPlane = 4.0f * sphereRadius;
    const glm::mat4 projection = glm::perspective(glm::radians(90.0f), 1.0f, nearPlane, farPlane);
    const float farValue = 1e30f;
    const float normalOffset = 0.5f * pixelSize;
    // Bias: a quarter bundle pixel, plus (in the shader) half a cube texel's
    // footprint at the receiver's distance, the error of a nearest lookup.
    // Kept well under a texel so walls one texel thick still cast shadows.
    const float distanceBias = 0.25f * pixelSize;

    for (const Emitter& e : emitters) {
        const BakeVertex* v = &mesh.vertices[e.triangle * 3];
        glm::vec3 a(v[0].position), b(v[1].position), c(v[2].position);
        glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
        bool doubleSided = mesh.triangles[e.triangle].flags & TRIANGLE_DOUBLE_SIDED;
        glm::vec3 perSample = e.radiance / float(e.samples);
        for (int i = 0; i < e.samples; ++i) {
            // stratified point on the triangle: R2 sequence (Roberts 2018), folded
            double su = std::fmod(0.5 + 0.7548776662466927 * (i + 1), 1.0);
            double sv = std::fmod(0.5 + 0.5698402909980532 * (i + 1), 1.0);
            if (su + sv > 1.0) {
                su = 1.0 - su;
                sv = 1.0 - sv;
            }
            glm::vec3 point = a + float(su) * (b - a) + float(sv) * (c - a) + n * (1e-4f * pixelSize);
            // distance cube map
            glUseProgram(distanceProgram.id());
            glUniform3fv(distanceProgram.uniform("samplePoint"), 1, &point.x);
            glEnable(GL_DEPTH_TEST);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
            glViewport(0, 0, size, size);
            for (int f = 0; f < 6; ++f) {
                glNamedFramebufferTextureLayer(fbo.id(), GL_COLOR_ATTACHMENT0, cube.id(), 0, f);
                glm::mat4 clipFromWorld = projection * glm::lookAt(point, point + faceDir[f], faceUp[f]);
                glUniformMatrix4fv(distanceProgram.uniform("clipFromWorld"), 1, GL_FALSE, &clipFromWorld[0][0]);
                glClearNamedFramebufferfv(fbo.id(), GL_COLOR, 0, &farValue);
                glClearNamedFramebufferfi(fbo.id(), GL_DEPTH_STENCIL, 0, 1.0f, 0);
                glDrawArrays(GL_TRIANGLES, 0, GLsizei(mesh.vertices.size()));
            }
            glDisable(GL_DEPTH_TEST);
            // accumulate this sample's share into the direct map, page by page
            glUseProgram(emitterProgram.id());
            glUniform3fv(emitterProgram.uniform("emitterA"), 1, &a.x);
            glUniform3fv(emitterProgram.uniform("emitterB"), 1, &b.x);
            glUniform3fv(emitterProgram.uniform("emitterC"), 1, &c.x);
            glUniform3fv(emitterProgram.uniform("emitterNormal"), 1, &n.x);
            glUniform1i(emitterProgram.uniform("emitterDoubleSided"), doubleSided);
            glUniform3fv(emitterProgram.uniform("radianceOverSamples"), 1, &perSample.x);
            glUniform3fv(emitterProgram.uniform("samplePoint"), 1, &point.x);
            glUniform1f(emitterProgram.uniform("normalOffset"), normalOffset);
            glUniform1f(emitterProgram.uniform("distanceBias"), distanceBias);
            glUniform1f(emitterProgram.uniform("footprintPerDistance"), 1.0f / float(size));
            glBindTextureUnit(0, cube.id());
            glBindImageTexture(BINDING_DIRECT, emitterMap.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
            glBindFramebuffer(GL_FRAMEBUFFER, pageFbo.id());
            glViewport(0, 0, layout.resolution, layout.resolution);
            for (int page = 0; page < layout.pageCount; ++page) {
                glUniform1i(emitterProgram.uniform("page"), page);
                GLint first = GLint(mesh.pageFirstTriangle[page] * 3);
                GLsizei count = GLsizei((mesh.pageFirstTriangle[page + 1] - mesh.pageFirstTriangle[page]) * 3);
                if (count) glDrawArrays(GL_TRIANGLES, first, count);
            }
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
            ++stats.emitterSampleCount;
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Baker::Impl::beginDirection(int k) {
    const glm::vec3 d = directions[size_t(k)];
    // history ramp: weight min(k+1, K)^power relative to the stored scale
    double rampEnd = std::max(1, options.directions / 2);
    double weight = std::pow(std::min(double(k + 1), rampEnd), historyPower);
    double sampleWeight = weight / accumScale;
    if (sampleWeight > 16.0) {
        gl::DebugGroup group("rescale accumulators");
        glUseProgram(rescaleProgram.id());
        glUniform1f(rescaleProgram.uniform("factor"), float(accumScale / weight));
        glUniform1ui(rescaleProgram.uniform("randomSeed"), pcgHash(uint32_t(options.seed) ^ pcgHash(uint32_t(k) + 77u)));
        glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        dispatchPages(rescaleProgram.id());
        accumScale = weight;
        sampleWeight = 1.0;
    }
    const uint32_t seed = pcgHash(uint32_t(options.seed) * 0x9E3779B1u ^ pcgHash(uint32_t(k)));
    directionUpdate = [this, sampleWeight, seed](const TileFrame&, uint32_t) -> GLuint {
        const bool useEnv = bool(envTexture);
        glUseProgram(updateProgram.id());
        glUniform1f(updateProgram.uniform("sampleWeight"), float(sampleWeight));
        // per direction, not per tile: each texel is updated once per direction, and tiles change with the budget
        glUniform1ui(updateProgram.uniform("randomSeed"), seed);
        glUniform3fv(updateProgram.uniform("sky"), 1, &options.sky.x);
        glUniform1i(updateProgram.uniform("useEnv"), useEnv);
        glUniform1f(updateProgram.uniform("depthBias"), depthBias);
        if (useEnv) glBindTextureUnit(BINDING_ENV, envTexture.id());
        glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
        return updateProgram.id();
    };
    tracer->begin(bundleFrame(d, glm::vec2(0.0f), tilerOptions.uniform), tilerOptions, seed, true);
    directionActive = true;
}

void Baker::Impl::stepTile() {
    const int k = stats.directionsDone;
    if (!directionActive) beginDirection(k);
    if (!tracer->done()) tracer->next(directionUpdate);
    if (tracer->done()) finishDirection(k);
}

void Baker::Impl::finishDirection(int k) {
    directionActive = false;
    stats.updatedTexels += stats.coveredTexels;
    // Refresh the outgoing radiance the next bundles read. Every direction at
    // first, when each one adds a bounce; later every k/32 directions (at most
    // 8): the estimate then moves slowly and the resolve is a pass over every page.
    const int interval = std::clamp(k / 32, 1, 8);
    if ((k + 1) % interval == 0 || k + 1 == options.directions) {
        auto tr = Clock::now();
        resolveInto(true, radiance);
        glFinish();
        stats.secondsResolve += secondsSince(tr);
    }
    ++stats.directionsDone;
}

void Baker::Impl::resolveInto(bool radianceOut, gl::Texture& target) {
    gl::DebugGroup group("resolve");
    glUseProgram(resolveProgram.id());
    glUniform1i(resolveProgram.uniform("radianceOut"), radianceOut);
    glUniform1i(resolveProgram.uniform("includeEmission"), !stats.explicitEmitters);
    glBindImageTexture(7, emitterMap.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(1, accum.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RG32UI);
    glBindImageTexture(2, sunMap.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(3, albedoMap.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(4, emissionMap.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    glBindImageTexture(5, target.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindImageTexture(6, dilationSource.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32I);
    dispatchPages(resolveProgram.id());
}

Baker::Baker(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Baker::~Baker() = default;

Expected<std::unique_ptr<Baker>> Baker::create(const Scene& scene, const Layout& layout, const BakeOptions& options) {
    auto impl = std::make_unique<Impl>();
    impl->options = options;
    impl->layout = layout;
    impl->mesh = buildBakeMesh(scene, layout);
    MemoryTracker::gpu().resetPeak();
    Status s = impl->init(scene);
    if (!s) return s;
    return std::unique_ptr<Baker>(new Baker(std::move(impl)));
}

BakeProgress Baker::step(double seconds) {
    auto t0 = Clock::now();
    while (impl_->stats.directionsDone < impl_->options.directions) {
        const int k = impl_->stats.directionsDone;
        while (impl_->stats.directionsDone == k) impl_->stepTile();
        if (secondsSince(t0) >= seconds) break;
    }
    impl_->stats.peakGpuBytes = MemoryTracker::gpu().peak();
    return progress();
}

BakeProgress Baker::stepTiles(double seconds) {
    auto t0 = Clock::now();
    while (impl_->stats.directionsDone < impl_->options.directions) {
        impl_->stepTile();
        if (secondsSince(t0) >= seconds) break;
    }
    impl_->stats.peakGpuBytes = MemoryTracker::gpu().peak();
    return progress();
}

BakeProgress Baker::progress() const {
    return {impl_->stats.directionsDone, impl_->options.directions, impl_->directionActive};
}

LightmapPages Baker::readLightmaps() {
    Impl& m = *impl_;
    m.resolveInto(false, m.resolved);
    const int res = m.layout.resolution;
    std::vector<glm::vec4> texels(size_t(res) * res * m.layout.pageCount);
    glGetTextureImage(m.resolved.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(texels.size() * 16), texels.data());
    std::vector<glm::u16vec4> albedo(texels.size());
    glGetTextureImage(m.albedoMap.id(), 0, GL_RGBA, GL_HALF_FLOAT, GLsizei(albedo.size() * 8), albedo.data());
    LightmapPages out;
    out.resolution = res;
    for (int p = 0; p < m.layout.pageCount; ++p) {
        io::ImageRgb img;
        img.width = img.height = res;
        img.pixels.resize(size_t(res) * res);
        std::vector<uint8_t> cov(size_t(res) * res);
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            size_t k = size_t(p) * res * res + i;
            img.pixels[i] = glm::vec3(texels[k]);
            cov[i] = albedo[k].w != 0;
        }
        out.pages.push_back(std::move(img));
        out.covered.push_back(std::move(cov));
    }
    return out;
}

std::vector<std::vector<glm::vec4>> Baker::readAccumulators() {
    Impl& m = *impl_;
    const int res = m.layout.resolution;
    std::vector<glm::uvec2> raw(size_t(res) * res * m.layout.pageCount);
    glGetTextureImage(m.accum.id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, GLsizei(raw.size() * 8), raw.data());
    std::vector<std::vector<glm::vec4>> out(size_t(m.layout.pageCount));
    for (int p = 0; p < m.layout.pageCount; ++p)
        for (int i = 0; i < res * res; ++i) {
            glm::uvec2 v = raw[size_t(p) * res * res + i];
            out[size_t(p)].push_back(glm::vec4(halfToFloat(uint16_t(v.x & 0xFFFF)), halfToFloat(uint16_t(v.x >> 16)),
                                               halfToFloat(uint16_t(v.y & 0xFFFF)), halfToFloat(uint16_t(v.y >> 16))));
        }
    return out;
}

Baker::BundleCapture Baker::captureBundle(const glm::vec3& dir) {
    Impl& m = *impl_;
    CHECK_LE(m.gridSize, m.maxTileSize);
    BundleCapture cap;
    cap.dir = glm::normalize(dir);
    // the uniform grid as one tile, everything drawn
    TilerOptions one = m.tilerOptions;
    one.uniform = true;
    one.fixedPixelSize = m.pixelSize;
    one.cull = false;
    one.nodeCapacity = 1e300;
    one.maxTilePixels = m.gridSize;
    m.tracer->run(m.bundleFrame(cap.dir, glm::vec2(0.0f), true), one, 12345u, false,
        [&](const TileFrame& f, uint32_t) -> GLuint {
            cap.u = f.u;
            cap.v = f.v;
            cap.origin = f.rootOrigin;
            cap.pixelSize = f.pixelSize;
            cap.width = f.window.width;
            cap.height = f.window.height;
            return 0;  // no update
        });
    cap.nodeCount = m.tracer->lastNodeCount();
    if (cap.width == 0) return cap;  // nothing drawn
    const int headSide = m.tracer->headSide();
    std::vector<uint32_t> heads(size_t(headSide) * headSide);
    glGetTextureImage(m.tracer->heads().id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, GLsizei(heads.size() * 4), heads.data());
    std::vector<shared::Node> nodes(std::max<uint32_t>(cap.nodeCount, 1));
    glGetNamedBufferSubData(m.tracer->nodes().id(), 0, GLsizeiptr(nodes.size() * sizeof(shared::Node)), nodes.data());
    cap.depths.resize(size_t(cap.width) * cap.height);
    cap.flags.resize(cap.depths.size());
    cap.radiance.resize(cap.depths.size());
    for (int y = 0; y < cap.height; ++y)
        for (int x = 0; x < cap.width; ++x) {
            std::vector<std::pair<float, uint32_t>> list;
            uint32_t steps = 0;
            for (uint32_t i = heads[size_t(y) * headSide + x]; i != END_OF_LIST; i = nodes[i].next) {
                if (i >= cap.nodeCount || ++steps > cap.nodeCount) {
                    cap.listsWellFormed = false;
                    break;
                }
                list.push_back({0.0f, i});
                std::memcpy(&list.back().first, &nodes[i].depth, 4);
            }
            std::sort(list.begin(), list.end());
            size_t k = size_t(y) * cap.width + x;
            for (auto& [z, i] : list) {
                cap.depths[k].push_back(z);
                cap.flags[k].push_back(nodes[i].depth & NODE_FLAG_MASK);
                cap.radiance[k].push_back(decodeRgbe(nodes[i].radiance));
            }
        }
    return cap;
}

namespace {
constexpr char CHECKPOINT_MAGIC[8] = {'B', 'B', 'C', 'K', 'P', 'T', '0', '2'};

uint64_t fnv1a(const void* data, size_t bytes, uint64_t h = 1469598103934665603ull) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

// What a checkpoint must match to be resumed: geometry, layout and every option that changes the bytes.
uint64_t checkpointKey(const BakeMesh& mesh, const Layout& layout, const BakeOptions& o, double historyPower) {
    uint64_t h = fnv1a(mesh.vertices.data(), mesh.vertices.size() * sizeof(BakeVertex));
    h = fnv1a(mesh.triangles.data(), mesh.triangles.size() * sizeof(BakeTriangle), h);
    const int64_t ints[] = {layout.resolution, layout.pageCount, o.directions, o.bundleResolution, o.memoryBudget, int64_t(o.tiling),
                            int64_t(o.seed), int64_t(o.rounding), o.sunJitter, o.environment ? 1 : 0};
    h = fnv1a(ints, sizeof ints, h);
    const double reals[] = {o.sky.r, o.sky.g, o.sky.b, historyPower};
    h = fnv1a(reals, sizeof reals, h);
    if (o.environment) h = fnv1a(o.environment->pixels.data(), o.environment->pixels.size() * sizeof(glm::vec3), h);
    return h;
}

struct CheckpointHeader {
    char magic[8];
    uint64_t key;
    int32_t directionsDone;
    int32_t resolution;
    int32_t pages;
    int32_t pad;
    double accumScale;
};
}  // namespace

Status Baker::saveCheckpoint(const std::string& path) {
    Impl& m = *impl_;
    // a checkpoint holds whole directions: finish the one in flight (the same tiles an uninterrupted bake draws)
    if (m.directionActive) {
        const int k = m.stats.directionsDone;
        while (m.stats.directionsDone == k) m.stepTile();
    }
    const int res = m.layout.resolution;
    std::vector<glm::uvec2> raw(size_t(res) * res * m.layout.pageCount);
    glGetTextureImage(m.accum.id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, GLsizei(raw.size() * 8), raw.data());
    CheckpointHeader h{};
    std::memcpy(h.magic, CHECKPOINT_MAGIC, 8);
    h.key = checkpointKey(m.mesh, m.layout, m.options, m.historyPower);
    h.directionsDone = m.stats.directionsDone;
    h.resolution = res;
    h.pages = m.layout.pageCount;
    h.accumScale = m.accumScale;
    // the radiance map too: it is refreshed on a schedule, so it can be older than the accumulators
    std::vector<glm::vec4> radiance(raw.size());
    glGetTextureImage(m.radiance.id(), 0, GL_RGBA, GL_FLOAT, GLsizei(radiance.size() * 16), radiance.data());
    std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
    bytes.append(reinterpret_cast<const char*>(raw.data()), raw.size() * sizeof(glm::uvec2));
    bytes.append(reinterpret_cast<const char*>(radiance.data()), radiance.size() * sizeof(glm::vec4));
    return io::writeFileAtomic(path, bytes);
}

Status Baker::loadCheckpoint(const std::string& path) {
    Impl& m = *impl_;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return Status::error("cannot read checkpoint " + path);
    CheckpointHeader h{};
    const int res = m.layout.resolution;
    std::vector<glm::uvec2> raw(size_t(res) * res * m.layout.pageCount);
    std::vector<glm::vec4> radiance(raw.size());
    bool ok = std::fread(&h, sizeof h, 1, f) == 1 && std::memcmp(h.magic, CHECKPOINT_MAGIC, 8) == 0 &&
              h.resolution == res && h.pages == m.layout.pageCount &&
              std::fread(raw.data(), sizeof(glm::uvec2), raw.size(), f) == raw.size() &&
              std::fread(radiance.data(), sizeof(glm::vec4), radiance.size(), f) == radiance.size();
    std::fclose(f);
    if (!ok) return Status::error(path + " is not a bundlebake checkpoint of this layout");
    if (h.key != checkpointKey(m.mesh, m.layout, m.options, m.historyPower))
        return Status::error(path + " was written for another scene or other bake options; remove it or bake without --resume");
    if (h.directionsDone < 0 || h.directionsDone > m.options.directions)
        return Status::error(path + ": corrupt progress count");
    glTextureSubImage3D(m.accum.id(), 0, 0, 0, 0, res, res, m.layout.pageCount, GL_RG_INTEGER, GL_UNSIGNED_INT,
                        raw.data());
    glTextureSubImage3D(m.radiance.id(), 0, 0, 0, 0, res, res, m.layout.pageCount, GL_RGBA, GL_FLOAT, radiance.data());
    m.stats.directionsDone = h.directionsDone;
    m.accumScale = h.accumScale;
    return Status::ok();
}

const BakeStats& Baker::stats() const { return impl_->stats; }
const BakeMesh& Baker::mesh() const { return impl_->mesh; }

void Baker::resolveLightmaps() { impl_->resolveInto(false, impl_->resolved); }

uint32_t Baker::lightmapTextureId() const { return impl_->resolved.id(); }

Baker::BundleGrid Baker::bundleGrid() const {
    const Impl& m = *impl_;
    BundleGrid g;
    if (m.stats.leavesPerDirection.empty() || m.tracer->leaves().empty()) {
        // before any direction: the uniform grid of direction 0
        if (m.directions.empty()) return g;
        g.dir = m.directions[0];
        orthonormalBasis(g.dir, g.u, g.v);
        g.origin = glm::vec2(glm::dot(m.sphereCenter, g.u), glm::dot(m.sphereCenter, g.v)) - glm::vec2(m.sphereRadius);
        g.pixelSize = m.pixelSize;
        g.gridSize = m.gridSize;
        g.tileStep = std::min(m.gridSize, m.maxTileSize);
        return g;
    }
    // the latest direction: the finest leaf's pixels, and its side as the tile step
    const BundleFrame& frame = m.tracer->frame();
    g.dir = frame.dir;
    g.u = frame.u;
    g.v = frame.v;
    g.origin = glm::vec2(frame.origin);
    const BundleLeaf* finest = &m.tracer->leaves()[0];
    for (const BundleLeaf& l : m.tracer->leaves())
        if (l.extent / l.pixels < finest->extent / finest->pixels) finest = &l;
    g.pixelSize = float(finest->extent * frame.size / finest->pixels);
    g.gridSize = int(std::ceil(frame.size / g.pixelSize - 1e-6));
    g.tileStep = std::max(1, finest->pixels);
    g.tiles = m.tracer->tilesThisDirection();
    return g;
}

}  // namespace bb
