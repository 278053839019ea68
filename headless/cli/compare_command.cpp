// `bundlebake compare A B`: error of light maps A against B (B is the
// reference), over covered texels, as numbers and a false-colour image. No GL.
//
// A and B are bake output directories (manifest.json + lightmap_<page>.exr +
// coverage_<page>.png, as `bake` and `reference` write them) or two EXR files.
// Texels compared (--mask): by default those covered in both A and B (from
// their coverage masks; an input without masks does not restrict); a DIR takes
// that directory's masks; `none` compares every texel, padding included.
//
// Metrics, over the compared texels n and the three channels c (3n values):
//   rmse        sqrt(mean (a - b)^2)
//   rel_rmse    rmse / mean b
//   rel_mse     mean (a - b)^2 / (b^2 + 0.01)       (0.01: keeps dark texels from dominating)
//   mean_ratio  sum a / sum b                      (1 = no overall bias)
//   mean_abs    mean |a - b|
//   max_abs     max |a - b|
// and rel_rmse over two parts of the compared texels (each still over mean b
// of all, so that their squares, weighted by their shares of the texels, add
// up to rel_rmse's): interior (the texel and its 8 neighbours all compared:
// a whole square on one chart) and border (the rest: partial footprints,
// chart seams), where a bake's sampling of a texel's footprint differs most
// from a reference's.
// The error image shows mean over channels |a - b| per texel, scaled so that
// --scale (default: the 99th percentile over compared texels) is the top of
// the colour ramp (black, blue, cyan, yellow, red, white at 2x); texels not
// compared are dark grey. One PNG per page (error.png, or error_<page>.png when
// there are several pages).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "bake/bake_output.h"
#include "headless/cli/options.h"
#include "io/image_io.h"

namespace bb::cli {
namespace {

namespace fs = std::filesystem;

struct CompareArgs {
    std::string a, b;
    std::string mask;  // "" = both inputs' masks, "none", or a directory
    std::string errorPng;
    float scale = 0.0f;
    bool json = false;
};

struct Maps {
    std::vector<io::ImageRgb> pages;
    std::vector<std::vector<uint8_t>> covered;  // empty when the input has no masks
};

Expected<std::vector<std::vector<uint8_t>>> readMasks(const std::string& dir, const nlohmann::json& manifest) {
    std::vector<std::vector<uint8_t>> masks;
    for (const auto& page : manifest.at("pages")) {
        if (!page.contains("coverage_png"))
            return Expected<std::vector<std::vector<uint8_t>>>::failure(
                dir + "/manifest.json: page " + page.at("page").dump() + " has no coverage_png (re-run the bake)");
        auto img = io::readImageRgb(dir + "/" + page.at("coverage_png").get<std::string>());
        if (!img) return img.status();
        std::vector<uint8_t> m(img->pixels.size());
        for (size_t i = 0; i < m.size(); ++i) m[i] = img->pixels[i].r > 0.5f;
        masks.push_back(std::move(m));
    }
    return masks;
}

Expected<nlohmann::json> readManifest(const std::string& dir) {
    std::ifstream in(dir + "/manifest.json");
    if (!in) return Expected<nlohmann::json>::failure(dir + ": not a bake output directory (no manifest.json)");
    try {
        nlohmann::json j = nlohmann::json::parse(in);
        if (!j.contains("pages") || !j["pages"].is_array())
            return Expected<nlohmann::json>::failure(dir + "/manifest.json: no pages array");
        return j;
    } catch (const std::exception& e) {
        return Expected<nlohmann::json>::failure(dir + "/manifest.json: " + e.what());
    }
}

Expected<Maps> readMaps(const std::string& path) {
    Maps maps;
    if (!fs::is_directory(path)) {
        auto img = io::readImageRgb(path);
        if (!img) return img.status();
        maps.pages.push_back(std::move(img.value()));
        return maps;
    }
    auto manifest = readManifest(path);
    if (!manifest) return manifest.status();
    bool allMasks = true;
    try {
        for (const auto& page : (*manifest)["pages"]) {
            auto img = io::readImageRgb(path + "/" + page.at("exr").get<std::string>());
            if (!img) return img.status();
            maps.pages.push_back(std::move(img.value()));
            allMasks = allMasks && page.contains("coverage_png");
        }
        if (allMasks) {
            auto masks = readMasks(path, *manifest);
            if (!masks) return masks.status();
            maps.covered = std::move(masks.value());
        }
    } catch (const std::exception& e) {
        return Expected<Maps>::failure(path + "/manifest.json: " + e.what());
    }
    return maps;
}

glm::vec3 ramp(float x) {  // x in [0, 2]: black, blue, cyan, yellow, red (1), white (2)
    static const glm::vec3 stops[] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 0}, {1, 0, 0}, {1, 1, 1}};
    static const float at[] = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f, 2.0f};
    x = std::clamp(x, 0.0f, 2.0f);
    for (int i = 0; i < 5; ++i)
        if (x <= at[i + 1]) return glm::mix(stops[i], stops[i + 1], (x - at[i]) / (at[i + 1] - at[i]));
    return stops[5];
}

