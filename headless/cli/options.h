// Flags shared by the commands, and the commands themselves.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "core/status.h"
#include "io/image_io.h"
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb::cli {

struct SceneArgs {
    std::string scene;
    std::string uvLayout = "pack";      // pack | generate | asset
    std::string uvOverlap = "warn";
    int resolution = 512;
    float texelDensity = 0.0f;
    std::string defaultAlbedo = "0.8,0.8,0.8";
};

struct InfoArgs {
    SceneArgs scene;
};

struct BakeArgs {
    SceneArgs scene;
    std::string outDir;
    std::string backend = "egl";
    int directions = 256;
    int bundleRes = 0;                // 0 = from the layout's texel density
    std::string tiling = "adaptive";  // adaptive | uniform
    std::string culling = "on";       // on | off
    std::string memoryBudget = "4G";
    uint64_t seed = 1;
    std::string sky = "0,0,0";
    std::string env;
    int checkpointEvery = 0;
    bool resume = false;
    double targetNoise = 0;           // > 0: stop at this estimated relative noise
    std::string errorCheck = "auto";  // paths per texel of the path-traced error check: auto, off or a number
    std::string rounding = "stochastic";
    float historyPower = -1.0f;
    int historyPlateau = 0;
    std::string direct = "auto";
    int emitterSamples = 0;
    int sunJitter = 0;
    int resolutionProbe = -1;         // BakeOptions::resolutionProbe (-1: from the directions)
    std::string supersample = "auto";  // auto | 1 | 2 | 4 (BakeOptions::supersample)
    std::string seams = "stitch";     // stitch | off (bake/seam_stitch.h)
    bool preview = true;
    bool progress = true;
};

void addSceneOptions(CLI::App& cmd, SceneArgs& args);
void addBakeOptions(CLI::App& cmd, BakeArgs& args);
// --seams stitch|off (bake and reference): UV seams stitched before the light maps are written (bake/seam_stitch.h)
void addSeamsOption(CLI::App& cmd, std::string& seams);
// --supersample auto|1|2|4 (bake and viewer), and its BakeOptions::supersample (auto: 0)
void addSupersampleOption(CLI::App& cmd, std::string& supersample);
// --history-power and --history-plateau (BakeOptions::historyPower, historyPlateau)
void addHistoryOptions(CLI::App& cmd, float& power, int& plateau);
int supersampleValue(const std::string& supersample);

// Parses "r,g,b" (three finite numbers >= 0) or a single number for grey.
Expected<glm::vec3> parseColor(const std::string& text, const char* flag);
// Parses "512M", "2G", "300000K", "1048576" (bytes).
Expected<int64_t> parseSize(const std::string& text, const char* flag);
// Reads --env into `environment` when `path` is not empty; error names the file.
Status loadEnvironment(const std::string& path, std::optional<io::ImageRgb>& environment);

// Loads the scene and computes the layout from SceneArgs; errors are one line.
struct LoadedScene {
    Scene scene;
    Layout layout;
};
// Generates TEXCOORD_1 where the layout needs it (see computeLayout(Scene&)).
Expected<LoadedScene> loadSceneAndLayout(const SceneArgs& args);
// The scene of `args` loaded with its --default-albedo (no layout).
Expected<Scene> loadSceneFromArgs(const SceneArgs& args);

// The layout flags the command line gave (not their defaults): commands that
// read a bake's manifest.json take its layout and refuse a flag that differs.
struct LayoutFlagsGiven {
    bool uvLayout = false, resolution = false, texelDensity = false;
};
// From a parsed command that has addSceneOptions (call in its callback).
LayoutFlagsGiven layoutFlagsGiven(const CLI::App& cmd);

// The scene of `args` with the layout recorded in BAKE_DIR/manifest.json
// (bake_output.h, readBakeManifest): the same rectangles and generated
// TEXCOORD_1 as the bake, whatever the flags' defaults. A layout flag that was
// given and differs from the manifest is an error (one line naming both); a
// manifest from before the layout record takes the given flags for what it lacks.
Expected<LoadedScene> loadSceneWithBakeLayout(const SceneArgs& args, const LayoutFlagsGiven& given,
                                              const std::string& bakeDir);

// An option's check: a whole number in [1, max], or one of `words` ("auto", "off").
CLI::Validator countOr(std::vector<std::string> words, long max);

// --uv-layout's names.
UvLayout parseUvLayout(const std::string& name);
const char* uvLayoutName(UvLayout mode);

// Command registration: adds the subcommand to `app`; when it is parsed, its
// callback stores the command's run function into `action`.
void addInfoCommand(CLI::App& app, std::function<int()>& action);
void addBakeCommand(CLI::App& app, std::function<int()>& action);
void addImportanceCommand(CLI::App& app, std::function<int()>& action);  // importance_command.cpp
void addRenderCommand(CLI::App& app, std::function<int()>& action);     // render_command.cpp
void addReferenceCommand(CLI::App& app, std::function<int()>& action);  // reference_command.cpp
void addCompareCommand(CLI::App& app, std::function<int()>& action);    // compare_command.cpp
void addExportCommand(CLI::App& app, std::function<int()>& action);     // export_command.cpp
void addCheckCommand(CLI::App& app, std::function<int()>& action);      // check_command.cpp

int runInfo(const InfoArgs& args);
int runBake(const BakeArgs& args);

// Prints "bundlebake: error: <message>" to stderr and returns 1.
int fail(const std::string& message);
// Said before "error:" in fail()'s line (an MPI rank's number).
void setFailPrefix(const std::string& prefix);

}  // namespace bb::cli
