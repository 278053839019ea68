#include "headless/cli/options.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <sstream>

#include "bake/bake_output.h"
#include "core/log.h"

namespace bb::cli {

namespace {
std::string& failPrefix() {
    static std::string prefix;
    return prefix;
}
}  // namespace

void setFailPrefix(const std::string& prefix) { failPrefix() = prefix; }

int fail(const std::string& message) {
    std::fprintf(stderr, "bundlebake: %serror: %s\n", failPrefix().c_str(), message.c_str());
    return 1;
}

void addSceneOptions(CLI::App& cmd, SceneArgs& a) {
    cmd.add_option("scene", a.scene, "glTF 2.0 scene (.gltf or .glb)")->required();
    cmd.add_option("--uv-layout", a.uvLayout,
                   "Light map layout: pack (a rectangle per instance; TEXCOORD_1 generated where a mesh has none), "
                   "generate (pack, with TEXCOORD_1 generated for every mesh) or asset (TEXCOORD_1 as one atlas)")
        ->check(CLI::IsMember({"pack", "generate", "asset"}))
        ->capture_default_str();
    cmd.add_option("--uv-overlap", a.uvOverlap,
                   "Overlapping TEXCOORD_1 charts under --uv-layout asset: warn (count and where) or fail")
        ->check(CLI::IsMember({"warn", "fail"}))
        ->capture_default_str();
    cmd.add_option("--resolution", a.resolution, "Light map page size in texels (square)")
        ->check(CLI::Range(16, 16384))
        ->capture_default_str();
    cmd.add_option("--texel-density", a.texelDensity,
                   "Texels per scene unit for the pack layout (0 = fit the scene into about one page)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd.add_option("--default-albedo", a.defaultAlbedo, "Diffuse albedo for primitives without a material (r,g,b)")
        ->capture_default_str();
}

void addInfoCommand(CLI::App& app, std::function<int()>& action) {
    auto args = std::make_shared<InfoArgs>();
    CLI::App* cmd = app.add_subcommand(
        "info", "Describe a scene: triangles, instances, materials, emitters, lights, bounds, light map texels and pages");
    addSceneOptions(*cmd, args->scene);
    cmd->callback([args, &action] { action = [args] { return runInfo(*args); }; });
}

Expected<glm::vec3> parseColor(const std::string& text, const char* flag) {
    std::vector<float> v;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            size_t used = 0;
            float f = std::stof(item, &used);
            if (used != item.size() || !std::isfinite(f) || f < 0) throw std::invalid_argument("");
            v.push_back(f);
        } catch (...) {
            return Expected<glm::vec3>::failure(std::string(flag) + ": '" + text +
                                                "' is not a colour (expected r,g,b with finite values >= 0)");
        }
    }
    if (v.size() == 1) return glm::vec3(v[0]);
    if (v.size() != 3)
        return Expected<glm::vec3>::failure(std::string(flag) + ": '" + text + "' is not a colour (expected r,g,b)");
    return glm::vec3(v[0], v[1], v[2]);
}

Expected<int64_t> parseSize(const std::string& text, const char* flag) {
    char* end = nullptr;
    double v = std::strtod(text.c_str(), &end);
    std::string suffix = end ? std::string(end) : "";
    double mult = 1;
    if (suffix == "K" || suffix == "k" || suffix == "KiB") mult = 1024.0;
    else if (suffix == "M" || suffix == "m" || suffix == "MiB") mult = 1024.0 * 1024;
    else if (suffix == "G" || suffix == "g" || suffix == "GiB") mult = 1024.0 * 1024 * 1024;
    else if (!suffix.empty() || end == text.c_str())
        return Expected<int64_t>::failure(std::string(flag) + ": '" + text + "' is not a size (e.g. 512M, 2G)");
    if (!(v > 0) || !std::isfinite(v))
        return Expected<int64_t>::failure(std::string(flag) + ": '" + text + "' must be positive");
    return int64_t(v * mult);
}

