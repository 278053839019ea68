// Checkpoints: the accumulators, the radiance map and the progress, written
// atomically; a bake resumed from one ends on the bytes of an uninterrupted
// bake. A checkpoint holds whole directions.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "bake/baker_impl.h"
#include "bake/rounding.h"
#include "core/check.h"
#include "gl/gl.h"
#include "glsl/shared/bundle_layout.h"
#include <cstdio>

#include "io/image_io.h"

namespace bb {

namespace {
constexpr char CHECKPOINT_MAGIC[8] = {'B', 'B', 'C', 'K', 'P', 'T', '0', '7'};

uint64_t fnv1a(const void* data, size_t bytes, uint64_t h = 1469598103934665603ull) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

// What a checkpoint must match to be resumed: geometry, layout and every option that changes the bytes.
uint64_t checkpointKey(const Baker::Impl& m) {
    const BakeMesh& mesh = m.mesh;
    const BakeOptions& o = m.options;
    uint64_t h = fnv1a(mesh.vertices.data(), mesh.vertices.size() * sizeof(BakeVertex));
    h = fnv1a(mesh.triangles.data(), mesh.triangles.size() * sizeof(BakeTriangle), h);
    // not the memory budget: the bytes do not depend on it (tiling_bake_test), so a bake may resume with another
    const int64_t ints[] = {m.layout.resolution, m.layout.pageCount, o.directions, o.bundleResolution,
                            int64_t(o.tiling), int64_t(o.seed), int64_t(o.rounding), o.sunJitter,
                            o.environment ? 1 : 0, int64_t(o.directLight), o.emitterSamples, o.emitterShadowSize,
                            m.historyPlateau};
    h = fnv1a(ints, sizeof ints, h);
    const double reals[] = {o.sky.r, o.sky.g, o.sky.b, m.historyPower};
    h = fnv1a(reals, sizeof reals, h);
    // a shared bake's bytes depend on how many bakers share it (a bake alone keeps its key)
    if (const int32_t bakers = m.shareCount(); bakers > 1) h = fnv1a(&bakers, sizeof bakers, h);
    if (o.environment) h = fnv1a(o.environment->pixels.data(), o.environment->pixels.size() * sizeof(glm::vec3), h);
    return fnv1a(&m.inputKey, sizeof m.inputKey, h);  // materials, their textures, lights
}

// The counters stats.json reports, carried over a resume.
nlohmann::json statsCounters(const BakeStats& s) {
    return {{"tiles_drawn", s.tilesDrawn}, {"overflows", s.overflows}, {"fragments", s.fragments},
            {"leaf_run_updates", s.leafRunUpdates},
            {"updated_texels", s.updatedTexels}, {"peak_nodes_per_tile", s.peakNodesPerTile},
            {"bundle_triangles_drawn", s.bundleTrianglesDrawn}, {"update_triangles_drawn", s.updateTrianglesDrawn},
            {"seconds", {s.secondsTiling, s.secondsBundle, s.secondsUpdate, s.secondsResolve}},
            {"combines", {s.combines, s.combineBytes, s.secondsCombine}},
            {"noise", {s.noiseRelative, s.noiseTexels}}, {"noise_history", s.noiseHistory},
            {"predicted_over_actual", s.predictedOverActual}, {"tiles_per_direction", s.tilesPerDirection},
            {"leaves_per_direction", s.leavesPerDirection}, {"tile_pixel_sizes", s.tilePixelSizes}};
}

bool restoreStatsCounters(const nlohmann::json& j, BakeStats& s) {
    try {
        s.tilesDrawn = j.at("tiles_drawn");
        s.overflows = j.at("overflows");
        s.leafRunUpdates = j.value("leaf_run_updates", int64_t(0));
        s.fragments = j.at("fragments");
        s.updatedTexels = j.at("updated_texels");
        s.peakNodesPerTile = j.at("peak_nodes_per_tile");
        s.bundleTrianglesDrawn = j.at("bundle_triangles_drawn");
        s.updateTrianglesDrawn = j.at("update_triangles_drawn");
        const auto& t = j.at("seconds");
        s.secondsTiling = t.at(0);
        s.secondsBundle = t.at(1);
        s.secondsUpdate = t.at(2);
        s.secondsResolve = t.at(3);
        const auto& c = j.at("combines");
        s.combines = c.at(0);
        s.combineBytes = c.at(1);
        s.secondsCombine = c.at(2);
        s.noiseRelative = j.at("noise").at(0);
        s.noiseTexels = j.at("noise").at(1);
        s.noiseHistory = j.at("noise_history").get<std::vector<std::pair<int, double>>>();
        s.predictedOverActual = j.at("predicted_over_actual").get<std::vector<double>>();
        s.tilesPerDirection = j.at("tiles_per_direction").get<std::vector<int>>();
        s.leavesPerDirection = j.at("leaves_per_direction").get<std::vector<int>>();
        s.tilePixelSizes = j.at("tile_pixel_sizes").get<std::vector<float>>();
        return true;
    } catch (const nlohmann::json::exception&) {
        return false;
    }
}

struct CheckpointHeader {
    char magic[8];
    uint64_t key;
    int32_t directionsDone;
    int32_t resolution;
    int32_t pages;
    int32_t pad;
    double accumLogScale;
};
}  // namespace

uint64_t Baker::Impl::hashInputs(const Scene& scene) {
    uint64_t h = fnv1a(nullptr, 0);
    for (const Material& mat : scene.materials) {
        const float values[] = {mat.albedo.r, mat.albedo.g, mat.albedo.b, mat.emission.r, mat.emission.g, mat.emission.b};
        const int32_t ints[] = {mat.albedoTexture, mat.emissionTexture, mat.doubleSided ? 1 : 0};
        h = fnv1a(values, sizeof values, h);
        h = fnv1a(ints, sizeof ints, h);
        if (mat.alphaMask) {  // cut-outs (only then: other scenes keep their keys)
            const float alpha[] = {mat.alphaCutoff, mat.alpha};
            h = fnv1a(alpha, sizeof alpha, h);
        }
    }
    for (const Texture& t : scene.textures) h = fnv1a(t.texels.data(), t.texels.size() * sizeof(glm::vec4), h);
    for (const DirectionalLight& l : scene.lights) {
        const float values[] = {l.direction.x, l.direction.y, l.direction.z, l.irradiance.r, l.irradiance.g, l.irradiance.b};
        h = fnv1a(values, sizeof values, h);
    }
    for (const PunctualLight& l : scene.punctualLights) {
        const double position[] = {l.position.x, l.position.y, l.position.z};
        const float values[] = {float(l.type == PunctualLight::Type::Spot), l.direction.x, l.direction.y, l.direction.z,
                                l.intensity.r, l.intensity.g, l.intensity.b, l.range, l.innerConeAngle, l.outerConeAngle};
        h = fnv1a(position, sizeof position, h);
        h = fnv1a(values, sizeof values, h);
    }
    return h;
}

Status Baker::saveCheckpoint(const std::string& path) {
    Impl& m = *impl_;
    // a checkpoint holds whole directions: finish the one in flight (the same tiles an uninterrupted bake draws)
    if (m.directionActive) m.stepDirection();
    // a shared bake: every baker calls this after a combine; baker 0 writes the
    // sums it holds and every baker's counters, and all return once it is written
    std::string counters = statsCounters(m.stats).dump();
    if (m.shareCount() > 1) {
        if (!m.combined) return Status::error("a shared bake's checkpoint must follow a combine");
        nlohmann::json all = nlohmann::json::array();
        for (const std::string& c : m.options.share->gather(counters)) all.push_back(nlohmann::json::parse(c));
        counters = all.dump();
        if (m.shareIndex() > 0) {
            m.options.share->barrier();
            return Status::ok();
        }
    }
    const int res = m.layout.resolution;
    const int pages = m.layout.pageCount, layers = m.stateLayers();
    std::vector<glm::uvec2> raw(size_t(res) * res * layers);
    gl::readTexture(m.accum.id(), 0, 0, 0, res, res, layers, GL_RG_INTEGER, GL_UNSIGNED_INT, 8, raw.data());
    CheckpointHeader h{};
    std::memcpy(h.magic, CHECKPOINT_MAGIC, 8);
    h.key = checkpointKey(m);
    h.directionsDone = m.stats.directionsDone;
    h.resolution = res;
    h.pages = m.layout.pageCount;
    h.accumLogScale = m.accumLogScale;
    // the radiance map too: it is refreshed on a schedule, so it can be older than the accumulators
    std::vector<uint32_t> radiance(raw.size());  // RGB9E5 bits
    gl::readTexture(m.radianceBits.id(), 0, 0, 0, res, res, layers, GL_RED_INTEGER, GL_UNSIGNED_INT, 4, radiance.data());
    // and the noise estimate's half
    std::vector<glm::uvec2> half(size_t(m.halfWidth) * m.halfWidth * pages);
    gl::readTexture(m.halfAccum.id(), 0, 0, 0, m.halfWidth, m.halfWidth, pages, GL_RG_INTEGER, GL_UNSIGNED_INT, 8, half.data());
    // and the texels' moments and the slopes refreshed with the radiance
    std::vector<glm::vec4> moments(raw.size());
    gl::readTexture(m.moments.id(), 0, 0, 0, res, res, layers, GL_RGBA, GL_FLOAT, 16, moments.data());
    std::vector<uint64_t> slopes(moments.size());  // four fp16s a texel
    gl::readTexture(m.slopes.id(), 0, 0, 0, res, res, layers, GL_RGBA, GL_HALF_FLOAT, 8, slopes.data());
    std::string bytes(reinterpret_cast<const char*>(&h), sizeof h);
    bytes.append(reinterpret_cast<const char*>(raw.data()), raw.size() * sizeof(glm::uvec2));
    bytes.append(reinterpret_cast<const char*>(radiance.data()), radiance.size() * sizeof(uint32_t));
    bytes.append(reinterpret_cast<const char*>(half.data()), half.size() * sizeof(glm::uvec2));
    bytes.append(reinterpret_cast<const char*>(moments.data()), moments.size() * sizeof(glm::vec4));
    bytes.append(reinterpret_cast<const char*>(slopes.data()), slopes.size() * sizeof(uint64_t));
    // then the statistics so far (JSON, length first: doubles round-trip exactly;
    // a shared bake's: an array, one per baker)
    const uint64_t countersBytes = counters.size();
    bytes.append(reinterpret_cast<const char*>(&countersBytes), sizeof countersBytes);
    bytes.append(counters);
    Status written = io::writeFileAtomic(path, bytes);
    if (m.shareCount() > 1) m.options.share->barrier();
    return written;
}

Status Baker::loadCheckpoint(const std::string& path) {
    Impl& m = *impl_;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return Status::error("cannot read checkpoint " + path);
    CheckpointHeader h{};
    const int res = m.layout.resolution;
    const size_t texels = size_t(res) * res * m.stateLayers();
    const size_t halfTexels = size_t(m.halfWidth) * m.halfWidth * m.layout.pageCount;
    const size_t mapBytes = sizeof h + texels * (sizeof(glm::uvec2) + sizeof(uint32_t) + sizeof(glm::vec4) + sizeof(uint64_t)) +
                            halfTexels * sizeof(glm::uvec2);
    // every way a file can fail to be this layout's checkpoint, said before anything is read into GL
    const bool headerRead = std::fread(&h, sizeof h, 1, f) == 1;
    size_t fileBytes = 0;
    if (std::fseek(f, 0, SEEK_END) == 0) {
        const long end = std::ftell(f);
        fileBytes = end > 0 ? size_t(end) : 0;
    }
    auto refuse = [&](const std::string& why) {
        std::fclose(f);
        return Status::error(path + " is not a bundlebake checkpoint of this layout: " + why +
                             " (remove it or bake without --resume)");
    };
    if (!headerRead) return refuse("shorter than its " + std::to_string(sizeof h) + "-byte header");
    if (std::memcmp(h.magic, CHECKPOINT_MAGIC, 8) != 0) return refuse("wrong magic or format version");
    if (h.resolution != res || h.pages != m.layout.pageCount)
        return refuse("it holds " + std::to_string(h.pages) + " page(s) of " + std::to_string(h.resolution) + "^2, this bake " +
                      std::to_string(m.layout.pageCount) + " of " + std::to_string(res) + "^2");
    uint64_t countersBytes = 0;
    if (fileBytes < mapBytes + sizeof countersBytes || std::fseek(f, long(mapBytes), SEEK_SET) != 0 ||
        std::fread(&countersBytes, sizeof countersBytes, 1, f) != 1 ||
        fileBytes - mapBytes - sizeof countersBytes != countersBytes)
        return refuse(std::to_string(fileBytes) + " bytes, which is not this layout's light maps (" +
                      std::to_string(mapBytes) + " bytes) and their statistics");
    if (!std::isfinite(h.accumLogScale)) return refuse("corrupt accumulator scale");
    std::vector<glm::uvec2> raw(texels);
    std::vector<uint32_t> radiance(texels);
    std::vector<glm::uvec2> half(halfTexels);
    std::vector<glm::vec4> moments(texels);
    std::vector<uint64_t> slopes(texels);
    const bool ok = std::fseek(f, long(sizeof h), SEEK_SET) == 0 &&
                    std::fread(raw.data(), sizeof(glm::uvec2), raw.size(), f) == raw.size() &&
                    std::fread(radiance.data(), sizeof(uint32_t), radiance.size(), f) == radiance.size() &&
                    std::fread(half.data(), sizeof(glm::uvec2), half.size(), f) == half.size() &&
                    std::fread(moments.data(), sizeof(glm::vec4), moments.size(), f) == moments.size() &&
                    std::fread(slopes.data(), sizeof(uint64_t), slopes.size(), f) == slopes.size();
    std::string counters(countersBytes, '\0');
    const bool countersRead = ok && std::fseek(f, long(mapBytes + sizeof countersBytes), SEEK_SET) == 0 &&
                              std::fread(counters.data(), 1, counters.size(), f) == counters.size();
    std::fclose(f);
    if (!ok || !countersRead) return Status::error("cannot read checkpoint " + path);
    if (h.key != checkpointKey(m))
        return Status::error(path + " was written for another scene or other bake options; remove it or bake without --resume");
    BakeStats restored = m.stats;
    nlohmann::json parsed = nlohmann::json::parse(counters, nullptr, false);
    if (m.shareCount() > 1)  // one per baker
        parsed = parsed.is_array() && parsed.size() == size_t(m.shareCount()) ? parsed[size_t(m.shareIndex())]
                                                                                : nlohmann::json();
    if (!restoreStatsCounters(parsed, restored))
        return Status::error(path + ": corrupt statistics (remove it or bake without --resume)");
    if (h.directionsDone < 0 || h.directionsDone > m.options.directions ||
        (h.directionsDone % m.shareCount() != 0 && h.directionsDone != m.options.directions))
        return Status::error(path + ": corrupt progress count");
    gl::writeTexture(m.accum.id(), 0, 0, 0, res, res, m.stateLayers(), GL_RG_INTEGER, GL_UNSIGNED_INT, 8, raw.data());
    gl::writeTexture(m.radianceBits.id(), 0, 0, 0, res, res, m.stateLayers(), GL_RED_INTEGER, GL_UNSIGNED_INT, 4,
                     radiance.data());
    m.updateReadModes();  // derived from the radiance map, not saved
    gl::writeTexture(m.moments.id(), 0, 0, 0, res, res, m.stateLayers(), GL_RGBA, GL_FLOAT, 16, moments.data());
    gl::writeTexture(m.slopes.id(), 0, 0, 0, res, res, m.stateLayers(), GL_RGBA, GL_HALF_FLOAT, 8, slopes.data());
    gl::writeTexture(m.halfAccum.id(), 0, 0, 0, m.halfWidth, m.halfWidth, m.layout.pageCount, GL_RG_INTEGER,
                     GL_UNSIGNED_INT, 8, half.data());
    m.stats = restored;
    m.stats.directionsDone = h.directionsDone;
    m.accumLogScale = h.accumLogScale;
    if (m.shareIndex() > 0) m.clearAccumulators();  // the sums are baker 0's to hold
    m.combined = true;
    return Status::ok();
}

}  // namespace bb
