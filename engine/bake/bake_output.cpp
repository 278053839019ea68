#include "bake/bake_output.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "io/image_io.h"

namespace bb {

namespace {

// Preview exposure: the 75th percentile of covered texels' luminance maps to
// 0.6 before the tone curve, so sunlit (L_lm ~ 1e3) and dim scenes both read.
float autoExposure(const LightmapPages& maps) {
    std::vector<float> lum;
    for (size_t p = 0; p < maps.pages.size(); ++p)
        for (size_t i = 0; i < maps.pages[p].pixels.size(); ++i)
            if (maps.covered[p][i]) {
                const glm::vec3& c = maps.pages[p].pixels[i];
                lum.push_back(0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b);
            }
    if (lum.empty()) return 0.0f;
    auto q = lum.begin() + std::ptrdiff_t(lum.size() * 3 / 4);
    std::nth_element(lum.begin(), q, lum.end());
    return *q > 0.0f ? std::log2(0.6f / *q) : 0.0f;
}

// The layout request that recomputes `layout`: its mode, resolution and
// padding, and the requested density from the run's flags
// (BakeOutputInfo::settings "texel_density", as bake, reference and the viewer
// echo it; 0 = auto), else the density the layout used.
nlohmann::json layoutRequest(const Layout& layout, const nlohmann::json& settings) {
    const char* mode = layoutModeName(layout.mode);
    double density = layout.mode == UvLayout::Asset ? 0.0 : double(layout.texelDensity);
    if (settings.is_object() && settings.contains("texel_density") && settings["texel_density"].is_number())
        density = settings["texel_density"].get<double>();
    const UvChartOptions charts;  // not a flag: always the defaults
    return {{"uv_layout", mode},
            {"resolution", layout.resolution},
            {"texel_density", density},
            {"padding_texels", layout.padding},
            {"uv_charts",
             {{"hard_angle_degrees", charts.hardAngleDegrees},
              {"cone_angle_degrees", charts.coneAngleDegrees},
              {"max_chart_triangles", charts.maxChartTriangles}}}};
}

}  // namespace

const char* layoutModeName(UvLayout mode) {
    return mode == UvLayout::Asset ? "asset" : mode == UvLayout::Generate ? "generate" : "pack";
}

Expected<BakeManifest> readBakeManifest(const std::string& dir) {
    using Fail = Expected<BakeManifest>;
    const std::string path = dir + "/manifest.json";
    std::ifstream file(path);
    if (!file) return Fail::failure("cannot read " + path + ": not a bundlebake light map directory");
    nlohmann::json m;
    try {
        file >> m;
    } catch (const nlohmann::json::exception&) {
        return Fail::failure(path + ": not valid JSON");
    }
    try {
        BakeManifest out;
        out.scene = m.value("scene", std::string());
        out.generator = m.value("generator", std::string());
        out.pageCount = int(m.at("pages").size());
        out.instanceCount = m.at("instances").size();
        auto modeOf = [&](const std::string& name) -> Expected<UvLayout> {
            if (name == "asset") return UvLayout::Asset;
            if (name == "pack") return UvLayout::Pack;
            if (name == "generate") return UvLayout::Generate;
            return Expected<UvLayout>::failure(path + ": unknown layout '" + name + "'");
        };
        if (m.contains("layout_options")) {
            const auto& o = m.at("layout_options");
            auto mode = modeOf(o.at("uv_layout").get<std::string>());
            if (!mode) return mode.status();
            out.layout.mode = *mode;
            out.layout.resolution = o.at("resolution").get<int>();
            out.layout.texelDensity = o.at("texel_density").get<float>();
            out.layout.padding = o.at("padding_texels").get<int>();
            if (o.contains("uv_charts")) {
                const auto& c = o.at("uv_charts");
                out.layout.charts.hardAngleDegrees = c.at("hard_angle_degrees").get<float>();
                out.layout.charts.coneAngleDegrees = c.at("cone_angle_degrees").get<float>();
                out.layout.charts.maxChartTriangles = c.at("max_chart_triangles").get<int>();
            }
            out.layoutRecorded = true;
        } else {
            auto mode = modeOf(m.at("layout").get<std::string>());
            if (!mode) return mode.status();
            out.layout.mode = *mode;
            out.layout.resolution = m.at("resolution").get<int>();
            out.layout.padding = m.value("padding_texels", out.layout.padding);
        }
        return out;
    } catch (const nlohmann::json::exception& e) {
        return Fail::failure(path + ": missing or malformed field (" + std::string(e.what()) + ")");
    }
}

std::string lightmapFileName(int page, const char* extension) {
    char name[64];
    std::snprintf(name, sizeof name, "lightmap_%d.%s", page, extension);
    return name;
}

std::string coverageFileName(int page) {
    char name[64];
    std::snprintf(name, sizeof name, "coverage_%d.png", page);
    return name;
}

double exrRoundingError(const LightmapPages& maps) {
    double squares = 0.0, sum = 0.0;
    int64_t n = 0;
    for (size_t p = 0; p < std::min(maps.pages.size(), maps.covered.size()); ++p) {
        const bool asFloat = io::exrWritesFloat(maps.pages[p]);
        for (size_t t = 0; t < maps.pages[p].pixels.size(); ++t) {
            if (!maps.covered[p][t]) continue;
            for (int c = 0; c < 3; ++c) {
                const float v = maps.pages[p].pixels[t][c];
                const double d = double(io::exrStoredValue(v, asFloat)) - double(v);
                squares += d * d;
                sum += v;
                ++n;
            }
        }
    }
    return n > 0 && sum > 0.0 ? std::sqrt(squares / double(n)) / (sum / double(n)) : 0.0;
}

Status writeBakeOutputs(const std::string& outDir, const Scene& scene, const Layout& layout, const LightmapPages& maps,
                        nlohmann::json stats, const BakeOutputInfo& info) {
    if (Status s = io::ensureDirectory(outDir); !s) return s;
    const std::string units = "L_lm = E/pi (irradiance over pi), scene radiance units; row 0 = v 0 (glTF: v down from the top)";
    const float exposure = autoExposure(maps);
    nlohmann::json pages = nlohmann::json::array();
    for (size_t p = 0; p < maps.pages.size(); ++p) {
        std::string exr = lightmapFileName(int(p));
        if (Status s = io::writeExr(outDir + "/" + exr, maps.pages[p], {{"bundlebake:units", units}}); !s) return s;
        nlohmann::json page = {{"page", p}, {"exr", exr}};
        if (p < maps.covered.size()) {
            io::ImageRgb mask;
            mask.width = maps.pages[p].width;
            mask.height = maps.pages[p].height;
            mask.pixels.resize(maps.covered[p].size());
            for (size_t i = 0; i < mask.pixels.size(); ++i) mask.pixels[i] = glm::vec3(maps.covered[p][i] ? 1.0f : 0.0f);
            std::string png = coverageFileName(int(p));
            if (Status s = io::writePng(outDir + "/" + png, mask, false); !s) return s;
            page["coverage_png"] = png;
        }
        if (info.writePreviews) {
            std::string png = lightmapFileName(int(p), "png");
            if (Status s = io::writePngToneMapped(outDir + "/" + png, maps.pages[p], exposure); !s) return s;
            page["preview_png"] = png;
            page["preview_exposure_stops"] = exposure;
        }
        pages.push_back(page);
    }
    nlohmann::json instances = nlohmann::json::array();
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const auto& r = layout.rects[i];
        instances.push_back({{"name", scene.instances[i].name}, {"node", scene.instances[i].node},
                             {"mesh", scene.instances[i].mesh}, {"page", r.page},
                             {"rect_texels", {r.x, r.y, r.width, r.height}},
                             {"uv1_scale", {r.scale.x, r.scale.y}}, {"uv1_offset", {r.offset.x, r.offset.y}},
                             {"texel_density", r.texelDensity}});
    }
    nlohmann::json manifest = {
        {"generator", info.generator},
        {"scene", scene.path},
        {"units", units},
        {"mapping", "page_uv = TEXCOORD_1 * uv1_scale + uv1_offset"},
        {"layout", layoutModeName(layout.mode)},
        {"layout_options", layoutRequest(layout, info.settings)},
        {"resolution", layout.resolution},
        {"padding_texels", layout.padding},
        {"texel_density", layout.texelDensity},
        {"pages", pages},
        {"instances", instances},
    };
    if (Status s = io::writeJson(outDir + "/manifest.json", manifest); !s) return s;

    stats["backend"] = info.backend;
    stats["renderer"] = info.renderer;
    stats["settings"] = info.settings;
    stats["wall_seconds"] = info.wallSeconds;
    stats["scene"] = {{"path", scene.path}, {"triangles", scene.triangleCount()},
                      {"instances", scene.instances.size()}, {"lights", scene.lights.size()}};
    return io::writeJson(outDir + "/stats.json", stats);
}

}  // namespace bb