Status loadEnvironment(const std::string& path, std::optional<io::ImageRgb>& environment) {
    if (path.empty()) return Status::ok();
    auto env = io::readImageRgb(path);
    if (!env) return env.status();
    environment = std::move(env.value());
    return Status::ok();
}

UvLayout parseUvLayout(const std::string& name) {
    return name == "asset" ? UvLayout::Asset : name == "generate" ? UvLayout::Generate : UvLayout::Pack;
}

const char* uvLayoutName(UvLayout mode) {
    return mode == UvLayout::Asset ? "asset" : mode == UvLayout::Generate ? "generate" : "pack";
}

Expected<Scene> loadSceneFromArgs(const SceneArgs& a) {
    auto albedo = parseColor(a.defaultAlbedo, "--default-albedo");
    if (!albedo) return albedo.status();
    LoadOptions lo;
    lo.defaultAlbedo = *albedo;
    return loadScene(a.scene, lo);
}

Expected<LoadedScene> loadSceneAndLayout(const SceneArgs& a) {
    auto scene = loadSceneFromArgs(a);
    if (!scene) return scene.status();
    LayoutOptions opts;
    opts.mode = parseUvLayout(a.uvLayout);
    opts.failOnOverlap = a.uvOverlap == "fail";
    opts.resolution = a.resolution;
    opts.texelDensity = a.texelDensity;
    auto layout = computeLayout(*scene, opts);
    if (!layout) return Expected<LoadedScene>::failure(a.scene + ": " + layout.error());
    return LoadedScene{std::move(scene.value()), std::move(layout.value())};
}

LayoutFlagsGiven layoutFlagsGiven(const CLI::App& cmd) {
    LayoutFlagsGiven g;
    g.uvLayout = cmd.count("--uv-layout") > 0;
    g.resolution = cmd.count("--resolution") > 0;
    g.texelDensity = cmd.count("--texel-density") > 0;
    return g;
}

Expected<LoadedScene> loadSceneWithBakeLayout(const SceneArgs& a, const LayoutFlagsGiven& given,
                                              const std::string& bakeDir) {
    auto manifest = readBakeManifest(bakeDir);
    if (!manifest) return manifest.status();
    LayoutOptions opts = manifest->layout;
    const std::string where = " (" + bakeDir + "/manifest.json; leave the layout flags out to use the bake's)";
    auto number = [](double v) {
        char s[32];
        std::snprintf(s, sizeof s, "%g", v);
        return std::string(s);
    };
    if (given.uvLayout && parseUvLayout(a.uvLayout) != opts.mode) {
        // an old manifest records a generate layout as pack: the flag decides there
        if (manifest->layoutRecorded || !(opts.mode == UvLayout::Pack && a.uvLayout == "generate"))
            return Expected<LoadedScene>::failure("--uv-layout " + a.uvLayout + " differs from the bake's " +
                                                  uvLayoutName(opts.mode) + where);
        opts.mode = UvLayout::Generate;
    }
    if (given.resolution && a.resolution != opts.resolution)
        return Expected<LoadedScene>::failure("--resolution " + std::to_string(a.resolution) + " differs from the bake's " +
                                              std::to_string(opts.resolution) + where);
    if (given.texelDensity) {
        if (manifest->layoutRecorded && a.texelDensity != opts.texelDensity)
            return Expected<LoadedScene>::failure("--texel-density " + number(a.texelDensity) +
                                                  " differs from the bake's " + number(opts.texelDensity) + where);
        opts.texelDensity = a.texelDensity;
    }
    opts.failOnOverlap = false;  // the bake accepted its layout

    auto scene = loadSceneFromArgs(a);
    if (!scene) return scene.status();
    if (scene->instances.size() != manifest->instanceCount)
        return Expected<LoadedScene>::failure(a.scene + " has " + std::to_string(scene->instances.size()) +
                                              " mesh instances, the bake in " + bakeDir + " " +
                                              std::to_string(manifest->instanceCount) + " (the bake of " +
                                              (manifest->scene.empty() ? "another scene" : manifest->scene) + "?)");
    auto layout = computeLayout(*scene, opts);
    if (!layout) return Expected<LoadedScene>::failure(a.scene + ": " + layout.error());
    return LoadedScene{std::move(scene.value()), std::move(layout.value())};
}

