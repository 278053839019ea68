// Importance analysis benchmark (supplement §1 preprocessing): time of the
// position pass, the I_max pass and the Eq. (4) compute pass against
// triangle count and texel count, on the assets and on synthetic planes. A
// program, not a test: one warm-up run (llvmpipe compiles shader variants on
// first use), then N runs, best and median, one aligned line per case;
// every phase timer stops after glFinish (ImportanceTimings).
//
// usage: importance_bench [--backend egl|osmesa] [--runs N] [--cpu] [--quick]
//   --cpu    also time the CPU reference (one run) for comparison
//
// Not in the top-level CMakeLists (that file belongs to the build's owner);
// build it like bake_bench: add_executable(importance_bench
// bench/importance_bench.cpp), link bundlebake_platform, define
// BUNDLEBAKE_SOURCE_DIR.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "core/log.h"
#include "headless/platform.h"
#include "importance/importance.h"
#include "importance/importance_gl.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"

using namespace bb;

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// A square plane of 1 x 1 world units with cells x cells quads, mapped onto
// `texels` x `texels` texels at the page origin (+1 texel).
BakeMesh planeMesh(int cells, int texels, int resolution) {
    BakeMesh m;
    const float uv0 = 1.0f / float(resolution), uvSpan = float(texels) / float(resolution);
    auto vertex = [&](int i, int j) {
        BakeVertex v;
        const glm::vec2 st(float(i) / float(cells), float(j) / float(cells));
        v.position = glm::vec4(st, 0.0f, 1.0f);
        v.normal = glm::vec4(0, 0, 1, 0);
        v.uv0 = st;
        v.lightmapUv = glm::vec2(uv0) + uvSpan * st;
        return v;
    };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const BakeVertex a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
            m.vertices.insert(m.vertices.end(), {a, b, c, a, c, d});
            m.triangles.push_back(BakeTriangle{0, 0, 0, 0});
            m.triangles.push_back(BakeTriangle{0, 0, 0, 0});
        }
    m.pageFirstTriangle = {0, uint32_t(m.triangles.size())};
    return m;
}

struct Row {
    std::string name;
    size_t triangles = 0;
    int resolution = 0, pages = 0;
};

