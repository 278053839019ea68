// A glTF asset placed elsewhere in the world by node translations: the
// asset's scene roots become children of an `inner` node, itself the child of
// an `outer` node, the new scene's only root:
//
//   world = translate(outer) * translate(inner) * (the asset's own transforms)
//
// Written as a .gltf next to copies of the asset's buffers, in a directory of
// its own under the system temp directory. Header-only, for tests (GL-free).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scratch_dirs.h"

namespace bb::test {

// `sourceFile` is the asset's .gltf path. Returns the written file's path, or
// "" (with `error` set) on failure. `tag` names the directory (one per call
// site keeps parallel tests apart).
inline std::string writeTranslatedGltf(const std::string& sourceFile, const glm::dvec3& outer,
                                       const glm::dvec3& inner, const std::string& tag, std::string* error) {
    namespace fs = std::filesystem;
    const fs::path source = sourceFile;
    std::ifstream in(source);
    if (!in) {
        *error = "cannot read " + source.string();
        return "";
    }
    nlohmann::json gltf = nlohmann::json::parse(in, nullptr, false);
    if (gltf.is_discarded() || !gltf.contains("scenes") || !gltf.contains("nodes")) {
        *error = source.string() + " is not a glTF with scenes and nodes";
        return "";
    }
    const fs::path dir = removeAtExit(fs::temp_directory_path() / ("bundlebake_" + tag + "_" + std::to_string(getpid())));
    std::error_code ec;
    fs::create_directories(dir, ec);
    // external buffers: copied next to the new file (relative URIs keep working)
    if (gltf.contains("buffers"))
        for (const auto& buffer : gltf["buffers"]) {
            if (!buffer.contains("uri")) continue;
            const std::string uri = buffer["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) continue;
            fs::copy_file(source.parent_path() / uri, dir / uri, fs::copy_options::overwrite_existing, ec);
            if (ec) {
                *error = "cannot copy " + uri + ": " + ec.message();
                return "";
            }
        }
    const int sceneIndex = gltf.value("scene", 0);
    auto& scene = gltf["scenes"][size_t(sceneIndex)];
    const nlohmann::json roots = scene["nodes"];
    auto& nodes = gltf["nodes"];
    const int innerIndex = int(nodes.size());
    nodes.push_back({{"name", "inner"}, {"translation", {inner.x, inner.y, inner.z}}, {"children", roots}});
    nodes.push_back({{"name", "outer"}, {"translation", {outer.x, outer.y, outer.z}}, {"children", {innerIndex}}});
    scene["nodes"] = nlohmann::json::array({innerIndex + 1});
    gltf["scene"] = sceneIndex;

    const fs::path out = dir / source.filename();
    std::ofstream file(out);
    file << gltf.dump(1);
    if (!file) {
        *error = "cannot write " + out.string();
        return "";
    }
    return out.string();
}

}  // namespace bb::test