int runInfo(const InfoArgs& args) {
    // the scene is described even when no layout can be made for it (no
    // TEXCOORD_1): the layout lines then say why
    auto scene = loadSceneFromArgs(args.scene);
    if (!scene) return fail(scene.error());
    LayoutOptions opts;
    opts.mode = parseUvLayout(args.scene.uvLayout);
    opts.resolution = args.scene.resolution;
    opts.texelDensity = args.scene.texelDensity;
    const bool hadUv1 = scene->allHaveUv1();
    auto layout = computeLayout(*scene, opts);  // generates TEXCOORD_1 where the layout needs it
    const Scene& s = *scene;
    size_t emissiveMaterials = 0;
    for (const auto& m : s.materials)
        if (m.emission.r > 0 || m.emission.g > 0 || m.emission.b > 0) ++emissiveMaterials;
    glm::vec3 size = s.bounds.size();
    std::printf("scene        %s\n", s.path.c_str());
    std::printf("triangles    %zu (in %zu instances of %zu meshes)\n", s.triangleCount(), s.instances.size(), s.meshes.size());
    std::printf("skipped      %zu degenerate triangles, %zu non-triangle primitives\n",
                s.report.skippedDegenerateTriangles, s.report.skippedNonTrianglePrimitives);
    std::printf("materials    %zu (%zu emissive, %zu primitives use the default albedo)\n", s.materials.size(),
                emissiveMaterials, s.report.primitivesWithoutMaterial);
    std::printf("emitters     %zu emissive triangles\n", s.emitterTriangleCount());
    size_t spots = 0, cutouts = 0;
    for (const auto& light : s.punctualLights) spots += light.type == bb::PunctualLight::Type::Spot;
    for (const auto& m : s.materials) cutouts += m.alphaMask;
    std::printf("lights       %zu directional, %zu point, %zu spot\n", s.lights.size(), s.punctualLights.size() - spots,
                spots);
    for (const auto& light : s.lights)
        std::printf("             %s: direction (%.3f, %.3f, %.3f), irradiance (%.3g, %.3g, %.3g)\n", light.name.c_str(),
                    light.direction.x, light.direction.y, light.direction.z, light.irradiance.r, light.irradiance.g,
                    light.irradiance.b);
    for (const auto& light : s.punctualLights)
        std::printf("             %s: %s at (%.4g, %.4g, %.4g), intensity (%.3g, %.3g, %.3g) cd, range %s\n",
                    light.name.c_str(), light.type == bb::PunctualLight::Type::Spot ? "spot" : "point", light.position.x,
                    light.position.y, light.position.z, light.intensity.r, light.intensity.g, light.intensity.b,
                    light.range > 0 ? std::to_string(light.range).c_str() : "infinite");
    if (cutouts) std::printf("cut-outs     %zu material(s) with alphaMode MASK\n", cutouts);
    std::printf("cameras      %zu\n", s.cameras.size());
    std::printf("textures     %zu\n", s.textures.size());
    std::printf("bounds       min (%.4g, %.4g, %.4g) max (%.4g, %.4g, %.4g) size (%.4g, %.4g, %.4g) scene units\n",
                s.bounds.min.x, s.bounds.min.y, s.bounds.min.z, s.bounds.max.x, s.bounds.max.y, s.bounds.max.z, size.x,
                size.y, size.z);
    std::printf("uv1          %s\n", hadUv1 ? "present on every primitive" : "missing on some primitives");
    if (!layout) {
        std::printf("layout       none: %s\n", layout.error().c_str());
        return 0;
    }
    const Layout& l = *layout;
    size_t coveredTexels = 0;
    for (const auto& r : l.rects) coveredTexels += size_t(r.width) * r.height;
    if (l.mode == UvLayout::Asset) coveredTexels = l.texelCount();
    std::printf("layout       %s, %d page(s) of %dx%d texels, padding %d\n", uvLayoutName(l.mode), l.pageCount,
                l.resolution, l.resolution, l.padding);
    if (l.mode != UvLayout::Asset) std::printf("density      %.6g texels per scene unit\n", l.texelDensity);
    std::printf("texels       %zu in pages, %zu inside instance rectangles\n", l.texelCount(), coveredTexels);
    const UvGenerationStats& uv = l.uv;
    if (uv.meshes > 0) {
        std::printf("generated    TEXCOORD_1 for %zu mesh(es) (%zu copies for instances of another size or shape) "
                    "in %.2f s (charts %.2f s, packing %.2f s)\n",
                    uv.meshes, uv.copiedMeshes, uv.chartSeconds + uv.packSeconds, uv.chartSeconds, uv.packSeconds);
        std::printf("charts       %zu (%zu flattened by LSCM, %zu planar; %zu smaller than a texel)\n", uv.charts,
                    uv.lscmCharts, uv.charts - uv.lscmCharts, uv.subTexelCharts);
        std::printf("stretch      worst %.4f, mean %.4f (chart L2 stretch, 1 = none)\n", uv.worstStretch, uv.meanStretch);
        std::printf("utilisation  %.1f %% (%zu covered of %zu texels in the generated meshes' rectangles; "
                    "%zu in two charts)\n",
                    uv.gridTexels ? 100.0 * double(uv.coveredTexels) / double(uv.gridTexels) : 0.0, uv.coveredTexels,
                    uv.gridTexels, uv.overlappingTexels);
    }
    const TexelCoverage cov = measureCoverage(s, l);
    std::printf("covered      %zu texel centres inside triangles: %.1f %% of the pages, %.1f %% of the rectangles; "
                "%zu inside two\n",
                cov.covered, l.texelCount() ? 100.0 * double(cov.covered) / double(l.texelCount()) : 0.0,
                coveredTexels ? 100.0 * double(cov.covered) / double(coveredTexels) : 0.0, cov.overlapping);
    return 0;
}

