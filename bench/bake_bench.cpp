// Bake benchmark: per-pass speed on named scenes and the furnace error
// against directions. A program, not a test: warm-up, N runs, best and
// median, one aligned line per case; timers stop after glFinish (the baker's
// phase timers read the node counter or finish the pass before stopping).
//
// usage: bake_bench [--backend egl|osmesa] [--runs N] [--quick]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bake/baker.h"
#include "core/log.h"
#include "gl/gl.h"
#include "headless/platform.h"

using namespace bb;

namespace {

struct Case {
    const char* name;
    const char* path;
    UvLayout mode;
    int resolution;
    int directions;
    glm::vec3 sky;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

std::unique_ptr<Baker> makeBaker(const Scene& scene, const Layout& layout, const BakeOptions& options) {
    auto b = Baker::create(scene, layout, options);
    if (!b) {
        std::fprintf(stderr, "bake_bench: %s\n", b.error().c_str());
        std::exit(1);
    }
    return std::move(b.value());
}

}  // namespace

int main(int argc, char** argv) {
    Backend backend = Backend::Egl;
    int runs = 3;
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--backend") && i + 1 < argc) backend = std::strcmp(argv[++i], "osmesa") ? Backend::Egl : Backend::OsMesa;
        else if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
        else if (!std::strcmp(argv[i], "--quick")) quick = true;
    }
    setLogLevel(LogLevel::Error);
    auto context = createHeadlessContext(backend);
    if (!context) {
        std::fprintf(stderr, "bake_bench: %s\n", context.error().c_str());
        return 1;
    }
    const std::string root = BUNDLEBAKE_SOURCE_DIR;
    std::printf("# bundlebake bake_bench, %s, %s\n", backendName(backend), context.value()->caps().renderer.c_str());

    // 1. speed per pass
    const Case cases[] = {
        {"cornell_box", "assets/cornell_box/cornell_box.gltf", UvLayout::Pack, 512, 64, glm::vec3(0)},
        {"mixed_lighting", "assets/shared/mixed_lighting/MixedLightingExample.gltf", UvLayout::Pack, 512, 32,
         glm::vec3(0.5f, 0.6f, 0.8f)},
    };
    std::printf("\n%-16s %6s %6s %9s %10s %12s %12s %12s %12s %10s %8s\n", "scene", "res", "dirs", "triangles", "texels",
                "ms/dir best", "ms/dir med", "Mfrag/s bndl", "Mtexel/s upd", "ms resolve", "s setup");
    for (const Case& c : cases) {
        auto scene = loadScene(root + "/" + c.path);
        if (!scene) return std::fprintf(stderr, "%s\n", scene.error().c_str()), 1;
        LayoutOptions lo;
        lo.mode = c.mode;
        lo.resolution = c.resolution;
        auto layout = computeLayout(*scene, lo);
        if (!layout) return std::fprintf(stderr, "%s\n", layout.error().c_str()), 1;
        BakeOptions o;
        o.directions = quick ? c.directions / 4 : c.directions;
        o.sky = c.sky;
        std::vector<double> perDir, frag, texel, resolve, setup;
        for (int r = 0; r < runs + 1; ++r) {  // run 0 is the warm-up (shader compiles, page faults)
            auto tc = std::chrono::steady_clock::now();
            auto baker = makeBaker(*scene, *layout, o);  // upload, meta pass, emitters, sun
            glFinish();
            double created = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
            baker->step(1e9);
            if (r == 0) continue;
            const BakeStats& st = baker->stats();
            perDir.push_back(1e3 * (st.secondsBundle + st.secondsUpdate + st.secondsResolve) / o.directions);
            setup.push_back(created);
            frag.push_back(st.fragments / st.secondsBundle / 1e6);
            texel.push_back(st.updatedTexels / st.secondsUpdate / 1e6);
            resolve.push_back(1e3 * st.secondsResolve / o.directions);
            if (r == runs)
                std::printf("%-16s %6d %6d %9zu %10lld %12.2f %12.2f %12.1f %12.1f %10.2f %8.2f\n", c.name, c.resolution,
                            o.directions, baker->mesh().triangleCount(), (long long)st.coveredTexels,
                            *std::min_element(perDir.begin(), perDir.end()), median(perDir), median(frag),
                            median(texel), median(resolve), median(setup));
        }
    }

    // 2. furnace error against directions (answer Le / (1 - rho) at every texel)
    std::printf("\n%-16s %6s %8s %12s %12s %12s %10s\n", "furnace", "rho", "dirs", "mean err %", "max err %", "rms err %",
                "seconds");
    for (auto [file, rho] : {std::pair{"assets/furnace/furnace.gltf", 0.5}, std::pair{"assets/furnace/furnace_rho09.gltf", 0.9}}) {
        auto scene = loadScene(root + "/" + file);
        LayoutOptions lo;
        lo.mode = UvLayout::Asset;
        lo.resolution = 64;
        auto layout = computeLayout(*scene, lo);
        const double answer = 1.0 / (1.0 - rho);
        for (int n : {16, 64, 256, 1024, 4096}) {
            if (quick && n > 256) break;
            BakeOptions o;
            o.directions = n;
            auto baker = makeBaker(*scene, *layout, o);
            auto t0 = std::chrono::steady_clock::now();
            baker->step(1e9);
            double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            LightmapPages maps = baker->readLightmaps();
            double sum = 0, sq = 0, worst = 0;
            size_t count = 0;
            for (size_t p = 0; p < maps.pages.size(); ++p)
                for (size_t i = 0; i < maps.pages[p].pixels.size(); ++i)
                    if (maps.covered[p][i]) {
                        double e = (maps.pages[p].pixels[i].g - answer) / answer;
                        sum += e;
                        sq += e * e;
                        worst = std::max(worst, std::abs(e));
                        ++count;
                    }
            std::printf("%-16s %6.1f %8d %12.3f %12.3f %12.3f %10.2f\n", "", rho, n, 100 * sum / count, 100 * worst,
                        100 * std::sqrt(sq / count), s);
        }
    }
    return 0;
}
