// `bundlebake bake`: load, lay out, bake on a headless context, write
// EXR pages + manifest.json + stats.json + tone-mapped PNG previews.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "bake/baker.h"
#include "core/log.h"
#include "headless/cli/options.h"
#include "bake/bake_output.h"
#include "bake/seam_stitch.h"
#include "headless/cli/progress.h"
#include "headless/mpi/mpi_share.h"
#include "headless/platform.h"
#include "reference/error_check.h"

namespace bb::cli {
namespace {
// Checkpoints left before the test hook kills the process (parsed once).
int& killCountdown(const char* value) {
    static int left = std::max(1, std::atoi(value));
    return left;
}
}  // namespace

void addSeamsOption(CLI::App& cmd, std::string& seams) {
    cmd.add_option("--seams", seams,
                   "UV seams: stitch (least squares over the texels along them, so both sides agree) or off")
        ->check(CLI::IsMember({"stitch", "off"}))
        ->capture_default_str();
}

void addBakeOptions(CLI::App& cmd, BakeArgs& a) {
    addSceneOptions(cmd, a.scene);
    cmd.add_option("-o,--output", a.outDir, "Output directory (created if missing)")->required();
    cmd.add_option("--backend", a.backend, "Headless GL: egl (surfaceless) or osmesa")
        ->check(CLI::IsMember({"egl", "osmesa"}))
        ->capture_default_str();
    cmd.add_option("--directions", a.directions, "Bundle directions (each serves d and -d)")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    cmd.add_option("--bundle-res", a.bundleRes,
                   "Uniform bundle resolution in pixels across the scene's bounding sphere (0 = half a light map texel per pixel)")
        ->check(CLI::Range(0, 1 << 20))
        ->capture_default_str();
    cmd.add_option("--tiling", a.tiling,
                   "Bundle tiles: adaptive (quadtree, each leaf's pixel from the importance of what it covers) or uniform "
                   "(one grid at the mean texel density, the Hermes et al. 2010 baseline)")
        ->check(CLI::IsMember({"adaptive", "uniform"}))
        ->capture_default_str();
    cmd.add_option("--culling", a.culling, "Per-tile cluster culling in the bundle and update passes: on or off")
        ->check(CLI::IsMember({"on", "off"}))
        ->capture_default_str();
    cmd.add_option("--memory-budget", a.memoryBudget, "GL bytes for the whole bake: light maps, mesh, materials, and the rest for the bundle pass (e.g. 1G, 4G)")
        ->capture_default_str();
    cmd.add_option("--seed", a.seed, "Random seed (directions, stochastic rounding)")->capture_default_str();
    cmd.add_option("--sky", a.sky, "Uniform sky radiance r,g,b (scene units)")->capture_default_str();
    cmd.add_option("--env", a.env, "Equirectangular environment map (EXR/HDR), radiance; replaces --sky")
        ->excludes(cmd.get_option("--sky"));
    cmd.add_option("--rounding", a.rounding, "fp16/RGBE conversion: stochastic (unbiased) or nearest (biased, for tests)")
        ->check(CLI::IsMember({"stochastic", "nearest"}))
        ->capture_default_str();
    addHistoryOptions(cmd, a.historyPower, a.historyPlateau);
    cmd.add_option("--direct", a.direct,
                   "Direct light from emissive triangles: explicit (form factor x shadow cube maps), bundles, or auto "
                   "(explicit for small emitters)")
        ->check(CLI::IsMember({"auto", "explicit", "bundles"}))
        ->capture_default_str();
    cmd.add_option("--emitter-samples", a.emitterSamples,
                   "Visibility samples over all explicit emitters (0 = max(128, directions / 4))")
        ->check(CLI::Range(0, 1 << 16))
        ->capture_default_str();
    cmd.add_option("--sun-jitter", a.sunJitter,
                   "Sun passes per axis, each at another point of every texel's footprint (0 = from the directions)")
        ->check(CLI::Range(0, kMaxSunJitter))
        ->capture_default_str();
    addSupersampleOption(cmd, a.supersample);
    cmd.add_option("--resolution-probe", a.resolutionProbe,
                   "Directions gathered again at the end of a supersampled bake, reading its light at coarser texels, "
                   "to estimate the error of the light map's resolution where the baked texels hold the light's "
                   "detail (stats.json noise.resolution; -1 = directions / 64, at least 8, from 256 directions on; "
                   "0 = off)")
        ->check(CLI::Range(-1, 1 << 16))
        ->capture_default_str();
    cmd.add_option("--target-noise", a.targetNoise,
                   "Stop once the light maps' estimated relative error (their noise and the bounces still to come) is "
                   "at most this (e.g. 0.01; checked at radiance refreshes from 16 directions on; --directions is then "
                   "the most); 0 = off")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    cmd.add_option("--error-check", a.errorCheck,
                   "After the bake, estimate its error against the truth with the CPU path tracer: two independent "
                   "estimates of every texel of N paths each on average, where the reference is noisiest most "
                   "(stats.json noise.check; unbiased, bias and noise alike); auto = directions / 4 (16 to 1024), up "
                   "to directions / 2 (2048) where that could not resolve the bake's own estimate but those could "
                   "twice it, directions / 16 where not even twice it could be; off")
        ->check(countOr({"auto", "off"}, 1 << 20))
        ->capture_default_str();
    addSeamsOption(cmd, a.seams);
    cmd.add_option("--checkpoint-every", a.checkpointEvery,
                   "Write OUTDIR/checkpoint.bin every N directions (0 = never)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd.add_flag("--resume", a.resume, "Continue from OUTDIR/checkpoint.bin if it exists (same scene and flags)");
    cmd.add_flag("--no-preview", [&a](int64_t) { a.preview = false; }, "Do not write PNG previews");
    cmd.add_flag("--no-progress", [&a](int64_t) { a.progress = false; }, "No progress bar on stderr");
}

void addBakeCommand(CLI::App& app, std::function<int()>& action) {
    auto args = std::make_shared<BakeArgs>();
    CLI::App* cmd = app.add_subcommand("bake", "Bake light maps (EXR pages, manifest.json, stats.json, PNG previews)");
    addBakeOptions(*cmd, *args);
    cmd->callback([args, &action] { action = [args] { return runBake(*args); }; });
}

namespace {
// A shared bake's figures per rank (stats.json "mpi"): what each baked and how
// long it waited for the others and moved bytes.
nlohmann::json rankFigures(const BakeStats& s, const DirectionShare& share) {
    char host[256] = {0};
    gethostname(host, sizeof host - 1);
    return {{"rank", share.index()}, {"host", host},
            {"directions", (s.directionsTotal - share.index() + share.count() - 1) / share.count()},
            {"tiles", s.tilesDrawn}, {"fragments", s.fragments}, {"texel_samples", s.updatedTexels},
            {"seconds", {{"tiling", s.secondsTiling}, {"bundle", s.secondsBundle}, {"update", s.secondsUpdate},
                         {"resolve", s.secondsResolve}, {"combine", s.secondsCombine},
                         {"waiting", share.secondsWaiting()}, {"transferring", share.secondsTransferring()},
                         {"total", s.secondsTotal()}}},
            {"combines", s.combines}, {"bytes_sent", s.combineBytes}};
}
}  // namespace

int runBake(const BakeArgs& args) {
    // one of several MPI ranks: each bakes its share of the directions; rank 0 writes
    auto started = MpiShare::startIfLaunched();
    if (!started) return fail(started.error());
    const std::shared_ptr<MpiShare> mpi = *started && (*started)->count() > 1 ? *started : nullptr;
    const bool writer = !mpi || mpi->index() == 0;
    if (!writer) {
        setFailPrefix("rank " + std::to_string(mpi->index()) + ": ");
        if (logLevel() < LogLevel::Error) setLogLevel(LogLevel::Error);  // rank 0 says it once
    }
    // a rank that fails ends the job: the others would wait for it in the next combine
    const auto fail = [&mpi](const std::string& message) {
        const int code = cli::fail(message);
        if (mpi) mpi->abortAll(code);
        return code;
    };
    // until the bake starts, a refused input gives its one error line alone:
    // warnings about a scene that is then refused are dropped with it
    LogHold hold;
    auto backend = parseBackend(args.backend);
    if (!backend) return fail(backend.error());
    auto budget = parseSize(args.memoryBudget, "--memory-budget");
    if (!budget) return fail(budget.error());
    auto sky = parseColor(args.sky, "--sky");
    if (!sky) return fail(sky.error());
    BakeOptions options;
    options.directions = args.directions;
    options.bundleResolution = args.bundleRes;
    options.tiling = args.tiling == "uniform" ? BakeOptions::Tiling::Uniform : BakeOptions::Tiling::Adaptive;
    options.cull = args.culling == "on";
    options.memoryBudget = *budget;
    options.seed = args.seed;
    options.sky = *sky;
    options.rounding = args.rounding == "nearest" ? Rounding::Nearest : Rounding::Stochastic;
    options.historyPower = args.historyPower;
    options.historyPlateau = args.historyPlateau;
    options.directLight = args.direct == "explicit" ? BakeOptions::DirectLight::Explicit
                        : args.direct == "bundles"  ? BakeOptions::DirectLight::Bundles
                                                    : BakeOptions::DirectLight::Auto;
    options.emitterSamples = args.emitterSamples;
    options.sunJitter = args.sunJitter;
    options.resolutionProbe = args.resolutionProbe;
    options.share = mpi;
    options.targetNoise = args.targetNoise;
    options.supersample = supersampleValue(args.supersample);
    if (Status s = loadEnvironment(args.env, options.environment); !s) return fail(s.message());
    auto loaded = loadSceneAndLayout(args.scene);
    if (!loaded) return fail(loaded.error());
    if (Status s = io::ensureDirectory(args.outDir); !s) return fail(s.message());

    auto context = createHeadlessContext(*backend);
    if (!context) return fail(context.error());
    auto baker = Baker::create(loaded->scene, loaded->layout, options);
    if (!baker) return fail(baker.error());

    const std::string checkpoint = args.outDir + "/checkpoint.bin";
    bool resume = args.resume && std::filesystem::exists(checkpoint);
    if (mpi && args.resume) {  // every rank reads the checkpoint: they must all see it, or none
        const auto seen = mpi->gather(resume ? "1" : "0");
        if (std::count(seen.begin(), seen.end(), "1") % mpi->count() != 0)
            return fail("not every rank sees " + checkpoint + ": --resume under MPI needs the output directory shared by all ranks");
    }
    if (resume) {
        if (Status s = (*baker)->loadCheckpoint(checkpoint); !s) return fail(s.message());
        logInfo("resuming from " + checkpoint + " at direction " + std::to_string((*baker)->progress().directionsDone));
    }
    hold.release();  // the input is accepted: print what was said about it
    ProgressBar bar(args.progress && writer, isatty(STDERR_FILENO));
    auto t0 = std::chrono::steady_clock::now();
    int lastCheckpoint = (*baker)->progress().directionsDone;
    while (true) {
        // one direction (a round of them under MPI) at a time when checkpointing: a checkpoint every N directions
        // exactly (under MPI: at the first combine after N directions; every rank takes part, rank 0 writes)
        BakeProgress p = (*baker)->step(args.checkpointEvery > 0 ? 0.0 : 0.25);
        bar.update(p.directionsDone, p.directionsTotal);
        if (args.checkpointEvery > 0 && p.directionsDone - lastCheckpoint >= args.checkpointEvery && p.combined &&
            !p.done()) {
            if (Status s = (*baker)->saveCheckpoint(checkpoint); !s) return fail(s.message());
            lastCheckpoint = p.directionsDone;
            // test hook: die as `kill -9` would, right after the n-th checkpoint (tests/gl/cli_resume_test.cpp);
            // under MPI the last rank dies (tests/mpi)
            if (const char* n = std::getenv("BUNDLEBAKE_TEST_KILL_AFTER_CHECKPOINTS");
                n && --killCountdown(n) == 0 && (!mpi || mpi->index() == mpi->count() - 1))
                std::raise(SIGKILL);
        }
        if (p.done()) break;
    }
    bar.finish();
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    nlohmann::json mpiFigures;
    if (mpi) {
        const std::vector<std::string> perRank = mpi->gather(rankFigures((*baker)->stats(), *mpi).dump());
        if (!writer) return 0;
        nlohmann::json ranks = nlohmann::json::array();
        double communication = 0, total = 0;
        for (const std::string& r : perRank) {
            ranks.push_back(nlohmann::json::parse(r));
            const auto& t = ranks.back()["seconds"];
            communication += t["waiting"].get<double>() + t["transferring"].get<double>();
            total += t["total"].get<double>();
        }
        mpiFigures = {{"ranks", mpi->count()}, {"per_rank", ranks},
                      {"communication_share", total > 0 ? communication / total : 0.0},
                      {"note", "the figures outside \"mpi\" are rank 0's own"}};
    }
    BakeOutputInfo info;
    info.backend = backendName(*backend);
    info.renderer = context.value()->caps().renderer;
    info.settings = {{"directions", args.directions}, {"bundle_res", args.bundleRes}, {"tiling", args.tiling}, {"culling", args.culling}, {"memory_budget", args.memoryBudget},
                     {"seed", args.seed}, {"sky", args.sky}, {"env", args.env}, {"rounding", args.rounding},
                     {"uv_layout", args.scene.uvLayout}, {"resolution", args.scene.resolution},
                     {"texel_density", args.scene.texelDensity}, {"history_power", (*baker)->stats().historyPower},
                     {"history_plateau", (*baker)->stats().historyPlateau},
                     {"direct", args.direct}, {"emitter_samples", args.emitterSamples},
                     {"sun_jitter", args.sunJitter}, {"resolution_probe", args.resolutionProbe},
                     {"seams", args.seams}, {"supersample", args.supersample}, {"mpi_ranks", mpi ? mpi->count() : 1}, {"target_noise", args.targetNoise},
                     {"error_check", args.errorCheck}};
    info.wallSeconds = seconds;
    info.writePreviews = args.preview;
    LightmapPages maps = (*baker)->readLightmaps();  // before the stats: its read-back memory counts
    nlohmann::json stats = (*baker)->stats().toJson();
    if (mpi) stats["mpi"] = mpiFigures;
    if (args.seams == "stitch")
        stats["seams"] = stitchSeams(maps, findSeams((*baker)->mesh(), maps.resolution)).toJson();
    // the error estimate: the bake's own (noise, lag, resolution probe), or the path-traced check where conclusive
    double estimate = (*baker)->stats().errorEstimate();
    if (args.errorCheck != "off") {  // on the maps as written
        ErrorCheckOptions check;
        check.reference.seed = args.seed;
        check.reference.sky = options.sky;
        check.reference.environment = options.environment;
        check.reference.threads = 0;
        check.stitchSeams = args.seams == "stitch";
        if (args.errorCheck == "auto")
            setAutoBudget(check, (*baker)->progress().directionsDone, estimate);
        else
            check.spp = std::atoi(args.errorCheck.c_str());
        auto result = checkError(loaded->scene, loaded->layout, maps, check);
        if (!result) return fail(result.error());
        stats["noise"]["check"] = result->toJson();
        if (result->conclusive()) estimate = result->relRmse;
        logInfo(result->summary());
    }
    // the written maps' half-float rounding, exact, added to whichever estimate stands
    const double rounding = exrRoundingError(maps);
    stats["noise"]["output_rounding"] = rounding;
    if (estimate >= 0) stats["noise"]["error_estimate"] = std::hypot(estimate, rounding);
    if (Status s = writeBakeOutputs(args.outDir, loaded->scene, loaded->layout, maps, stats, info); !s)
        return fail(s.message());
    if (args.checkpointEvery > 0 || args.resume) std::filesystem::remove(checkpoint);  // the outputs supersede it
    logInfo("baked " + std::to_string((*baker)->progress().directionsDone) + " directions in " + std::to_string(seconds) + " s -> " +
            args.outDir + (mpi ? " (" + std::to_string(mpi->count()) + " MPI ranks)" : ""));
    return 0;
}

}  // namespace bb::cli
