// `bundlebake importance`: the supplement §1 importance analysis of a scene's
// light map layout, as maps and figures. Writes into OUTDIR (each file
// atomically):
//   importance_<page>.exr  half RGB, R = G = B = I(t) of the triangle drawn at
//                          each texel (0 where unmapped), times `exr_scale`
//                          (1 unless I(t) would leave the half range)
//   importance_<page>.png  false colour of log10 I(t) over the range in
//                          importance.json; magenta = mapped with I(t) = 0,
//                          black = unmapped
//   importance.json        the range, the distribution, timings
// and prints the distribution of I(t) over triangles.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/log.h"
#include "headless/cli/options.h"
#include "headless/platform.h"
#include "importance/importance_gl.h"
#include "io/image_io.h"
#include "layout/bake_mesh.h"

namespace bb::cli {
namespace {

struct ImportanceArgs {
    SceneArgs scene;
    std::string outDir;
    std::string backend = "egl";
};

constexpr float HALF_MAX = 65504.0f;

// A power of two that brings the largest value into [2^14, 2^15] when it
// would overflow half (> 2^15) or sit in half's subnormal / low-precision
// range (< 2^-4); 1 otherwise, so most maps hold I(t) itself.
float exrScale(float maxValue) {
    if (!(maxValue > 0.0f) || (maxValue <= 32768.0f && maxValue >= 0.0625f)) return 1.0f;
    return std::exp2(14.0f - std::floor(std::log2(maxValue)));
}

// Log-scale false colour: dark blue, cyan, green, yellow, red at t = 0, 1/4, 1/2, 3/4, 1.
glm::vec3 falseColour(float t) {
    static const glm::vec3 stops[5] = {{0.05f, 0.05f, 0.45f}, {0.0f, 0.6f, 1.0f}, {0.1f, 0.8f, 0.2f},
                                       {1.0f, 0.85f, 0.0f}, {0.9f, 0.1f, 0.05f}};
    t = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    const int i = std::min(int(t), 3);
    return glm::mix(stops[i], stops[i + 1], t - float(i));
}

int runImportance(const ImportanceArgs& args) {
    auto backend = parseBackend(args.backend);
    if (!backend) return fail(backend.error());
    auto loaded = loadSceneAndLayout(args.scene);
    if (!loaded) return fail(loaded.error());
    const Layout& layout = loaded->layout;
    if (Status s = io::ensureDirectory(args.outDir); !s) return fail(s.message());
    auto context = createHeadlessContext(*backend);
    if (!context) return fail(context.error());

    const BakeMesh mesh = buildBakeMesh(loaded->scene, layout);
    auto analyzer = ImportanceAnalyzer::create();
    if (!analyzer) return fail(analyzer.error());
    ImportanceCapture capture;
    capture.texelTriangles = true;
    auto result = (*analyzer)->analyze(mesh, layout.resolution, capture);
    if (!result) return fail(result.error());
    const Importance& imp = result->importance;
    const ImportanceSummary summary = summarize(imp);
    const int R = layout.resolution;

    // the per-texel map: I(t) of the triangle drawn at each texel
    size_t mapped = 0;
    float texelMin = 0.0f, texelMax = 0.0f;  // over mapped texels with I > 0
    for (const auto& page : result->texelTriangles)
        for (uint32_t id : page) {
            if (!id) continue;
            ++mapped;
            const float v = imp.importance[id - 1];
            if (v > 0.0f) {
                texelMin = texelMin > 0.0f ? std::min(texelMin, v) : v;
                texelMax = std::max(texelMax, v);
            }
        }
    const float scale = exrScale(summary.max);
    const double logMin = texelMin > 0.0f ? std::log10(double(texelMin)) : 0.0;
    double logMax = texelMax > 0.0f ? std::log10(double(texelMax)) : 0.0;
    const double logSpan = logMax > logMin ? logMax - logMin : 0.0;

    nlohmann::json exrFiles = nlohmann::json::array(), pngFiles = nlohmann::json::array();
    for (size_t p = 0; p < result->texelTriangles.size(); ++p) {
        const auto& ids = result->texelTriangles[p];
        io::ImageRgb exr, png;
        exr.width = png.width = R;
        exr.height = png.height = R;
        exr.pixels.assign(size_t(R) * R, glm::vec3(0.0f));
        png.pixels.assign(size_t(R) * R, glm::vec3(0.0f));
        for (size_t i = 0; i < ids.size(); ++i) {
            if (!ids[i]) continue;
            const float v = imp.importance[ids[i] - 1];
            exr.pixels[i] = glm::vec3(std::min(v * scale, HALF_MAX));
            png.pixels[i] = v > 0.0f ? falseColour(logSpan > 0.0 ? float((std::log10(double(v)) - logMin) / logSpan) : 0.5f)
                                     : glm::vec3(1.0f, 0.0f, 1.0f);
        }
        // row 0 = v = 0, as the light maps (glTF: v runs down from the top of an image)
        const std::string stem = "importance_" + std::to_string(p);
        char scaleText[32];
        std::snprintf(scaleText, sizeof(scaleText), "%.9g", double(scale));
        if (Status s = io::writeExr(args.outDir + "/" + stem + ".exr", exr,
                                        {{"bundlebake:quantity", "I(t), light map texels per scene unit^2 (supplement Eq. 4)"},
                                         {"bundlebake:importance_scale", scaleText}});
            !s)
            return fail(s.message());
        if (Status s = io::writePng(args.outDir + "/" + stem + ".png", png, false); !s) return fail(s.message());
        exrFiles.push_back(stem + ".exr");
        pngFiles.push_back(stem + ".png");
    }

    const ImportanceTimings& t = result->seconds;
    const double n = double(std::max<size_t>(summary.triangles, 1));
    nlohmann::json j;
    j["scene"] = loaded->scene.path;
    j["backend"] = backendName(*backend);
    j["renderer"] = context.value()->caps().renderer;
    j["uv_layout"] = args.scene.uvLayout;
    j["resolution"] = R;
    j["pages"] = layout.pageCount;
    j["units"] = "light map texels per scene unit^2 (world space)";
    j["triangles"] = summary.triangles;
    j["mapped_texels"] = mapped;
    j["importance"] = {{"min", summary.min}, {"median", summary.median}, {"max", summary.max},
                       {"min_nonzero", summary.minNonZero}};
    j["clamped"] = summary.clamped;
    j["clamped_beyond_1_percent"] = summary.clampedBeyond1Percent;
    j["zero_max_density"] = summary.zeroMaxDensity;
    j["exr"] = {{"files", exrFiles}, {"scale", scale}, {"value", "R = G = B = I(t) * scale; 0 where unmapped"}};
    j["png"] = {{"files", pngFiles},
                {"log10_min", logMin},
                {"log10_max", logMax},
                {"min", texelMin},
                {"max", texelMax},
                {"colour_map", "log10 I(t) from log10_min to log10_max: dark blue, cyan, green, yellow, red"},
                {"zero", "magenta: mapped, I(t) = 0"},
                {"unmapped", "black"}};
    j["seconds"] = {{"upload", t.upload}, {"position_pass", t.positionPass}, {"max_density_pass", t.maxDensityPass},
                    {"compute_pass", t.computePass}, {"readback", t.readback}, {"total", t.total()}};
    if (Status s = io::writeJson(args.outDir + "/importance.json", j); !s) return fail(s.message());

    std::printf("scene        %s\n", loaded->scene.path.c_str());
    std::printf("triangles    %zu on %d page(s) of %dx%d texels, %zu texels mapped\n", summary.triangles,
                layout.pageCount, R, R, mapped);
    std::printf("I(t)         min %.6g  median %.6g  max %.6g  (smallest non-zero %.6g) texels per scene unit^2\n",
                double(summary.min), double(summary.median), double(summary.max), double(summary.minNonZero));
    if (summary.median > 0.0f)
        std::printf("bundle pixel %.6g scene units at the median I(t) (1/sqrt(I))\n", 1.0 / std::sqrt(double(summary.median)));
    std::printf("clamped      %zu triangles (%.1f%%): I_max(t) < A_l/A_o, Eq. (4) took the neighbourhood estimate; "
                "%zu (%.1f%%) by more than 1%%\n",
                summary.clamped, 100.0 * double(summary.clamped) / n, summary.clampedBeyond1Percent,
                100.0 * double(summary.clampedBeyond1Percent) / n);
    std::printf("zero I_max   %zu triangles (%.1f%%): cover no texel centre, so I(t) = 0\n", summary.zeroMaxDensity,
                100.0 * double(summary.zeroMaxDensity) / n);
    std::printf("time         %.1f ms: position pass %.1f, I_max pass %.1f, Eq. (4) pass %.1f, upload %.1f, readback %.1f\n",
                1e3 * t.total(), 1e3 * t.positionPass, 1e3 * t.maxDensityPass, 1e3 * t.computePass, 1e3 * t.upload,
                1e3 * t.readback);
    std::printf("png range    log10 I from %.4g to %.4g (importance.json)\n", logMin, logMax);
    logInfo("wrote " + std::to_string(exrFiles.size()) + " importance map(s) and importance.json to " + args.outDir);
    return 0;
}

}  // namespace

void addImportanceCommand(CLI::App& app, std::function<int()>& action) {
    auto args = std::make_shared<ImportanceArgs>();
    CLI::App* cmd = app.add_subcommand(
        "importance", "Light map texel density per triangle (importance, paper supplement §1): maps and figures");
    addSceneOptions(*cmd, args->scene);
    cmd->add_option("-o,--output", args->outDir, "Output directory (created if missing)")->required();
    cmd->add_option("--backend", args->backend, "Headless GL: egl (surfaceless) or osmesa")
        ->check(CLI::IsMember({"egl", "osmesa"}))
        ->capture_default_str();
    cmd->callback([args, &action] { action = [args] { return runImportance(*args); }; });
}

}  // namespace bb::cli
