// `bundlebake reference`: the CPU path-traced reference (engine/reference) into
// the same outputs as `bake`: EXR pages, coverage masks, manifest.json,
// stats.json (with wall time and spp), tone-mapped PNG previews. No GL.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include <embree3/rtcore_config.h>

#include "bake/bake_output.h"
#include "bake/seam_stitch.h"
#include "core/log.h"
#include "headless/cli/options.h"
#include "reference/reference_baker.h"

namespace bb::cli {
namespace {

struct ReferenceArgs {
    SceneArgs scene;
    std::string outDir;
    int spp = 1024;
    int passSpp = 16;
    int threads = 2;
    uint64_t seed = 1;
    std::string sky = "0,0,0";
    std::string env;
    std::string emitterSampling = "on";
    std::string seams = "stitch";
    int rouletteDepth = 3;
    int maxBounces = 1000;
    bool preview = true;
    bool progress = true;
};

int runReference(const ReferenceArgs& args) {
    auto sky = parseColor(args.sky, "--sky");
    if (!sky) return fail(sky.error());
    ReferenceOptions options;
    options.spp = args.spp;
    options.passSpp = args.passSpp;
    options.threads = args.threads;
    options.seed = args.seed;
    options.sky = *sky;
    options.emitterSampling = args.emitterSampling == "on";
    options.rouletteDepth = args.rouletteDepth;
    options.maxBounces = args.maxBounces;
    if (Status s = loadEnvironment(args.env, options.environment); !s) return fail(s.message());
    auto loaded = loadSceneAndLayout(args.scene);
    if (!loaded) return fail(loaded.error());
    if (Status s = io::ensureDirectory(args.outDir); !s) return fail(s.message());

    auto t0 = std::chrono::steady_clock::now();
    auto baker = ReferenceBaker::create(loaded->scene, loaded->layout, options);
    if (!baker) return fail(baker.error());
    const bool bar = args.progress && isatty(STDERR_FILENO);
    while (true) {
        ReferenceProgress p = (*baker)->step(0.5);
        if (bar) {
            double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::fprintf(stderr, "\r%d/%d spp, %.1f s ", p.sppDone, p.sppTotal, elapsed);
            std::fflush(stderr);
        }
        if (p.done()) break;
    }
    if (bar) std::fprintf(stderr, "\n");
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    BakeOutputInfo info;
    info.backend = "cpu";
    info.renderer = "embree " + std::to_string(RTC_VERSION_MAJOR) + "." + std::to_string(RTC_VERSION_MINOR) + "." +
                    std::to_string(RTC_VERSION_PATCH) + ", " + std::to_string((*baker)->stats().threads) + " threads";
    info.generator = "bundlebake reference";
    info.settings = {{"spp", args.spp}, {"pass_spp", args.passSpp}, {"threads", (*baker)->stats().threads},
                     {"seed", args.seed}, {"sky", args.sky}, {"env", args.env},
                     {"emitter_sampling", args.emitterSampling}, {"roulette_depth", args.rouletteDepth},
                     {"max_bounces", args.maxBounces}, {"seams", args.seams},
                     {"uv_layout", args.scene.uvLayout}, {"resolution", args.scene.resolution},
                     {"texel_density", args.scene.texelDensity}};
    info.wallSeconds = seconds;  // BVH build + tracing (not scene loading or writing)
    info.writePreviews = args.preview;
    // the same light maps as a bake's: its seams stitched the same way (the same
    // least squares over the same seams), unless --seams off
    LightmapPages maps = (*baker)->readLightmaps();
    nlohmann::json stats = (*baker)->stats().toJson();
    if (args.seams == "stitch")
        stats["seams"] = stitchSeams(maps, findSeams((*baker)->mesh(), maps.resolution)).toJson();
    if (Status s = writeBakeOutputs(args.outDir, loaded->scene, loaded->layout, maps, stats, info); !s)
        return fail(s.message());
    logInfo("traced " + std::to_string(args.spp) + " spp in " + std::to_string(seconds) + " s -> " + args.outDir);
    return 0;
}

}  // namespace

void addReferenceCommand(CLI::App& app, std::function<int()>& action) {
    auto a = std::make_shared<ReferenceArgs>();
    CLI::App* cmd = app.add_subcommand(
        "reference", "CPU path-traced reference light maps (Embree): same layout, texels, units and outputs as bake");
    addSceneOptions(*cmd, a->scene);
    cmd->add_option("-o,--output", a->outDir, "Output directory (created if missing)")->required();
    cmd->add_option("--spp", a->spp, "Paths per texel")->check(CLI::Range(1, 1 << 30))->capture_default_str();
    cmd->add_option("--pass-spp", a->passSpp, "Paths per texel per progressive pass")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    cmd->add_option("--seed", a->seed, "Random seed (per-texel sample streams)")->capture_default_str();
    cmd->add_option("--sky", a->sky, "Uniform sky radiance r,g,b (scene units)")->capture_default_str();
    cmd->add_option("--env", a->env, "Equirectangular environment map (EXR/HDR), radiance; replaces --sky")
        ->excludes(cmd->get_option("--sky"));
    cmd->add_option("--emitter-sampling", a->emitterSampling,
                    "Next-event estimation of emissive triangles with MIS (off: emitters found by cosine samples only)")
        ->check(CLI::IsMember({"on", "off"}))
        ->capture_default_str();
    cmd->add_option("--roulette-depth", a->rouletteDepth, "Bounces before Russian roulette")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    cmd->add_option("--max-bounces", a->maxBounces,
                    "Path vertices after the texel (1 = direct light only, as the GPU's first iteration)")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    addSeamsOption(*cmd, a->seams);
    cmd->add_flag("--no-preview", [a](int64_t) { a->preview = false; }, "Do not write PNG previews");
    cmd->add_flag("--no-progress", [a](int64_t) { a->progress = false; }, "No progress line on stderr");
    cmd->callback([a, &action] { action = [a] { return runReference(*a); }; });
}

}  // namespace bb::cli