std::string pagePngName(const std::string& path, size_t page, size_t pages) {
    if (pages == 1) return path;
    fs::path p(path);
    return (p.parent_path() / (p.stem().string() + "_" + std::to_string(page) + p.extension().string())).string();
}

int runCompare(const CompareArgs& args) {
    auto a = readMaps(args.a);
    if (!a) return fail(a.error());
    auto b = readMaps(args.b);
    if (!b) return fail(b.error());
    if (a->pages.size() != b->pages.size())
        return fail("page counts differ: " + std::to_string(a->pages.size()) + " in " + args.a + ", " +
                    std::to_string(b->pages.size()) + " in " + args.b);
    for (size_t p = 0; p < a->pages.size(); ++p)
        if (a->pages[p].width != b->pages[p].width || a->pages[p].height != b->pages[p].height)
            return fail("page " + std::to_string(p) + " sizes differ: " + std::to_string(a->pages[p].width) + "x" +
                        std::to_string(a->pages[p].height) + " vs " + std::to_string(b->pages[p].width) + "x" +
                        std::to_string(b->pages[p].height));

    // the texels to compare
    std::vector<std::vector<uint8_t>> mask(a->pages.size());
    for (size_t p = 0; p < a->pages.size(); ++p) mask[p].assign(a->pages[p].pixels.size(), 1);
    int64_t onlyA = 0, onlyB = 0;
    std::string maskSource;
    if (args.mask == "none") {
        maskSource = "none (every texel)";
    } else if (!args.mask.empty()) {
        auto manifest = readManifest(args.mask);
        if (!manifest) return fail(manifest.error());
        auto masks = readMasks(args.mask, *manifest);
        if (!masks) return fail(masks.error());
        if (masks->size() != mask.size()) return fail("--mask " + args.mask + ": page count differs from the inputs'");
        for (size_t p = 0; p < mask.size(); ++p) {
            if ((*masks)[p].size() != mask[p].size()) return fail("--mask " + args.mask + ": page size differs");
            mask[p] = (*masks)[p];
        }
        maskSource = args.mask;
    } else {
        for (size_t p = 0; p < mask.size(); ++p)
            for (size_t i = 0; i < mask[p].size(); ++i) {
                bool inA = a->covered.empty() || a->covered[p][i];
                bool inB = b->covered.empty() || b->covered[p][i];
                if (!a->covered.empty() && !b->covered.empty()) {  // only meaningful when both have masks
                    onlyA += inA && !inB;
                    onlyB += inB && !inA;
                }
                mask[p][i] = inA && inB;
            }
        maskSource = a->covered.empty() && b->covered.empty() ? "none (no coverage masks in the inputs)"
                                                                : "covered in both";
    }

    // metrics
    int64_t n = 0, interior = 0;
    double sumSq = 0, sumRel = 0, sumA = 0, sumB = 0, sumAbs = 0, maxAbs = 0, interiorSq = 0;
    std::vector<float> errors;
    for (size_t p = 0; p < mask.size(); ++p)
        for (size_t i = 0; i < mask[p].size(); ++i) {
            if (!mask[p][i]) continue;
            const glm::vec3 va = a->pages[p].pixels[i], vb = b->pages[p].pixels[i];
            ++n;
            const int width = a->pages[p].width, height = a->pages[p].height;
            const int x = int(i % size_t(width)), y = int(i / size_t(width));
            bool inner = true;
            for (int dy = -1; dy <= 1 && inner; ++dy)
                for (int dx = -1; dx <= 1 && inner; ++dx)
                    inner = x + dx >= 0 && x + dx < width && y + dy >= 0 && y + dy < height &&
                            mask[p][size_t(y + dy) * size_t(width) + size_t(x + dx)];
            interior += inner;
            float e = 0.0f;
            for (int c = 0; c < 3; ++c) {
                double d = double(va[c]) - double(vb[c]);
                sumSq += d * d;
                if (inner) interiorSq += d * d;
                sumRel += d * d / (double(vb[c]) * vb[c] + 1e-2);
                sumA += va[c];
                sumB += vb[c];
                sumAbs += std::fabs(d);
                maxAbs = std::max(maxAbs, std::fabs(d));
                e += float(std::fabs(d)) / 3.0f;
            }
            errors.push_back(e);
        }
    if (n == 0) return fail("no texels to compare (the coverage masks do not overlap)");
    const double values = 3.0 * double(n);
    const double rmse = std::sqrt(sumSq / values);
    const double meanB = sumB / values;
    // rel_rmse over a part of the texels: its rms over mean b of all
    auto partRelRmse = [&](double sq, int64_t texels) {
        return texels > 0 && meanB != 0.0 ? std::sqrt(sq / (3.0 * double(texels))) / std::fabs(meanB) : 0.0;
    };
    nlohmann::json result = {
        {"a", args.a},
        {"b", args.b},
        {"mask", maskSource},
        {"texels", n},
        {"texels_only_in_a", onlyA},
        {"texels_only_in_b", onlyB},
        {"rmse", rmse},
        {"rel_rmse", meanB != 0.0 ? rmse / std::fabs(meanB) : 0.0},
        {"rel_mse", sumRel / values},
        {"mean_ratio", sumB != 0.0 ? sumA / sumB : 0.0},
        {"mean_abs", sumAbs / values},
        {"max_abs", maxAbs},
        {"mean_b", meanB},
        {"interior_texels", interior},
        {"interior_rel_rmse", partRelRmse(interiorSq, interior)},
        {"border_rel_rmse", partRelRmse(sumSq - interiorSq, n - interior)},
        {"definitions",
         "over compared texels and the 3 channels: rmse = sqrt(mean (a-b)^2); rel_rmse = rmse / mean b; "
         "rel_mse = mean (a-b)^2 / (b^2 + 0.01); mean_ratio = sum a / sum b; mean_abs = mean |a-b|; max_abs = max |a-b|; "
         "interior_rel_rmse, border_rel_rmse: rms (a-b) over the texels whose 8 neighbours are compared too, and over "
         "the rest, each / mean b of all"},
    };

    // error image
    if (!args.errorPng.empty()) {
        float scale = args.scale;
        if (!(scale > 0.0f)) {
            std::vector<float> sorted = errors;
            auto q = sorted.begin() + std::ptrdiff_t(double(sorted.size() - 1) * 0.99);
            std::nth_element(sorted.begin(), q, sorted.end());
            scale = *q > 0.0f ? *q : 1.0f;
        }
        result["error_png_scale"] = scale;
        nlohmann::json files = nlohmann::json::array();
        for (size_t p = 0; p < mask.size(); ++p) {
            io::ImageRgb img;
            img.width = a->pages[p].width;
            img.height = a->pages[p].height;
            img.pixels.assign(a->pages[p].pixels.size(), glm::vec3(0.12f));
            for (size_t i = 0; i < mask[p].size(); ++i) {
                if (!mask[p][i]) continue;
                glm::vec3 d = glm::abs(a->pages[p].pixels[i] - b->pages[p].pixels[i]);
                img.pixels[i] = ramp((d.r + d.g + d.b) / 3.0f / scale);
            }
            std::string file = pagePngName(args.errorPng, p, mask.size());
            if (Status s = io::writePng(file, img, false); !s) return fail(s.message());
            files.push_back(file);
        }
        result["error_png"] = files;
    }

    if (args.json) {
        std::printf("%s\n", result.dump(2).c_str());
        return 0;
    }
    std::printf("texels      %lld compared (%s; %lld only in A, %lld only in B)\n", (long long)n, maskSource.c_str(),
                (long long)onlyA, (long long)onlyB);
    std::printf("rmse        %.6g\n", rmse);
    std::printf("rel_rmse    %.6g   (rmse / mean B = %.6g)\n", result["rel_rmse"].get<double>(), meanB);
    std::printf("  interior  %.6g   (%lld texels whose 8 neighbours are compared too)\n",
                result["interior_rel_rmse"].get<double>(), (long long)interior);
    std::printf("  border    %.6g   (%lld texels: partial footprints, chart seams)\n",
                result["border_rel_rmse"].get<double>(), (long long)(n - interior));
    std::printf("rel_mse     %.6g   (mean (a-b)^2 / (b^2 + 0.01))\n", result["rel_mse"].get<double>());
    std::printf("mean_ratio  %.6f   (sum A / sum B)\n", result["mean_ratio"].get<double>());
    std::printf("mean_abs    %.6g\n", sumAbs / values);
    std::printf("max_abs     %.6g\n", maxAbs);
    if (result.contains("error_png"))
        std::printf("error_png   %s (scale %.4g)\n", result["error_png"][0].get<std::string>().c_str(),
                    result["error_png_scale"].get<double>());
    return 0;
}

}  // namespace

void addCompareCommand(CLI::App& app, std::function<int()>& action) {
    auto a = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand(
        "compare", "Error of light maps A against reference B (output dirs or EXR files), over covered texels");
    cmd->add_option("a", a->a, "Light maps to measure: a bake output directory or an EXR file")->required();
    cmd->add_option("b", a->b, "Reference light maps: a bake output directory or an EXR file")->required();
    cmd->add_option("--mask", a->mask,
                    "Texels to compare: a bake output directory whose coverage masks to use, or 'none' for every "
                    "texel (default: texels covered in both A and B)");
    cmd->add_option("-o,--output", a->errorPng, "False-colour error PNG (|A-B| per texel)");
    cmd->add_option("--scale", a->scale, "Error at the top of the colour ramp (default: 99th percentile)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--json", a->json, "Print the metrics as JSON");
    cmd->callback([a, &action] { action = [a] { return runCompare(*a); }; });
}

}  // namespace bb::cli