void addSupersampleOption(CLI::App& cmd, std::string& supersample) {
    cmd.add_option("--supersample", supersample,
                   "Bake each light map texel as 2 x 2 half-size (or 4 x 4 quarter-size) texels and average them over its "
                   "footprint, or not (1): less bias and noise for 4x (16x) the light-map memory; auto = 4 where a fifth of "
                   "the half-size texels are cut by a chart's edge or shared by charts, else 2, each when it takes at most "
                   "half the memory budget")
        ->check(CLI::IsMember({"auto", "1", "2", "4"}))
        ->capture_default_str();
}

void addHistoryOptions(CLI::App& cmd, float& power, int& plateau) {
    cmd.add_option("--history-power", power,
                   "Weight direction k by min(k, plateau)^p to fade early, few-bounce directions (-1 = from the scene's transport albedo, the light's share kept per bounce)")
        ->capture_default_str();
    cmd.add_option("--history-plateau", plateau,
                   "The direction from which every one weighs the same (0 = the earliest after which the bounce-lag model leaves under 0.02/sqrt(N) of the bounced light to come, at most N/2)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
}

int supersampleValue(const std::string& supersample) { return supersample == "auto" ? 0 : std::stoi(supersample); }

CLI::Validator countOr(std::vector<std::string> words, long max) {
    std::string names;
    for (const std::string& w : words) names += w + ", ";
    const std::string description = "must be " + names + "or 1 to " + std::to_string(max);
    return CLI::Validator(
        [words, max, description](std::string& v) -> std::string {
            if (std::find(words.begin(), words.end(), v) != words.end()) return {};
            char* end = nullptr;
            const long n = std::strtol(v.c_str(), &end, 10);
            return end != v.c_str() && *end == 0 && n >= 1 && n <= max ? std::string{} : description;
        },
        "");
}

}  // namespace bb::cli
