// Per-triangle SSBOs bound in chunks (MeshChunks, engine/layout/bake_mesh_gl.h):
// with the chunk limit forced small (setMeshChunkBytesForTesting) a tiny
// city spans a dozen chunks, with boundaries inside cluster ranges, inside
// the renderer's material runs and inside pages; the bake, the importance
// analysis and the renderer must give the same bits as with one chunk.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "importance/importance_gl.h"
#include "layout/bake_mesh.h"
#include "layout/bake_mesh_gl.h"
#include "render/scene_renderer.h"
#include "support/bake_helper.h"

namespace bb::test {
namespace {

// About 1000 triangles of vertices (3 x 48 bytes) per chunk: 11 chunks of the tiny city.
constexpr int64_t SMALL_CHUNK_BYTES = 1000 * 144;

// Restores GL's own limit when a test ends, pass or fail.
struct ChunkLimit {
    explicit ChunkLimit(int64_t bytes) { setMeshChunkBytesForTesting(bytes); }
    ~ChunkLimit() { setMeshChunkBytesForTesting(0); }
};

LayoutOptions cityLayout() { return packLayout(512); }
BakeOptions cityOptions() { return skyOptions(6, 11); }

struct Baked {
    std::vector<std::vector<glm::vec4>> accumulators;
    LightmapPages maps;
    BakeStats stats;
    std::string error;
};

Baked bakeCity(const std::string& path, int64_t chunkBytes) {
    ChunkLimit limit(chunkBytes);
    Baked out;
    SceneBake bake = makeBake(path, cityLayout(), cityOptions());
    if (!bake) {
        out.error = bake.error;
        return out;
    }
    bakeToEnd(*bake.baker);
    out.accumulators = bake.baker->readAccumulators();
    out.maps = bake.baker->readLightmaps();
    out.stats = bake.baker->stats();
    return out;
}

size_t differingAccumulators(const Baked& a, const Baked& b) {
    size_t n = 0;
    for (size_t p = 0; p < a.accumulators.size(); ++p)
        for (size_t i = 0; i < a.accumulators[p].size(); ++i)
            n += std::memcmp(&a.accumulators[p][i], &b.accumulators[p][i], sizeof(glm::vec4)) != 0;
    return n;
}

size_t differingTexels(const LightmapPages& a, const LightmapPages& b) {
    size_t n = 0;
    for (size_t p = 0; p < a.pages.size(); ++p)
        for (size_t i = 0; i < a.pages[p].pixels.size(); ++i)
            n += std::memcmp(&a.pages[p].pixels[i], &b.pages[p].pixels[i], sizeof(glm::vec3)) != 0;
    return n;
}

size_t differingBytes(const Image8& a, const Image8& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i) n += a.rgb[i] != b.rgb[i];
    return n;
}

// The chunk geometry the bake below runs with: several chunks, every range
// offset aligned, boundaries that cut the mesh's 256-triangle clusters.
TEST(MeshChunks, SmallLimitGivesAlignedChunks) {
    BB_REQUIRE_GL();
    GLint align = 0;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
    ChunkLimit limit(SMALL_CHUNK_BYTES);
    const MeshChunks chunks = MeshChunks::create(10632, {{1, 0, 16}, {2, 0, 144}, {3, 0, 4}});
    std::printf("[chunks] offset alignment %d: %lld triangles per chunk, %d chunks\n", align,
                (long long)chunks.chunkTriangles(), chunks.chunkCount());
    EXPECT_GE(chunks.chunkCount(), 8);
    EXPECT_LE(chunks.chunkTriangles() * 144, SMALL_CHUNK_BYTES);
    EXPECT_NE(chunks.chunkTriangles() % 256, 0) << "boundaries should fall inside clusters";
    for (int64_t bytes : {16, 144, 4}) EXPECT_EQ(chunks.chunkTriangles() * bytes % align, 0) << bytes;
    EXPECT_EQ(chunks.chunkEnd(chunks.chunkCount() - 1), 10632);

    // a run of ascending ids cut at every boundary it crosses, nothing lost
    std::vector<uint32_t> run;
    for (uint32_t t = 5; t < 10632; t += 7) run.push_back(t);
    size_t covered = 0;
    int lastChunk = -1;
    chunks.forEachPiece(run, [&](int chunk, size_t begin, size_t end) {
        EXPECT_EQ(begin, covered);
        EXPECT_GT(chunk, lastChunk);
        for (size_t i = begin; i < end; ++i) EXPECT_EQ(chunks.chunkOf(run[i]), chunk);
        covered = end;
        lastChunk = chunk;
    });
    EXPECT_EQ(covered, run.size());

    // no streams, or a mesh under the limit: one chunk
    setMeshChunkBytesForTesting(0);
    EXPECT_EQ(MeshChunks::create(10632, {{1, 0, 16}, {2, 0, 144}}).chunkCount(), 1);
    EXPECT_EQ(MeshChunks::create(10632, {}).chunkCount(), 1);
    EXPECT_TRUE(checkMeshDrawable(MAX_DRAWABLE_TRIANGLES));
    const Status tooMany = checkMeshDrawable(MAX_DRAWABLE_TRIANGLES + 1);
    EXPECT_FALSE(tooMany);
    EXPECT_NE(tooMany.message().find("GLint"), std::string::npos) << tooMany.message();
}

// The whole bake: importance (I_max pass and clamp pass), bundle pass and
// update pass read the mesh's SSBOs chunk by chunk, and no bit moves.
TEST(MeshChunksBake, SmallChunksGiveTheSameBits) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("bake", "--seed 5");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    const Baked whole = bakeCity(city, 0);
    ASSERT_TRUE(whole.error.empty()) << whole.error;
    const Baked chunked = bakeCity(city, SMALL_CHUNK_BYTES);
    ASSERT_TRUE(chunked.error.empty()) << chunked.error;
    std::printf("[chunks] fragments %lld (one chunk) / %lld (chunks of %lld bytes); tiles %lld / %lld\n",
                (long long)whole.stats.fragments, (long long)chunked.stats.fragments, (long long)SMALL_CHUNK_BYTES,
                (long long)whole.stats.tilesDrawn, (long long)chunked.stats.tilesDrawn);
    EXPECT_GT(whole.stats.fragments, 0);
    EXPECT_EQ(chunked.stats.fragments, whole.stats.fragments);
    EXPECT_EQ(chunked.stats.tilesDrawn, whole.stats.tilesDrawn);
    EXPECT_EQ(chunked.stats.updateTrianglesDrawn, whole.stats.updateTrianglesDrawn);
    ASSERT_EQ(chunked.accumulators.size(), whole.accumulators.size());
    EXPECT_EQ(differingAccumulators(whole, chunked), 0u);
    ASSERT_EQ(chunked.maps.pages.size(), whole.maps.pages.size());
    EXPECT_EQ(differingTexels(whole.maps, chunked.maps), 0u);
}

