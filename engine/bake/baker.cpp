// The Baker: setup (programs, meta pass, importance -> clusters, buffers),
// the public API, read-backs and captures. The stages live beside it (see
// baker_impl.h).
#include "bake/baker.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <future>
#include <cmath>
#include <numeric>

#include "bake/baker_impl.h"
#include "bake/supersample.h"
#include "bake/transport_albedo.h"
#include "bake/directions.h"
#include "core/check.h"
#include "core/hash.h"
#include "core/log.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "gl/gl.h"
#include "gl/shader.h"
#include "glsl/shared/bundle_layout.h"
#include "importance/importance_gl.h"
#include "layout/bake_mesh_gl.h"

namespace bb {

// One page's CHART_NEIGHBOUR_* bits (glsl/shared/bundle_layout.h): for each
// texel the GPU covered (codes before dilation), the texels 1 and 2 away
// along its row and column that the GPU covered and whose CPU owners
// (texelOwners) are on the same chart as its own, 2 away only through 1 away.
void chartNeighbourBits(const std::vector<uint8_t>& codes, const std::vector<int32_t>& owner,
                        const std::vector<uint32_t>& chart, int res, std::vector<uint8_t>& bits) {
    const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
    const uint8_t bit[4] = {CHART_NEIGHBOUR_LEFT, CHART_NEIGHBOUR_RIGHT, CHART_NEIGHBOUR_DOWN, CHART_NEIGHBOUR_UP};
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            const size_t i = size_t(y) * res + x;
            bits[i] = 0;
            if (codes[i] != DILATION_SELF || owner[i] < 0) continue;
            auto sameChart = [&](int nx, int ny) {
                if (nx < 0 || ny < 0 || nx >= res || ny >= res) return false;
                const size_t j = size_t(ny) * res + nx;
                return codes[j] == DILATION_SELF && owner[j] >= 0 && chart[size_t(owner[j])] == chart[size_t(owner[i])];
            };
            for (int k = 0; k < 4; ++k) {
                if (!sameChart(x + dx[k], y + dy[k])) continue;
                bits[i] |= bit[k];
                if (sameChart(x + 2 * dx[k], y + 2 * dy[k])) bits[i] |= bit[k] << CHART_NEIGHBOUR_FAR;
            }
        }
}

void ownerChartCodes(const std::vector<int32_t>& owner, const std::vector<uint32_t>& chart, std::vector<uint16_t>& codes) {
    codes.resize(owner.size());
    for (size_t i = 0; i < owner.size(); ++i)
        codes[i] = uint16_t(owner[i] < 0 ? TEXEL_CHART_MASK : chart[size_t(owner[i])] & TEXEL_CHART_MASK);
}

namespace {

// One page of dilation codes (glsl/shared/bundle_layout.h), in place: covered
// texels hold DILATION_SELF; every other texel gets the nearest covered texel
// within `radius` (Euclidean, ties to the first in row order), or DILATION_NONE.
void dilationCodes(std::vector<uint8_t>& codes, int res, int radius) {
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            uint8_t& code = codes[size_t(y) * res + x];
            if (code == DILATION_SELF) continue;
            int best = DILATION_NONE, bestD2 = 1 << 30;
            for (int dy = -radius; dy <= radius; ++dy)
                for (int dx = -radius; dx <= radius; ++dx) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= res || qy >= res) continue;
                    if (codes[size_t(qy) * res + qx] != DILATION_SELF) continue;
                    int d2 = dx * dx + dy * dy;
                    if (d2 < bestD2) {
                        bestD2 = d2;
                        best = (dx + DILATION_RADIUS) | ((dy + DILATION_RADIUS) << 4);
                    }
                }
            code = uint8_t(best);
        }
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
                   {"history_power", historyPower}, {"history_plateau", historyPlateau},
                   {"transport_albedo", transportAlbedo}, {"transport_albedo_slowest", transportAlbedoSlowest},
                   {"radiance_unit", radianceUnit}};
    auto pct = [&](double q) { return quantile(predictedOverActual, q); };
    auto size = [&](double q) { return quantile(tilePixelSizes, q); };
    int maxTiles = tilesPerDirection.empty() ? 0 : *std::max_element(tilesPerDirection.begin(), tilesPerDirection.end());
    double meanTiles = mean(tilesPerDirection);
    double meanLeaves = mean(leavesPerDirection);
    const double drawnTiles = double(std::max<int64_t>(tilesDrawn, 1)) * double(std::max<int64_t>(triangles, 1));
    j["tiles"] = {{"drawn", tilesDrawn}, {"per_direction_mean", meanTiles}, {"per_direction_max", maxTiles},
                  {"leaves_per_direction_mean", meanLeaves},
                  {"curvature_refined_triangles", curvatureRefinedTriangles},
                  {"overflows_redrawn", overflows}, {"leaf_run_updates", leafRunUpdates},
                  {"predicted_over_actual_nodes", {{"min", pct(0)}, {"p10", pct(0.1)}, {"median", pct(0.5)},
                                                   {"p90", pct(0.9)}, {"max", pct(1)}, {"count", predictedOverActual.size()}}},
                  {"pixel_size_scene_units", {{"min", size(0)}, {"median", size(0.5)}, {"max", size(1)}}}};
    j["culling"] = {{"clusters", clusters}, {"triangles", triangles},
                    {"bundle_pass_triangles_drawn_fraction", double(bundleTrianglesDrawn) / drawnTiles},
                    {"update_pass_triangles_drawn_fraction", double(updateTrianglesDrawn) / drawnTiles}};
    // GL memory as the objects that existed hold it (GL's component sizes),
    // peak per category; the light-map state per page texel and per covered texel
    const double pageTexels = double(std::max<int64_t>(lightmapTexels, 1));
    const double coveredTexelsOrOne = double(std::max<int64_t>(coveredTexels, 1));
    nlohmann::json categories = nlohmann::json::object();
    for (const auto& [name, bytes] : peakGpuBytesByCategory)
        categories[name] = {{"peak_bytes", bytes}, {"bytes_per_page_texel", double(bytes) / pageTexels}};
    j["memory"] = {{"budget_bytes", memoryBudget}, {"peak_gpu_bytes", peakGpuBytes},
                   {"peak_resident_bytes", peakResidentBytes()},
                   {"peak_gpu_bytes_per_page_texel", double(peakGpuBytes) / pageTexels},
                   {"lightmap_state_bytes", lightmapStateBytes},
                   {"lightmap_bytes_per_page_texel", double(lightmapStateBytes) / pageTexels},
                   {"lightmap_bytes_per_covered_texel", double(lightmapStateBytes) / coveredTexelsOrOne},
                   {"curved_texel_bytes", curvedTexelBytes},
                   {"by_category", categories},
                   {"node_capacity", nodeCapacity}, {"peak_nodes_per_tile", peakNodesPerTile},
                   {"node_buffer_bytes", nodeBufferBytes}, {"head_image_bytes", headImageBytes}, {"bytes_per_node", 12}};
    j["lightmap"] = {{"texels", lightmapTexels}, {"covered_texels", coveredTexels}, {"shared_texels", sharedTexels},
                   {"curved_texels", curvedTexels}, {"partial_texels", partialTexels},
                   {"exact_footprint_texels", exactFootprintTexels}, {"supersample", supersample},
                   {"supersample_filled_texels", supersampleFilledTexels},
                   {"supersample_lost_texels", supersampleLostTexels}};
    j["direct_light"] = {{"explicit_emitters", explicitEmitters}, {"emitter_samples", emitterSampleCount},
                         {"sun_passes_per_axis", sunJitter}};
    double bundleSeconds = secondsBundle > 0 ? secondsBundle : 1e-9;
    double updateSeconds = secondsUpdate > 0 ? secondsUpdate : 1e-9;
    j["throughput"] = {{"fragments", fragments}, {"fragments_per_second_bundle_pass", fragments / bundleSeconds},
                       {"texel_samples", updatedTexels}, {"texel_samples_per_second_update_pass", updatedTexels / updateSeconds}};
    j["seconds"] = {{"setup", secondsSetup}, {"importance", secondsImportance}, {"tiling", secondsTiling}, {"sun", secondsSun}, {"emitters", secondsEmitters}, {"bundle", secondsBundle}, {"update", secondsUpdate},
                    {"resolve", secondsResolve}, {"combine", secondsCombine}, {"resolution_probe", secondsProbe},
                    {"total", secondsTotal()}};
    if (combines > 0) j["combine"] = {{"count", combines}, {"bytes_sent", combineBytes}};
    j["noise"] = {{"relative", noiseRelative}, {"halves", noiseHalves}, {"direct", noiseDirect}, {"lag", noiseLag},
                  {"sampled_texels", noiseTexels}, {"stride", noiseStride}, {"stopped_at_target", stoppedAtTargetNoise},
                  {"history", noiseHistory}};
    if (noiseResolution >= 0)
        j["noise"].update({{"resolution", noiseResolution}, {"error_estimate", errorEstimate()},
                           {"resolution_probe_directions", resolutionProbeDirections},
                           {"resolution_order", resolutionOrder}, {"resolution_past_range", resolutionPastRange}});
    return j;
}

