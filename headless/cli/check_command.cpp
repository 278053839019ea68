// `bundlebake check SCENE BAKE_DIR`: the error of a bake's light maps against
// the truth, estimated by the CPU path tracer without a converged reference
// (engine/reference/error_check.h). No GL.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "core/log.h"
#include "headless/cli/options.h"
#include "reference/error_check.h"
#include "render/scene_renderer.h"

namespace bb::cli {
namespace {

struct CheckArgs {
    SceneArgs scene;
    LayoutFlagsGiven given;
    std::string bakeDir;
    std::string spp = "auto";
    int threads = 0;
    uint64_t seed = 1;
    std::string sky, env;  // empty: as BAKE_DIR/stats.json's settings say
    std::string seams;     // empty: as BAKE_DIR/stats.json's settings say (off if they do not: the viewer's saves)
    bool json = false;
};

nlohmann::json readStats(const std::string& bakeDir) {
    std::ifstream in(bakeDir + "/stats.json");
    return nlohmann::json::parse(in, nullptr, false);
}

// What the flags left out as the bake's stats.json "settings" (sky, env, seams) say.
void settingsAsBaked(const nlohmann::json& stats, CheckArgs& args) {
    const nlohmann::json s = stats.is_object() && stats.contains("settings") ? stats["settings"] : nlohmann::json::object();
    const auto take = [&s](const char* key, std::string& value) {
        if (value.empty() && s.contains(key) && s[key].is_string()) value = s[key].get<std::string>();
    };
    if (args.sky.empty() && args.env.empty()) {
        take("sky", args.sky);
        take("env", args.env);
    }
    take("seams", args.seams);
}

int runCheck(CheckArgs args) {
    const nlohmann::json stats = readStats(args.bakeDir);
    settingsAsBaked(stats, args);
    ErrorCheckOptions options;
    auto sky = parseColor(args.sky.empty() ? "0,0,0" : args.sky, "--sky");
    if (!sky) return fail(sky.error());
    options.reference.sky = *sky;
    if (Status s = loadEnvironment(args.env, options.reference.environment); !s) return fail(s.message());
    options.reference.threads = args.threads;
    options.reference.seed = args.seed;
    if (args.spp == "auto") {  // as the bake's own check: from its directions and its estimate
        const nlohmann::json* noise = stats.is_object() && stats.contains("noise") ? &stats["noise"] : nullptr;
        if (!noise || !stats.contains("directions") || !noise->contains("relative"))
            return fail(args.bakeDir + "/stats.json: no directions and noise estimate to take the budget from; give --spp N");
        // the bake's own estimate: the noise and the resolution probe, not a check's
        const double own = std::hypot((*noise)["relative"].get<double>(), noise->value("resolution", 0.0));
        setAutoBudget(options, stats["directions"]["done"].get<int>(), own);
    } else {
        options.spp = std::atoi(args.spp.c_str());
    }
    options.stitchSeams = args.seams == "stitch";
    auto loaded = loadSceneWithBakeLayout(args.scene, args.given, args.bakeDir);
    if (!loaded) return fail(loaded.error());
    auto maps = readBakedLightmaps(args.bakeDir, loaded->layout);
    if (!maps) return fail(maps.error());
    auto check = checkError(loaded->scene, loaded->layout, *maps, options);
    if (!check) return fail(check.error());
    if (args.json) {
        std::printf("%s\n", check->toJson().dump(2).c_str());
        return 0;
    }
    std::printf("%s\n", check->summary().c_str());
    return 0;
}

}  // namespace

void addCheckCommand(CLI::App& app, std::function<int()>& action) {
    auto a = std::make_shared<CheckArgs>();
    CLI::App* cmd = app.add_subcommand(
        "check", "Estimate a bake's error against the truth with the CPU path tracer, without a converged reference "
                 "(relative RMSE, unbiased, with its standard error)");
    addSceneOptions(*cmd, a->scene);
    cmd->add_option("bake", a->bakeDir, "Directory written by `bundlebake bake` (its manifest.json gives the layout)")
        ->required();
    cmd->add_option("--spp", a->spp,
                    "Mean paths per texel of each of the two estimates, or auto: as `bake --error-check auto` takes "
                    "them from the bake's directions and its own error estimate (its stats.json)")
        ->check(countOr({"auto"}, 1 << 20))
        ->capture_default_str();
    cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    cmd->add_option("--seed", a->seed, "Random seed of the check's paths")->capture_default_str();
    cmd->add_option("--sky", a->sky, "Uniform sky radiance r,g,b (default: the bake's, from its stats.json)");
    cmd->add_option("--env", a->env, "Equirectangular environment map (default: the bake's)")
        ->excludes(cmd->get_option("--sky"));
    cmd->add_option("--seams", a->seams, "The bake's seams: stitch or off (default: as its stats.json says; off where it does not say)")
        ->check(CLI::IsMember({"stitch", "off"}));
    cmd->add_flag("--json", a->json, "Print the figures as JSON");
    cmd->callback([a, cmd, &action] {
        a->given = layoutFlagsGiven(*cmd);
        action = [a] { return runCheck(*a); };
    });
}

}  // namespace bb::cli
