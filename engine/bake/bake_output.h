// Writes a bake's outputs into a directory, each file atomically (temp name,
// then rename): lightmap_<page>.exr (half RGB, L_lm = E/pi), coverage_<page>.png
// (8-bit mask: 255 where LightmapPages::covered, 0 in padding and empty texels;
// `bundlebake compare` reads it), manifest.json (pages, instances with
// scale/offset, units), stats.json (the baker's figures plus the run's
// settings) and, optionally, lightmap_<page>.png tone-mapped previews.
// Shared by the CLI (bake, reference) and the viewer.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "bake/baker.h"
#include "core/status.h"

namespace bb {

struct BakeOutputInfo {
    std::string backend;            // "egl", "osmesa", "glfw"
    std::string renderer;           // GL_RENDERER
    nlohmann::json settings;        // the flags of the run, echoed into stats.json
    double wallSeconds = 0;         // bake loop wall time
    bool writePreviews = true;
    std::string generator = "bundlebake";  // manifest.json "generator" (e.g. "bundlebake reference")
};

// `maps`: Baker::readLightmaps() or ReferenceBaker::readLightmaps(); `stats`: the
// baker's figures (BakeStats::toJson(), ReferenceStats::toJson()), written to
// stats.json with the run's info added.
Status writeBakeOutputs(const std::string& outDir, const Scene& scene, const Layout& layout, const LightmapPages& maps,
                        nlohmann::json stats, const BakeOutputInfo& info);

// The light maps' error from being written as half floats (writeExr): the
// RMS of (stored - value) over the covered texels and the 3 channels, over
// their mean (rel_rmse's measure). Exact, not an estimate: a part of the
// written maps' error that the bake's own estimates do not hold (the rho 0.5
// furnace's values sit just under 2, where half's step is 0.049 %).
double exrRoundingError(const LightmapPages& maps);

// Coverage mask file name: "coverage_<page>.png".
std::string coverageFileName(int page);

// Page file name: "lightmap_<page>.exr".
std::string lightmapFileName(int page, const char* extension = "exr");

// The layout a bake directory's manifest.json records: the request that
// recomputes it exactly (computeLayout is deterministic, generated TEXCOORD_1
// included), so `render`, `export` and the viewer's --open need no flags.
// manifest.json "layout_options": {"uv_layout", "resolution", "texel_density"
// (as requested: 0 = auto), "padding_texels", "uv_charts": {...}}; the
// density, rectangles and pages that came out are recorded beside it.
struct BakeManifest {
    std::string scene;             // the scene path as the bake was given it
    std::string generator;         // "bundlebake", "bundlebake reference"
    LayoutOptions layout;          // mode, resolution, requested density, padding, chart options
    // false: a manifest written before "layout_options" (mode and resolution
    // come from its "layout" and "resolution"; a generate bake reads as pack
    // and the requested density is unknown, so layout.texelDensity is 0).
    bool layoutRecorded = false;
    int pageCount = 0;
    size_t instanceCount = 0;
};

// Reads DIR/manifest.json. Errors (one line naming the file): missing,
// not JSON, or without the fields above.
Expected<BakeManifest> readBakeManifest(const std::string& dir);

// "asset", "pack", "generate".
const char* layoutModeName(UvLayout mode);

}  // namespace bb