double defaultHistoryPower(double transportAlbedo) {
    const double rho = std::min(transportAlbedo, 0.99);
    return std::clamp(std::round(2.0 * rho / std::pow(1.0 - rho, 1.5)), 1.0, 1024.0);
}

// A Cranley-Patterson rotation of the footprint points' R2 sequence, the same
// for every texel (layouts of one density still bake the same values) and new
// with each seed, so that two seeds' bakes differ by all of a bake's sampling
// and not by all of it less the footprint's (a sun's shadow edge: by a third
// of the error with the points fixed, design notes "The direct light's noise
// in the estimate").
std::string Baker::Impl::footprintShiftDefine() const {
    const uint64_t h = hash(options.seed, 0x466f6f747072696eull);
    return "#define FOOTPRINT_SHIFT uvec2(" + std::to_string(uint32_t(h)) + "u, " + std::to_string(uint32_t(h >> 32)) +
           "u)\n";
}

Status Baker::Impl::buildPrograms() {
    const std::string rounding = roundingDefine();
    const std::string shift = footprintShiftDefine();  // the programs that sample texels' footprints
    struct Spec {
        gl::Program* target;
        std::vector<std::string> files;
        std::string defines;
    } specs[] = {
        {&updateProgram, {"lightmap/update.vert", "lightmap/update.frag"}, rounding + shift + backSidesDefine()},
        {&updateLeafRunProgram, {"lightmap/update.vert", "lightmap/update.frag"},
         rounding + shift + backSidesDefine() + "#define LEAF_TABLE 1\n"},
        {&updateCurvedLeafRunProgram, {"lightmap/curved.vert", "lightmap/update.frag"},
         rounding + shift + backSidesDefine() + "#define CURVED_FOOTPRINT 1\n#define LEAF_TABLE 1\n"},
        {&sunProgram, {"lightmap/update.vert", "lightmap/update.frag"}, shift + "#define SUN_PASS 1\n"},
        {&updateCurvedProgram, {"lightmap/curved.vert", "lightmap/update.frag"},
         rounding + shift + backSidesDefine() + "#define CURVED_FOOTPRINT 1\n"},
        {&sunCurvedProgram, {"lightmap/curved.vert", "lightmap/update.frag"}, shift + "#define SUN_PASS 1\n#define CURVED_FOOTPRINT 1\n"},
        {&sunLeafRunProgram, {"lightmap/update.vert", "lightmap/update.frag"}, shift + "#define SUN_PASS 1\n#define LEAF_TABLE 1\n"},
        {&sunCurvedLeafRunProgram, {"lightmap/curved.vert", "lightmap/update.frag"},
         shift + "#define SUN_PASS 1\n#define CURVED_FOOTPRINT 1\n#define LEAF_TABLE 1\n"},
        {&resolveProgram, {"lightmap/resolve.comp"}, ""},
        {&rescaleProgram, {"lightmap/rescale.comp"}, rounding},
        {&noiseProgram, {"lightmap/noise.comp"}, ""},
        {&metaProgram, {"lightmap/meta.vert", "lightmap/meta.frag"}, rounding},
        {&coverageProgram, {"lightmap/meta.vert", "lightmap/meta.frag"}, "#define COVERAGE 1\n"},
        {&dilateProgram, {"lightmap/dilate.comp"}, ""},
        {&readModesProgram, {"lightmap/read_modes.comp"}, ""},
        {&directFoldProgram, {"lightmap/direct_fold.comp"}, rounding},
        {&distanceProgram, {"direct/distance.vert", "direct/distance.frag"}, ""},
        {&emitterProgram, {"direct/emitter.vert", "direct/emitter.frag"}, shift},
        {&emitterCurvedProgram, {"lightmap/curved.vert", "direct/emitter.frag"}, shift + "#define CURVED_FOOTPRINT 1\n"},
        {&emitterFoldProgram, {"direct/emitter_fold.comp"}, ""},
        {&emitterNoiseProgram, {"direct/direct_noise.comp"}, ""},
        {&sunNoiseProgram, {"direct/direct_noise.comp"}, "#define SUN 1\n"},
        {&punctualProgram, {"direct/emitter.vert", "direct/punctual.frag"}, shift},
        {&punctualCurvedProgram, {"lightmap/curved.vert", "direct/punctual.frag"}, shift + "#define CURVED_FOOTPRINT 1\n"},
    };
    for (auto& s : specs) {
        auto p = gl::buildProgram(s.files, s.defines);
        if (!p) return p.status();
        *s.target = std::move(p.value());
    }
    return Status::ok();
}

