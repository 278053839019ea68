// Writes a bake's outputs into a directory, each file atomically (temp name,
// then rename): lightmap_<page>.exr (half RGB, L_lm = E/pi), manifest.json
// (pages, instances with scale/offset, units), stats.json (BakeStats plus the
// run's settings) and, optionally, lightmap_<page>.png tone-mapped previews.
// Shared by the CLI and the viewer.
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
};

Status writeBakeOutputs(const std::string& outDir, const Scene& scene, const Layout& layout, Baker& baker,
                        const BakeOutputInfo& info);

// Page file name: "lightmap_<page>.exr".
std::string lightmapFileName(int page, const char* extension = "exr");

}  // namespace bb