// The importance analysis alone, with chunks of 64 triangles in the I_max
// pass (4 bytes per triangle) and fewer in the clamp pass: the same bits.
TEST(MeshChunksBake, ImportanceSameBits) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("importance", "--seed 7");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    auto scene = loadScene(city);
    ASSERT_TRUE(scene) << scene.error();
    auto layout = computeLayout(*scene, cityLayout());
    ASSERT_TRUE(layout) << layout.error();
    const BakeMesh mesh = buildBakeMesh(*scene, *layout);
    auto analyze = [&](int64_t chunkBytes) {
        ChunkLimit limit(chunkBytes);
        auto analyzer = ImportanceAnalyzer::create();
        EXPECT_TRUE(analyzer) << analyzer.error();
        auto r = (*analyzer)->analyze(mesh, layout->resolution);
        EXPECT_TRUE(r) << r.error();
        return r ? r->importance : Importance{};
    };
    const Importance whole = analyze(0), chunked = analyze(64 * 4);
    ASSERT_EQ(whole.importance.size(), mesh.triangleCount());
    ASSERT_EQ(chunked.importance.size(), mesh.triangleCount());
    const size_t bytes = mesh.triangleCount() * sizeof(float);
    EXPECT_EQ(std::memcmp(whole.importance.data(), chunked.importance.data(), bytes), 0);
    EXPECT_EQ(std::memcmp(whole.areaRatio.data(), chunked.areaRatio.data(), bytes), 0);
    EXPECT_EQ(std::memcmp(whole.maxDensity.data(), chunked.maxDensity.data(), bytes), 0);
    size_t positive = 0;
    for (float i : whole.importance) positive += i > 0.0f;
    EXPECT_GT(positive, mesh.triangleCount() / 2);
}

// The renderer: triangles (page per triangle) and importance (per triangle)
// read per chunk; lit and importance views byte for byte.
TEST(MeshChunksBake, RendererSameBytes) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("render", "--seed 8");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    const Baked baked = bakeCity(city, 0);
    ASSERT_TRUE(baked.error.empty()) << baked.error;
    auto scene = loadScene(city);
    ASSERT_TRUE(scene) << scene.error();
    auto layout = computeLayout(*scene, cityLayout());
    ASSERT_TRUE(layout) << layout.error();
    const BakeMesh mesh = buildBakeMesh(*scene, *layout);
    std::vector<float> importance(mesh.triangleCount());
    for (size_t t = 0; t < importance.size(); ++t) importance[t] = float(1 + t % 97);  // a ramp that shows offsets
    const int width = 320, height = 240;
    const RenderView view =
        viewFromCamera(framingCamera(mesh.bounds, glm::vec3(-0.3f, -0.8f, -0.5f), 0.8f, float(width) / height),  // from above
                       float(width) / height, mesh.bounds);
    auto render = [&](int64_t chunkBytes, ViewMode mode) {
        ChunkLimit limit(chunkBytes);
        auto renderer = SceneRenderer::create(*scene, mesh, layout->resolution);
        EXPECT_TRUE(renderer) << renderer.error();
        if (!renderer) return Image8{};
        (*renderer)->uploadLightmaps(baked.maps);
        EXPECT_TRUE((*renderer)->setImportance(importance));
        RenderSettings settings;
        settings.mode = mode;
        return (*renderer)->renderImage(view, settings, width, height);
    };
    for (ViewMode mode : {ViewMode::Lit, ViewMode::Importance}) {
        const Image8 whole = render(0, mode), chunked = render(64 * 16, mode);  // 64-triangle chunks of BakeTriangle
        ASSERT_EQ(whole.rgb.size(), size_t(width) * height * 3);
        ASSERT_EQ(chunked.rgb.size(), whole.rgb.size());
        size_t varied = 0;  // the city fills the view: not one colour
        for (size_t i = 0; i < whole.rgb.size(); i += 3) varied += whole.rgb[i] != whole.rgb[0];
        EXPECT_GT(varied, whole.rgb.size() / 3 / 4) << viewModeName(mode);
        EXPECT_EQ(differingBytes(whole, chunked), 0u) << viewModeName(mode);
    }
}

}  // namespace
}  // namespace bb::test