void Baker::Impl::uploadMesh() {
    MemoryCategory category("mesh");
    charts = findLightmapCharts(mesh);
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        mesh.triangles[t].flags |= (charts[t] & TEXEL_CHART_MASK) << TRIANGLE_CHART_SHIFT;
    vertexBuffer = gl::Buffer::create("bake vertices", int64_t(mesh.vertices.size() * sizeof(BakeVertex)),
                                      mesh.vertices.data(), 0);
    triangleBuffer = gl::Buffer::create("bake triangles", int64_t(mesh.triangles.size() * sizeof(BakeTriangle)),
                                        mesh.triangles.data(), 0);
    vao = createBakeVertexArray("bake vertex array", vertexBuffer);
}

void Baker::Impl::dispatchPages(GLuint program, int layers) {
    if (layers == 0) layers = layout.pageCount;
    glUniform1i(glGetUniformLocation(program, "pageCount"), layers);
    glUniform2i(glGetUniformLocation(program, "pageSize"), layout.resolution, layout.resolution);
    glDispatchCompute((layout.resolution + 7) / 8, (layout.resolution + 7) / 8, layers);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

void Baker::Impl::rescaleAccumulators(float factor, uint32_t seed) {
    gl::DebugGroup group("rescale accumulators");
    glUseProgram(rescaleProgram.id());
    glUniform1f(rescaleProgram.uniform("factor"), factor);
    glUniform1ui(rescaleProgram.uniform("randomSeed"), seed);
    glBindImageTexture(BINDING_ACCUM, accum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
    dispatchPages(rescaleProgram.id(), stateLayers());
    glBindImageTexture(BINDING_ACCUM, halfAccum.id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_RG32UI);
    glUniform2i(rescaleProgram.uniform("pageSize"), halfWidth, halfWidth);
    glDispatchCompute(GLuint(halfWidth + 7) / 8, GLuint(halfWidth + 7) / 8, GLuint(layout.pageCount));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

void Baker::Impl::clearAccumulators() {
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearTexImage(accum.id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, zero);
    glClearTexImage(halfAccum.id(), 0, GL_RG_INTEGER, GL_UNSIGNED_INT, zero);
    const float none[4] = {0, 0, 0, 0};
    glClearTexImage(moments.id(), 0, GL_RGBA, GL_FLOAT, none);
}

void Baker::Impl::uploadMaterials(const Scene& scene) {
    // material textures (linear RGBA, mipmapped)
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        MemoryCategory category("materials");
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
    // each page's triangles in pageDrawOrder (by material): one draw per (page, material) run
    std::vector<uint32_t> order;
    order.reserve(mesh.triangles.size());
    for (int p = 0; p < layout.pageCount; ++p) {
        const std::vector<uint32_t> page = pageDrawOrder(mesh, p);
        order.insert(order.end(), page.begin(), page.end());
    }
    std::vector<uint32_t> indices;
    indices.reserve(order.size() * 3);
    for (size_t i = 0; i < order.size(); ++i) {
        const BakeTriangle& t = mesh.triangles[order[i]];
        if (surfaceRuns.empty() || surfaceRuns.back().page != t.page || surfaceRuns.back().material != t.material)
            surfaceRuns.push_back({i, 0, t.page, t.material});
        ++surfaceRuns.back().count;
        for (uint32_t k = 0; k < 3; ++k) indices.push_back(order[i] * 3 + k);
    }
    MemoryCategory category("mesh");
    metaIndexBuffer = gl::Buffer::create("surface indices (by page, material)", int64_t(indices.size() * 4), indices.data(), 0);
    glVertexArrayElementBuffer(vao.id(), metaIndexBuffer.id());
}

void Baker::Impl::drawSurface(GLuint program, bool materialUniforms) {
    glUseProgram(program);
    glBindFramebuffer(GL_FRAMEBUFFER, pageFbo.id());
    glViewport(0, 0, layout.resolution, layout.resolution);
    const GLint pageUniform = glGetUniformLocation(program, "page");
    const GLint albedoUniform = glGetUniformLocation(program, "albedo");
    const GLint emissionUniform = glGetUniformLocation(program, "emission");
    const GLint hasAlbedoUniform = glGetUniformLocation(program, "hasAlbedoTexture");
    const GLint hasEmissionUniform = glGetUniformLocation(program, "hasEmissionTexture");
    const GLint materialUniform = glGetUniformLocation(program, "material");  // cut-outs (coverage)
    auto setRun = [&](const SurfaceRun& run) {
        glUniform1i(pageUniform, GLint(run.page));
        glUniform1i(materialUniform, GLint(run.material));
        if (!materialUniforms) return;
        const Material& mat = materials[run.material];
        glUniform3fv(albedoUniform, 1, &mat.albedo.x);
        const glm::vec3 emission = mat.emission / radianceUnit;
        glUniform3fv(emissionUniform, 1, &emission.x);
        glUniform1i(hasAlbedoUniform, mat.albedoTexture >= 0);
        glUniform1i(hasEmissionUniform, mat.emissionTexture >= 0);
        if (mat.albedoTexture >= 0) glBindTextureUnit(BINDING_MATERIAL_TEX, materialTextures[mat.albedoTexture].id());
        if (mat.emissionTexture >= 0) glBindTextureUnit(BINDING_MATERIAL_TEX + 1, materialTextures[mat.emissionTexture].id());
    };
    glBindVertexArray(vao.id());  // meta.vert reads attributes only: no per-triangle SSBO to chunk
    for (const SurfaceRun& run : surfaceRuns) {
        setRun(run);
        glDrawElements(GL_TRIANGLES, GLsizei(run.count * 3), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(uintptr_t(run.first) * 3 * sizeof(uint32_t)));
    }
    if (!partialRuns.empty()) glBindVertexArray(partialPointArray.id());
    for (const SurfaceRun& run : partialRuns) {
        setRun(run);
        glDrawArrays(GL_POINTS, GLint(run.first), GLsizei(run.count));
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

std::vector<int32_t> Baker::Impl::bakeTexelOwners(int page, std::vector<uint8_t>* partial) const {
    return fineTexelOwners(mesh, charts, page, outputLayout.resolution, options.supersample, partial);
}

void Baker::Impl::uploadPartialPoints() {
    const int res = layout.resolution;
    std::vector<BakeVertex> points;
    std::vector<std::vector<std::pair<uint32_t, BakeVertex>>> pagePoints(size_t(layout.pageCount));  // (material, point)
    const bool keep = int64_t(res) * res * layout.pageCount * int64_t(sizeof(int32_t) + 1) <= kKeptOwnersBytes;
    keptOwners.assign(keep ? size_t(layout.pageCount) : 0, PageOwners{});
    parallelFor(pagePoints.size(), [&](size_t pageIndex) {  // each page its own points
        const int p = int(pageIndex);
        PageOwners taken;
        PageOwners& own = keep ? keptOwners[pageIndex] : taken;
        own.owners = bakeTexelOwners(p, &own.partial);
        const std::vector<uint8_t>& partial = own.partial;
        const std::vector<int32_t>& owners = own.owners;
        std::vector<std::pair<uint32_t, BakeVertex>>& page = pagePoints[pageIndex];
        for (size_t i = 0; i < owners.size(); ++i) {
            if (!partial[i]) continue;
            const uint32_t t = uint32_t(owners[i]);
            const BakeVertex* v = &mesh.vertices[3 * size_t(t)];
            // the owner's point nearest the centre, near enough: its barycentrics clamped
            const glm::dvec2 c(double(i % size_t(res)) + 0.5, double(i / size_t(res)) + 0.5);
            glm::dvec2 q[3];
            for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(v[k].lightmapUv) * double(res);
            const double det = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x);
            const double b1 = ((c.x - q[0].x) * (q[2].y - q[0].y) - (c.y - q[0].y) * (q[2].x - q[0].x)) / det;
            const double b2 = ((q[1].x - q[0].x) * (c.y - q[0].y) - (q[1].y - q[0].y) * (c.x - q[0].x)) / det;
            glm::dvec3 b = glm::max(glm::dvec3(1.0 - b1 - b2, b1, b2), glm::dvec3(0.0));
            b /= b.x + b.y + b.z;
            BakeVertex point{};
            for (int k = 0; k < 3; ++k) {
                point.position += v[k].position * float(b[k]);
                point.normal += v[k].normal * float(b[k]);
                point.uv0 += v[k].uv0 * float(b[k]);
            }
            point.lightmapUv = glm::vec2(c / double(res));
            page.emplace_back(mesh.triangles[t].material, point);
        }
        std::stable_sort(page.begin(), page.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    });
    for (int p = 0; p < layout.pageCount; ++p) {
        for (const auto& [material, point] : pagePoints[size_t(p)]) {
            if (partialRuns.empty() || partialRuns.back().page != uint32_t(p) || partialRuns.back().material != material)
                partialRuns.push_back({points.size(), 0, uint32_t(p), material});
            ++partialRuns.back().count;
            points.push_back(point);
        }
    }
    if (points.empty()) return;
    MemoryCategory category("mesh");
    partialPointBuffer = gl::Buffer::create("partial texels' points", int64_t(points.size() * sizeof(BakeVertex)),
                                            points.data(), 0);
    partialPointArray = createBakeVertexArray("partial texels' points", partialPointBuffer);
}

void Baker::Impl::coveragePass() {
    gl::DebugGroup group("coverage");
    const uint8_t none = DILATION_NONE;
    glClearTexImage(dilation.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_BYTE, &none);
    glBindImageTexture(BINDING_DILATION, dilation.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R8UI);
    bindAlphaMasks();  // a cut-away texel centre is not covered
    // the partial texels' points (texelOwners, page by page; the loop below takes
    // each page's owners again rather than holding every page's at once)
    uploadPartialPoints();
    drawSurface(coverageProgram.id(), false);
    // padding: the nearest covered texel, page by page on the CPU (once)
    const int res = layout.resolution;
    const int radius = std::min(std::max(layout.padding, 1) + 1, DILATION_RADIUS);
    std::vector<uint8_t> codes(size_t(res) * res), neighbours(codes.size());
    std::vector<uint16_t> ownerCharts(codes.size());
    std::vector<std::vector<CurvedTexel>> curved(size_t(layout.pageCount));
    // the curved texels' records are SSBOs: their triangles' (144 B each, at most one a reference) within one binding
    GLint64 maxSsbo = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxSsbo);
    int64_t curvedRefs = 0, flatInstead = 0;
    // each page's texels on the CPU (pure functions of the mesh and layout), a
    // page a core at a time within threadsWithin's memory; what follows in page
    // order on this thread
    struct PageTexels {
        std::vector<uint8_t> partial;
        std::vector<int32_t> owners;
        std::vector<TexelFootprint> footprints;
        int64_t shared = 0;
    };
    const int batch = int(threadsWithin(int64_t(res) * res * int64_t(sizeof(int32_t) + 1 + sizeof(TexelFootprint) + sizeof(uint64_t))));
    std::vector<PageTexels> pageTexels;
    for (int p = 0; p < layout.pageCount; ++p) {
        if (p % batch == 0) {
            pageTexels.assign(size_t(std::min(batch, layout.pageCount - p)), PageTexels{});
            parallelFor(pageTexels.size(), [&, first = p](size_t i) {
                PageTexels& t = pageTexels[i];
                const int page = first + int(i);
                if (size_t(page) < keptOwners.size()) {  // taken by uploadPartialPoints
                    t.owners = std::move(keptOwners[size_t(page)].owners);
                    t.partial = std::move(keptOwners[size_t(page)].partial);
                } else {
                    t.owners = bakeTexelOwners(page, &t.partial);
                }
                t.footprints = texelFootprints(mesh, page, res, t.owners, charts);
                curved[size_t(page)] = curvedTexels(mesh, page, res, t.owners, charts, t.partial, t.footprints);
                t.shared = int64_t(sharedTexels(mesh, page, res, t.owners, charts));
            });
        }
        const PageTexels& texels = pageTexels[size_t(p % batch)];
        const std::vector<uint8_t>& partial = texels.partial;
        const std::vector<int32_t>& owners = texels.owners;
        const std::vector<TexelFootprint>& footprints = texels.footprints;
        gl::readTexture(dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, codes.data());
        std::erase_if(curved[size_t(p)], [&](const CurvedTexel& c) {
            if (codes[c.texel] != DILATION_SELF) return true;
            curvedRefs += int64_t(c.triangles.size());
            if (curvedRefs * int64_t(sizeof(CurvedTriangle)) <= maxSsbo) return false;
            // past the binding's size: a texel whose centre is on its chart is baked
            // along its owner's plane, a partial one not at all (padding)
            ++flatInstead;
            if (partial[c.texel]) codes[c.texel] = DILATION_NONE;
            return true;
        });
        stats.coveredTexels += std::count(codes.begin(), codes.end(), uint8_t(DILATION_SELF));
        for (size_t i = 0; i < codes.size(); ++i) stats.partialTexels += partial[i] && codes[i] == DILATION_SELF;
        for (const CurvedTexel& c : curved[size_t(p)]) stats.exactFootprintTexels += c.exact;
        chartNeighbourBits(codes, owners, charts, res, neighbours);
        ownerChartCodes(owners, charts, ownerCharts);
        for (const CurvedTexel& c : curved[size_t(p)]) ownerCharts[c.texel] |= TEXEL_CURVED;
        gl::writeTexture(texelCharts.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_SHORT, 2, ownerCharts.data());
        stats.sharedTexels += texels.shared;
        {
            std::vector<glm::uvec4> packed(footprints.size());
            for (size_t i = 0; i < packed.size(); ++i) {
                const TexelFootprint& f = footprints[i];
                packed[i] = glm::uvec4(uint32_t(f.cells), uint32_t(f.cells >> 32), f.edge | uint32_t(f.area) << 24, f.spread);
            }
            gl::writeTexture(footprint.id(), 0, 0, p, res, res, 1, GL_RGBA_INTEGER, GL_UNSIGNED_INT, 16, packed.data());
        }
        gl::writeTexture(chartNeighbours.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1,
                         neighbours.data());
        dilationCodes(codes, res, radius);
        gl::writeTexture(dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, codes.data());
    }
    keptOwners = {};
    uploadCurvedTexels(curved);
    if (flatInstead > 0)
        logWarning(std::to_string(flatInstead) + " texels whose charts curve within them (or miss their centres) are "
                   "baked as flat ones (or padding): the curved texels' records would pass "
                   "GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" + std::to_string(maxSsbo) +
                   " bytes); lower --resolution or --texel-density");
    stats.lightmapTexels = int64_t(res) * res * layout.pageCount;
    if (stats.sharedTexels * 100 > stats.coveredTexels)  // over 1 %: worth the user's look
        logWarning(std::to_string(stats.sharedTexels) + " of " + std::to_string(stats.coveredTexels) +
                   " covered light map texels also hold part of another chart (TEXCOORD_1 charts closer than a texel "
                   "at this density): their light bleeds between the charts; raise --resolution or --texel-density, "
                   "or space the charts further apart");
}

void Baker::Impl::uploadCurvedTexels(const std::vector<std::vector<CurvedTexel>>& pages) {
    MemoryCategory category("light maps");
    CurvedFootprints curved = buildCurvedFootprints(mesh, clusters, layout.resolution, pages);
    stats.curvedTexels = int64_t(curved.count());
    if (curved.count() == 0) return;
    curvedTexelBuffer = gl::Buffer::create("curved texels", int64_t(curved.texels.size() * sizeof(glm::uvec4)),
                                           curved.texels.data(), 0);
    curvedRefBuffer = gl::Buffer::create("curved texels' triangles", int64_t(curved.refs.size() * 4), curved.refs.data(), 0);
    curvedTriangleBuffer = gl::Buffer::create("curved triangles", int64_t(curved.triangles.size() * sizeof(CurvedTriangle)),
                                              curved.triangles.data(), 0);
    curvedClusterFirst = std::move(curved.clusterFirst);
    pointArray = gl::VertexArray::create("curved texels' rectangles (no attributes)");
    stats.curvedTexelBytes = curved.bytes();
    stats.lightmapStateBytes += curved.bytes();
}

void Baker::Impl::bindCurvedTexels(GLuint program) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_CURVED_TEXELS, curvedTexelBuffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_CURVED_REFS, curvedRefBuffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_CURVED_TRIANGLES, curvedTriangleBuffer.id());
    glUniform1i(glGetUniformLocation(program, "pageResolution"), layout.resolution);
    glBindVertexArray(pointArray.id());
}

void Baker::Impl::sanitizeInputs(const Scene& scene) {
    // inputs the passes cannot take: one warning each, then read as 0 (or 1 for albedo)
    float rhoMax = 0.0f;
    for (Material& m : materials) {
        if (!(glm::all(glm::greaterThanEqual(m.emission, glm::vec3(0.0f))) && std::isfinite(glm::length(m.emission)))) {
            logWarning("material " + m.name + ": emission not finite and >= 0; baked as 0");
            m.emission = glm::vec3(0.0f);
        }
        if (glm::any(glm::greaterThan(m.albedo, glm::vec3(1.0f))))
            logWarning("material " + m.name + ": albedo above 1 (energy would grow with each bounce); clamped to 1");
        m.albedo = glm::clamp(m.albedo, 0.0f, 1.0f);
        if (!std::isfinite(m.albedo.r + m.albedo.g + m.albedo.b)) m.albedo = glm::vec3(0.0f);
        rhoMax = std::max({rhoMax, m.albedo.r, m.albedo.g, m.albedo.b});
    }
    float peak = 0.0f;  // the brightest source radiance
    for (const Material& m : materials) {
        float texMax = 1.0f;
        if (m.emissionTexture >= 0)
            for (const glm::vec4& t : scene.textures[size_t(m.emissionTexture)].texels) texMax = std::max({texMax, t.r, t.g, t.b});
        peak = std::max(peak, std::max({m.emission.r, m.emission.g, m.emission.b}) * texMax);
    }
    peak = std::max({peak, options.sky.r, options.sky.g, options.sky.b});
    for (const DirectionalLight& l : lights)
        peak = std::max(peak, std::max({l.irradiance.r, l.irradiance.g, l.irradiance.b}) / 3.14159265f);
    if (options.environment) {
        size_t bad = 0;
        for (glm::vec3& p : options.environment->pixels)
            for (int c = 0; c < 3; ++c) {
                if (!(p[c] >= 0.0f && std::isfinite(p[c]))) {
                    p[c] = 0.0f;
                    ++bad;
                }
                peak = std::max(peak, p[c]);
            }
        if (bad) logWarning(std::to_string(bad) + " environment values are NaN, infinite or negative; read as 0");
    }
    // The light-map state (fp16, RGB9E5) holds radiance / radianceUnit: a power
    // of two that keeps the brightest light map value expected, the brightest
    // source after every bounce (/ (1 - rho_max)), below 2^12 (16x under the
    // fp16 maximum) and the brightest source above 2^-10 (fp16 normals below).
    // 1 for every scene between: their bytes do not change. Exact (a power of two).
    const double expected = double(peak) / (1.0 - std::min(double(rhoMax), 0.999));
    radianceUnit = 1.0f;
    if (expected > 4096.0) radianceUnit = std::ldexp(1.0f, int(std::ceil(std::log2(expected))) - 12);
    else if (peak > 0.0f && peak < 1.0f / 1024.0f) radianceUnit = std::ldexp(1.0f, int(std::floor(std::log2(double(peak)))));
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
    punctualLights = scene.punctualLights;
    inputKey = hashInputs(scene);
    stats.directionsTotal = options.directions;
    if (options.directions < 1) return Status::error("--directions must be at least 1");
    // the sun's sample count is the direct map's fp16 alpha, exact to 2048 (45^2 = 2025)
    if (options.sunJitter < 0 || options.sunJitter > kMaxSunJitter)
        return Status::error("--sun-jitter must be 0 to " + std::to_string(kMaxSunJitter));
    if (options.share && (options.share->count() < 1 || options.share->index() < 0 ||
                          options.share->index() >= options.share->count()))
        return Status::error("a direction share needs 0 <= index < count");
    if (mesh.triangles.empty()) return Status::error("nothing to bake: the scene has no triangles");

    GLint maxTex = 0, maxLayers = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTex);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    if (layout.resolution > maxTex)
        return Status::error("--resolution " + std::to_string(layout.resolution) + " exceeds GL_MAX_TEXTURE_SIZE " +
                             std::to_string(maxTex));
    if (hasBackSides(mesh)) backLayerOffset = layout.pageCount;
    if (stateLayers() > maxLayers)
        return Status::error(std::to_string(layout.pageCount) + " light map pages" +
                             (backLayerOffset ? " (twice over: double-sided materials)" : "") +
                             " exceed GL_MAX_ARRAY_TEXTURE_LAYERS " + std::to_string(maxLayers) +
                             "; raise --resolution or lower --texel-density");

    // scene frame: bounding sphere of the bounds box
    sphereCenter = mesh.bounds.center();
    sphereRadius = std::max(0.5f * glm::length(mesh.bounds.size()), 1e-6f) * 1.001f;
    depthBias = 4e-6f * (glm::length(sphereCenter) + sphereRadius);

    // culling units: the triangles reordered into spatially coherent clusters
    clusters = clusterMesh(mesh);
    stats.triangles = int64_t(mesh.triangles.size());
    // importance (supplement §1) decides each leaf's pixel size
    {
        auto t = Clock::now();
        MemoryCategory category("importance");
        auto analyzer = ImportanceAnalyzer::create();
        if (!analyzer) return analyzer.status();
        auto result = (*analyzer)->analyze(mesh, layout.resolution);
        if (!result) return result.status();
        std::vector<float>& importance = result->importance.importance;
        for (size_t t = 0; t < importance.size(); ++t) {
            const float raised = curvatureImportance(&mesh.vertices[3 * t], importance[t], tilerOptions.pixelsPerTexel);
            stats.curvatureRefinedTriangles += raised > importance[t];
            importance[t] = raised;
        }
        setClusterImportance(mesh, clusters, importance);
        stats.clusters = int64_t(clusters.size());
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
    texelSize = 1.0 / density;
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

    // The largest albedo sets how many bounces the light needs: what a path
    // keeps after b bounces is rho^b. The history ramp's power grows with it
    // (early rounds saw fewer bounces): 2 rho / (1 - rho)^1.5, i.e. 3 for
    // rho 0.5, 15 for 0.78 (the Cornell box), 57 for 0.9, 1024 (the cap) for
    // 0.99. With 2 rho / (1 - rho) (18 at 0.9, 198 at 0.99) the furnaces read
    // 1.1 % low at rho 0.9 and 256 directions (now 0.1 %) and 1.35 % low at
    // rho 0.99 and 4096 (now 0.36 %), while the Cornell box's error moved
    // from 4.0 to 4.2 % at 256 directions and 2.33 to 2.38 % at 1024 (fewer
    // rounds count). The radiance is refreshed after every round until
    // rho^b < 1e-3: ln 1000 / (1 - rho) rounds, 14 for rho 0.5, 66 for 0.9,
    // 688 for 0.99, and never fewer than 64. A textured material's albedo is
    // its factor times its texture's mean (the factor alone counted a
    // factor 1 on a dark texture as rho 1: the ramp's power 1024, only the
    // last half of the directions counting, and a refresh after each of the
    // first 690 rounds). mixed_lighting's red velvet is rho 0.995 in red.
    // Since 2026-12-04 that albedo is the scene's transport albedo (bake/
    // transport_albedo.h), the share of the light that comes back each bounce,
    // not the largest albedo: the same in a closed room of one albedo, less
    // where light escapes (mixed_lighting's velvet, the city under its sky).
    std::vector<glm::vec3> albedos;
    std::vector<bool> doubleSided;
    for (const auto& m : materials) {
        albedos.push_back(m.albedo * (m.albedoTexture >= 0 ? textureMeans[size_t(m.albedoTexture)] : glm::vec3(1.0f)));
        doubleSided.push_back(m.doubleSided);
    }
    const TransportAlbedo transport = transportAlbedo(mesh, albedos, doubleSided);
    const double rho = std::min(transport.lambda, 0.99);
    stats.transportAlbedo = rho;
    stats.transportAlbedoSlowest = std::min(transport.slowest, 0.99);  // where the ramp's plateau waits for (noise.cpp)
    historyPower = options.historyPower >= 0 ? options.historyPower : defaultHistoryPower(rho);
    refreshEveryRound = std::max(64, int(std::ceil(std::log(1000.0) / (1.0 - rho))));
    stats.historyPower = historyPower;
    directions = makeDirections(options.directions, options.seed);
    sanitizeInputs(scene);
    stats.radianceUnit = radianceUnit;

    Status s = buildPrograms();
    if (!s) return s;
    const int64_t gpuAtStart = MemoryTracker::gpu().current();
    uploadMesh();
    // the noise estimate's sampled texels and, for a supersampled bake, their
    // half-size texels' weights (the reduction's, fineTexelWeights: CPU work on
    // the mesh and layout, its charts from uploadMesh; done beside the GL setup below)
    const int outputRes = outputLayout.resolution, k = options.supersample;
    stats.noiseStride = std::clamp(int(std::bit_floor(unsigned(std::max(1, outputRes / 256)))), 1, 16);
    halfWidth = (outputRes + stats.noiseStride - 1) / stats.noiseStride * k;
    std::future<std::vector<float>> noiseWeightValues = std::async(std::launch::async, [this, outputRes, k] {
        const int pages = layout.pageCount;
        std::vector<float> weights(size_t(halfWidth) * halfWidth * size_t(pages), 1.0f);
        if (k > 1)
            parallelFor(size_t(pages), [&](size_t p) {  // each page its own slice
                const std::vector<float> fine = fineTexelWeights(mesh, charts, int(p), outputRes, k);
                for (int y = 0; y < halfWidth; ++y)
                    for (int x = 0; x < halfWidth; ++x) {
                        const int fx = x / k * stats.noiseStride * k + x % k, fy = y / k * stats.noiseStride * k + y % k;
                        weights[(p * halfWidth + size_t(y)) * halfWidth + size_t(x)] =
                            fx < k * outputRes && fy < k * outputRes ? fine[size_t(fy) * size_t(k * outputRes) + size_t(fx)] : 0.0f;
                    }
            });
        return weights;
    });
    const int pages = layout.pageCount, res = layout.resolution;
    {
        MemoryCategory category("light maps");
        accum = gl::Texture::create2DArray("accumulators (mean RGB + W)", GL_RG32UI, res, res, stateLayers());
        radiance = gl::Texture::create2DArray("outgoing radiance (RGB9E5)", GL_RGB9_E5, res, res, stateLayers());
        direct = gl::Texture::create2DArray("direct light (fp16)", GL_RGBA16F, res, res, pages);
        dilation = gl::Texture::create2DArray("dilation codes", GL_R8UI, res, res, pages);
        chartNeighbours = gl::Texture::create2DArray("same-chart neighbours", GL_R8UI, res, res, pages);
        footprint = gl::Texture::create2DArray("texel footprints on their charts", GL_RGBA32UI, res, res, pages);
        texelCharts = gl::Texture::create2DArray("texel owners' charts", GL_R16UI, res, res, pages);
        readModes = gl::Texture::create2DArray("radiance read modes", GL_R8UI, res, res, stateLayers());
        moments = gl::Texture::create2DArray("texels' first moments", GL_RGBA32F, res, res, stateLayers());
        slopes = gl::Texture::create2DArray("texels' slopes inside them", GL_RGBA16F, res, res, stateLayers());
        accumAsFloat = gl::Texture::createView("accumulators as rg32f (direct light sums)", accum, GL_RG32F);
        radianceBits = gl::Texture::createView("outgoing radiance as r32ui", radiance, GL_R32UI);
        radianceAsFloat = gl::Texture::createView("outgoing radiance as r32f (direct light sums)", radiance, GL_R32F);
    }
    stats.lightmapStateBytes =
        accum.bytes() + radiance.bytes() + direct.bytes() + dilation.bytes() + chartNeighbours.bytes() + readModes.bytes() +
        footprint.bytes() + texelCharts.bytes() + moments.bytes() + slopes.bytes();
    {
        // the noise estimate's half: about 256^2 sampled texels a page, every texel of small pages
        MemoryCategory category("noise estimate");
        halfAccum = gl::Texture::create2DArray("noise estimate: odd directions' accumulators", GL_RG32UI, halfWidth,
                                               halfWidth, pages);
        noiseTerms = gl::Texture::create2DArray("noise estimate terms", GL_RGBA32F, halfWidth / k, halfWidth / k, pages);
        // the sampled texels' half-size texels' weights (the reduction's: fineTexelWeights; whole texels 1)
        noiseWeights = gl::Texture::create2DArray("noise estimate: half-size texels' weights", GL_R16F, halfWidth, halfWidth, pages);
    }
    const uint32_t zero[4] = {0, 0, 0, 0};
    clearAccumulators();
    glClearTexImage(radianceBits.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, zero);
    glClearTexImage(direct.id(), 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(slopes.id(), 0, GL_RGBA, GL_FLOAT, zero);
    pageFbo = gl::Framebuffer::create("light map page framebuffer (no attachments)");
    glNamedFramebufferParameteri(pageFbo.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, res);
    glNamedFramebufferParameteri(pageFbo.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, res);
    uploadMaterials(scene);
    uploadAlphaMasks(scene);
    if (options.environment) {
        MemoryCategory category("materials");
        const auto& env = *options.environment;
        envTexture = gl::Texture::create2D("environment", GL_RGBA32F, env.width, env.height);
        std::vector<glm::vec4> rgba(env.pixels.size());
        for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = glm::vec4(env.pixels[i] / radianceUnit, 1.0f);
        // file row 0 is the top (theta = 0): texture t = theta / pi, so upload rows top-down as t = 0..1
        glTextureSubImage2D(envTexture.id(), 0, 0, 0, env.width, env.height, GL_RGBA, GL_FLOAT, rgba.data());
        glTextureParameteri(envTexture.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(envTexture.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(envTexture.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
    }

    // coverage, the footprints' cells and the curved texels (light map state: within the budget's fixed part)
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    coveragePass();
    gl::writeTexture(noiseWeights.id(), 0, 0, 0, halfWidth, halfWidth, pages, GL_RED, GL_FLOAT, 4,
                     noiseWeightValues.get().data());

    // The budget: what the light maps, mesh and materials (all fixed by the
    // scene and layout) leave goes to the bundle pass's node buffer and head
    // image, within the GL limits. Tile limits are all read from GL: a leaf's
    // grid is one viewport; a tile's side is the head image's; the node buffer
    // is one SSBO binding.
    const int64_t fixedBytes = MemoryTracker::gpu().current() - gpuAtStart;
    stats.memoryBudget = options.memoryBudget;
    const int64_t leftBytes = options.memoryBudget - fixedBytes;
    int64_t bundleBytes = options.bundleMemory > 0 ? options.bundleMemory : leftBytes;
    // the direct light's passes run first, in what the bundle pass's buffers will take
    constexpr int64_t kMinBundleBytes = 64 * 64 * 4 + 1024 * 12;
    const int64_t directBytes = directLightPeakBytes();
    if (bundleBytes < kMinBundleBytes || leftBytes < directBytes) {
        auto mib = [](int64_t b) { return std::to_string((b + (1 << 20) - 1) >> 20) + " MiB"; };
        return Status::error("--memory-budget " + mib(options.memoryBudget) + " is too small: the light maps take " +
                             mib(stats.lightmapStateBytes) + ", the mesh and materials " +
                             mib(fixedBytes - stats.lightmapStateBytes) +
                             (directBytes ? ", the direct light's passes " + mib(directBytes) : std::string()) +
                             "; give at least " + mib(fixedBytes + std::max<int64_t>(16 << 20, directBytes)));
    }
    maxTileSize = std::min({maxTex, maxViewport, 2048});
    while (maxTileSize > 64 && int64_t(maxTileSize) * maxTileSize * 4 > bundleBytes / 4) maxTileSize /= 2;
    int64_t headBytes = int64_t(maxTileSize) * maxTileSize * 4;
    GLint64 maxSsbo = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxSsbo);
    nodeCapacity = std::min<int64_t>({(bundleBytes - headBytes) / 12, maxSsbo / 12, int64_t(0xFFFFFFFEll)});
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
    historyPlateau = chooseHistoryPlateau();  // the lag model needs the pixels a texel spans
    stats.historyPlateau = historyPlateau;
    {
        // the bundle pass: its buffers start small and grow to what the tiles predict
        MemoryCategory category("bundles");
        const BundleScene scene{&mesh, &clusters, vao.id(), vertexBuffer.id(), triangleBuffer.id(),
                                radiance.id(), readModes.id(), texelCharts.id(), slopes.id(), pageFbo.id(), res,
                                materialAlphaBuffer.id(), alphaTexelBuffer.id(), backLayerOffset};
        const BundleLimits limits{nodeCapacity, maxTileSize, subpixelBits, options.predictTiles};
        auto t = BundleTracer::create(scene, limits, roundingDefine() + backSidesDefine(), &stats);
        if (!t) return t.status();
        tracer = std::move(t.value());
    }

    if (!curvedClusterFirst.empty())
        tracer->setCurvedTexels(curvedClusterFirst, [this](GLuint program) { bindCurvedTexels(program); });
    stats.secondsSetup = secondsSince(t0);

    // the direct light, summed in float in views of the accumulators and the
    // radiance map (both still unused), folded into the fp16 direct map
    stats.explicitEmitters = useExplicitEmitters();
    auto te = Clock::now();
    if (stats.explicitEmitters) {
        bakeEmitters();
        foldDirect(false);
    }
    if (!punctualLights.empty()) {
        bakePunctualLights();
        foldDirect(false);
    }
    glFinish();
    stats.secondsEmitters = secondsSince(te);
    auto ts = Clock::now();
    bakeSun();
    glFinish();
    stats.secondsSun = secondsSince(ts);
    auto tr = Clock::now();
    refreshRadiance(0xFFFFFFFFu);
    stats.secondsResolve += secondsSince(tr);
    noteMemory();
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
    if (options.supersample < 0 || options.supersample > 4 || options.supersample == 3)
        return Status::error("supersample must be 0 (auto), 1, 2 or 4, not " + std::to_string(options.supersample));
    impl->options = options;
    int& k = impl->options.supersample;
    if (k == 0) {
        const BakeMesh mesh = buildBakeMesh(scene, layout);
        k = autoSupersample(mesh, findLightmapCharts(mesh), layout,
                            options.memoryBudget - largestDistanceCubeBytes(scene, mesh, options));
    }
    impl->stats.supersample = k;
    impl->outputLayout = layout;
    impl->layout = k > 1 ? supersampledLayout(layout, k) : layout;
    impl->mesh = buildBakeMesh(scene, impl->layout);
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
    while (stats.directionsDone < directionsGoal()) {
        if (wholeDirections)
            stepDirection();
        else
            stepTile();
        if (secondsSince(t0) >= seconds) break;
    }
    if (stats.directionsDone >= directionsGoal() && !probed) probeResolution();
    noteMemory();
}

void Baker::Impl::noteMemory() {
    stats.peakGpuBytes = MemoryTracker::gpu().peak();
    stats.peakGpuBytesByCategory.clear();
    for (const auto& [name, f] : MemoryTracker::gpu().categories())
        if (f.peak > 0) stats.peakGpuBytesByCategory[name] = f.peak;
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
    return {impl_->stats.directionsDone, impl_->directionsGoal(), impl_->directionActive, impl_->combined};
}

LightmapPages Baker::readLightmaps() {
    Impl& m = *impl_;
    const int res = m.layout.resolution;
    // resolved band by band: at most 64 MiB of GL memory, and what the budget leaves
    const int64_t room = std::min<int64_t>(int64_t(64) << 20, m.options.memoryBudget - MemoryTracker::gpu().current());
    const int rows = int(std::clamp<int64_t>(room / (int64_t(res) * 16), 1, res));
    gl::Texture band;
    {
        MemoryCategory category("read-back");
        band = gl::Texture::create2DArray("light map read-back band", GL_RGBA32F, res, rows, 1);
    }
    std::vector<glm::vec4> texels(size_t(res) * rows);
    LightmapPages out;
    out.resolution = res;
    for (int p = 0; p < m.layout.pageCount; ++p) {
        io::ImageRgb img;
        img.width = img.height = res;
        img.pixels.resize(size_t(res) * res);
        std::vector<uint8_t> cov(size_t(res) * res);
        gl::readTexture(m.dilation.id(), 0, 0, p, res, res, 1, GL_RED_INTEGER, GL_UNSIGNED_BYTE, 1, cov.data());
        for (uint8_t& c : cov) c = c == DILATION_SELF;
        for (int y0 = 0; y0 < res; y0 += rows) {
            const int n = std::min(rows, res - y0);
            m.resolveInto(band, y0, n, p, 1);
            gl::readTexture(band.id(), 0, 0, 0, res, n, 1, GL_RGBA, GL_FLOAT, 16, texels.data());
            for (size_t i = 0; i < size_t(n) * res; ++i) img.pixels[size_t(y0) * res + i] = glm::vec3(texels[i]);
        }
        out.pages.push_back(std::move(img));
        out.covered.push_back(std::move(cov));
    }
    m.noteMemory();
    if (m.options.supersample == 1) return out;
    LightmapPages reduced = reduceLightmaps(out, m.mesh, m.charts, m.outputLayout);
    if (reduced.lostTexels > 0 && m.stats.supersampleLostTexels == 0)
        logWarning(std::to_string(reduced.lostTexels) + " covered light map texels hold no half-size texel of their chart, nor "
                   "a neighbour on it (charts packed tighter than a texel?): left as padding; --supersample 1 bakes them");
    m.stats.supersampleFilledTexels = reduced.filledTexels;
    m.stats.supersampleLostTexels = reduced.lostTexels;
    return reduced;
}

std::vector<std::vector<glm::vec4>> Baker::readAccumulators() {
    Impl& m = *impl_;
    const int res = m.layout.resolution;
    std::vector<glm::uvec2> raw(size_t(res) * res);
    std::vector<std::vector<glm::vec4>> out(size_t(m.layout.pageCount));
    for (int p = 0; p < m.layout.pageCount; ++p) {
        gl::readTexture(m.accum.id(), 0, 0, p, res, res, 1, GL_RG_INTEGER, GL_UNSIGNED_INT, 8, raw.data());
        for (const glm::uvec2& v : raw) {
            const glm::vec4 state = decodeAccumulator(v);
            out[size_t(p)].push_back(glm::vec4(glm::vec3(state) * m.radianceUnit, state.a));
        }
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
        [&](const TileFrame& f, uint32_t) {
            cap.u = f.u;
            cap.v = f.v;
            cap.origin = f.rootOrigin;
            cap.pixelSize = f.pixelSize;
            cap.width = f.window.width;
            cap.height = f.window.height;
            return BundleTracer::UpdatePrograms{};  // no update
        });
    cap.nodeCount = m.tracer->lastNodeCount();
    if (cap.width == 0) return cap;  // nothing drawn
    const int headSide = m.tracer->headSide();
    std::vector<uint32_t> heads(size_t(headSide) * headSide);
    gl::readTexture(m.tracer->heads().id(), 0, 0, 0, headSide, headSide, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, 4, heads.data());
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
                cap.radiance[k].push_back(decodeRgbe(nodes[i].radiance) * m.radianceUnit);
            }
        }
    return cap;
}

const BakeStats& Baker::stats() const { return impl_->stats; }
const BakeMesh& Baker::mesh() const { return impl_->mesh; }

void Baker::resolveLightmaps() {
    Impl& m = *impl_;
    if (!m.resolved) {
        MemoryCategory category("viewer");
        m.resolved = gl::Texture::create2DArray("resolved light map", GL_RGBA32F, m.layout.resolution,
                                                m.layout.resolution, m.layout.pageCount);
    }
    m.resolveInto(m.resolved, 0, m.layout.resolution, 0, m.layout.pageCount);
}

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