void runCase(ImportanceAnalyzer& analyzer, const Row& row, const BakeMesh& mesh, int runs, bool cpu) {
    std::vector<double> pos, imax, comp, total;
    ImportanceSummary summary;
    for (int r = -1; r < runs; ++r) {  // r = -1: warm-up
        auto result = analyzer.analyze(mesh, row.resolution);
        if (!result) {
            std::fprintf(stderr, "importance_bench: %s: %s\n", row.name.c_str(), result.error().c_str());
            std::exit(1);
        }
        if (r < 0) {
            summary = summarize(result->importance);
            continue;
        }
        pos.push_back(1e3 * result->seconds.positionPass);
        imax.push_back(1e3 * result->seconds.maxDensityPass);
        comp.push_back(1e3 * result->seconds.computePass);
        total.push_back(1e3 * result->seconds.total());
    }
    double cpuMs = 0;
    if (cpu) {
        auto t0 = std::chrono::steady_clock::now();
        const Importance ref = computeImportance(mesh, row.resolution, analyzer.rasterRules());
        cpuMs = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    auto best = [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); };
    std::printf("%-34s %9zu %5d x%-2d | %8.2f %8.2f | %8.2f %8.2f | %7.2f %7.2f | %8.2f %8.2f | %8.3f",
                row.name.c_str(), row.triangles, row.resolution, row.pages, best(pos), median(pos), best(imax),
                median(imax), best(comp), median(comp), best(total), median(total),
                1e6 * median(total) / 1e3 / double(std::max<size_t>(row.triangles, 1)));
    if (cpu) std::printf(" | %9.1f", cpuMs);
    std::printf(" | %5.1f%% %5.1f%% %5.1f%%\n", 100.0 * double(summary.clamped) / double(std::max<size_t>(summary.triangles, 1)),
                100.0 * double(summary.clampedBeyond1Percent) / double(std::max<size_t>(summary.triangles, 1)),
                100.0 * double(summary.zeroMaxDensity) / double(std::max<size_t>(summary.triangles, 1)));
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    Backend backend = Backend::Egl;
    int runs = 5;
    bool cpu = false, quick = false;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--backend") && i + 1 < argc) backend = std::strcmp(argv[++i], "osmesa") ? Backend::Egl : Backend::OsMesa;
        else if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
        else if (!std::strcmp(argv[i], "--cpu")) cpu = true;
        else if (!std::strcmp(argv[i], "--quick")) quick = true;
        else {
            std::fprintf(stderr, "usage: importance_bench [--backend egl|osmesa] [--runs N] [--cpu] [--quick]\n");
            return 2;
        }
    }
    setLogLevel(LogLevel::Error);
    auto context = createHeadlessContext(backend);
    if (!context) {
        std::fprintf(stderr, "importance_bench: %s\n", context.error().c_str());
        return 1;
    }
    auto analyzer = ImportanceAnalyzer::create();
    if (!analyzer) {
        std::fprintf(stderr, "importance_bench: %s\n", analyzer.error().c_str());
        return 1;
    }
    char date[32];
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M", std::localtime(&now));
    std::printf("# importance_bench, %s, %s, %s; %d runs after 1 warm-up; ms (best, median); wall time to glFinish\n",
                date, backendName(backend), context.value()->caps().renderer.c_str(), runs);
    std::printf("%-34s %9s %9s | %17s | %17s | %15s | %17s | %8s%s | %20s\n", "case", "triangles", "res pages",
                "position pass", "I_max pass", "Eq.(4) compute", "total (+upload,rb)", "us/ktri",
                cpu ? " | CPU ref ms" : "", "clamped >1% zero");

    struct AssetCase {
        const char* name;
        const char* path;
        UvLayout mode;
        int resolution;
    };
    const AssetCase assets[] = {
        {"cornell_box (asset)", "assets/cornell_box/cornell_box.gltf", UvLayout::Asset, 256},
        {"furnace (asset)", "assets/furnace/furnace.gltf", UvLayout::Asset, 256},
        {"shared CornellBox.glb (pack)", "assets/shared/cornell_box/CornellBox.glb", UvLayout::Pack, 512},
        {"mixed_lighting (pack)", "assets/shared/mixed_lighting/MixedLightingExample.gltf", UvLayout::Pack, 1024},
        {"mixed_lighting (pack)", "assets/shared/mixed_lighting/MixedLightingExample.gltf", UvLayout::Pack, 2048},
        {"zdm2 (pack)", "assets/shared/zdm2/zdm2.glb", UvLayout::Pack, 2048},
    };
    for (const AssetCase& a : assets) {
        if (quick && a.resolution > 1024) continue;
        auto scene = loadScene(std::string(BUNDLEBAKE_SOURCE_DIR) + "/" + a.path);
        if (!scene) {
            std::printf("%-34s skipped: %s\n", a.name, scene.error().c_str());
            continue;
        }
        LayoutOptions o;
        o.mode = a.mode;
        o.resolution = a.resolution;
        auto layout = computeLayout(*scene, o);
        if (!layout) {
            std::printf("%-34s %9zu skipped: %s\n", a.name, scene->triangleCount(), layout.error().c_str());
            continue;
        }
        const BakeMesh mesh = buildBakeMesh(*scene, *layout);
        runCase(**analyzer, Row{a.name, mesh.triangles.size(), layout->resolution, layout->pageCount}, mesh, runs, cpu);
    }
    // triangle count at a fixed texel count: a plane on 1000 x 1000 texels of a 1024 page
    for (int cells : {16, 64, 128, 256, 512, 1024}) {
        if (quick && cells > 256) continue;
        const BakeMesh mesh = planeMesh(cells, 1000, 1024);
        runCase(**analyzer, Row{"plane " + std::to_string(cells) + "^2 quads on 1000^2 texels", mesh.triangles.size(), 1024, 1},
                mesh, runs, cpu);
    }
    // texel count at a fixed triangle count
    for (int res : {512, 1024, 2048, 4096}) {
        if (quick && res > 1024) continue;
        const BakeMesh mesh = planeMesh(128, res - 2, res);
        runCase(**analyzer, Row{"plane 128^2 quads on " + std::to_string(res - 2) + "^2 texels", mesh.triangles.size(), res, 1},
                mesh, runs, cpu);
    }
    return 0;
}
