// The Baker: setup (programs, meta pass, importance -> clusters, buffers),
// the public API, read-backs and captures. The stages live beside it (see
// baker_impl.h).
#include "bake/baker.h"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <numeric>

#include "bake/baker_impl.h"
#include "bake/directions.h"
#include "core/check.h"
#include "core/log.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "importance/importance_gl.h"
#include "layout/bake_mesh_gl.h"

namespace bb {
namespace {

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

// Quantile q in [0, 1] of `values` (nearest rank below); 0 when empty.
template <class T>
double quantile(std::vector<T> values, double q) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    return double(values[size_t(q * double(values.size() - 1))]);
}

template <class T>
double mean(const std::vector<T>& values) {
    return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
}

}  // namespace

nlohmann::json BakeStats::toJson() const {
    nlohmann::json j;
    j["directions"] = {{"done", directionsDone}, {"total", directionsTotal}};
    j["bundle"] = {{"resolution_pixels", bundleResolution}, {"pixel_size_scene_units", pixelSize},
                   {"history_power", historyPower}};
    auto pct = [&](double q) { return quantile(predictedOverActual, q); };
    auto size = [&](double q) { return quantile(tilePixelSizes, q); };
    int maxTiles = tilesPerDirection.empty() ? 0 : *std::max_element(tilesPerDirection.begin(), tilesPerDirection.end());
    double meanTiles = mean(tilesPerDirection);
    double meanLeaves = mean(leavesPerDirection);
    const double drawnTiles = double(std::max<int64_t>(tilesDrawn, 1)) * double(std::max<int64_t>(triangles, 1));
    j["tiles"] = {{"drawn", tilesDrawn}, {"per_direction_mean", meanTiles}, {"per_direction_max", maxTiles},
                  {"leaves_per_direction_mean", meanLeaves},
                  {"overflows_redrawn", overflows},
                  {"predicted_over_actual_nodes", {{"min", pct(0)}, {"p10", pct(0.1)}, {"median", pct(0.5)},
                                                   {"p90", pct(0.9)}, {"max", pct(1)}, {"count", predictedOverActual.size()}}},
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
    // importance (supplement §1) decides each leaf's pixel size
    {
        auto t = Clock::now();
        auto analyzer = ImportanceAnalyzer::create();
        if (!analyzer) return analyzer.status();
        auto result = (*analyzer)->analyze(mesh, layout.resolution);
        if (!result) return result.status();
        setClusterImportance(mesh, clusters, result->importance.importance);
        stats.secondsImportance = secondsSince(t);
    }

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
    // the sun's bundles in adaptive mode: every leaf at the scene's finest pixel
    // (bakeSun), so the jitter is a stratified fraction of a pixel everywhere
    if (!tilerOptions.uniform && tilerOptions.fixedPixelSize <= 0) {
        float imax = 0.0f;
        for (const Cluster& c : clusters) imax = std::max(imax, c.maxImportance);
        if (imax > 0.0f) sunPixelSize = pixelForImportance(imax, tilerOptions.pixelsPerTexel);
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

BundleFrame Baker::Impl::bundleFrame(const glm::vec3& d, glm::vec2 jitter, bool uniformGrid, double jitterUnit) const {
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
        // the bounding sphere's square, with a margin for the sun's jitter
        const double margin = std::max(double(pixelSize), jitterUnit);
        frame.size = 2.0 * (double(sphereRadius) + margin);
        frame.origin = centre - glm::dvec2(sphereRadius + margin) + glm::dvec2(jitter) * jitterUnit;
    }
    return frame;
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

void Baker::Impl::stepDirection() {
    const int k = stats.directionsDone;
    while (stats.directionsDone == k) stepTile();
}

void Baker::Impl::run(double seconds, bool wholeDirections) {
    auto t0 = Clock::now();
    while (stats.directionsDone < options.directions) {
        if (wholeDirections)
            stepDirection();
        else
            stepTile();
        if (secondsSince(t0) >= seconds) break;
    }
    stats.peakGpuBytes = MemoryTracker::gpu().peak();
}

BakeProgress Baker::step(double seconds) {
    impl_->run(seconds, true);
    return progress();
}

BakeProgress Baker::stepTiles(double seconds) {
    impl_->run(seconds, false);
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
    m.tracer->run(m.bundleFrame(cap.dir, glm::vec2(0.0f), true, m.pixelSize), one, 12345u, false,
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
