// `bundlebake export SCENE BAKE_DIR -o baked.glb`: the scene with its light
// map UVs as baked and the light maps (RGBM PNG embedded, EXR beside), for
// engines and glTF viewers (engine/export/gltf_export.h). GL-free.
#include <cstdio>

#include "core/log.h"
#include "export/gltf_export.h"
#include "headless/cli/options.h"
#include "render/scene_renderer.h"

namespace bb::cli {

struct ExportArgs {
    SceneArgs scene;
    LayoutFlagsGiven given;
    std::string bakeDir;
    std::string output;
};

int runExport(const ExportArgs& args);

void addExportCommand(CLI::App& app, std::function<int()>& action) {
    auto a = std::make_shared<ExportArgs>();
    CLI::App* cmd = app.add_subcommand(
        "export", "Write the scene with its baked light maps as a .glb (TEXCOORD_1 as baked, RGBM PNG pages embedded, "
                  "EXR pages beside it, the encoding under extras)");
    addSceneOptions(*cmd, a->scene);
    cmd->add_option("bake", a->bakeDir, "Directory written by `bundlebake bake` (its manifest.json gives the layout)")
        ->required();
    cmd->add_option("-o,--output", a->output, "The .glb to write (<stem>.lightmap_<page>.exr are written beside it)")
        ->required();
    cmd->callback([a, cmd, &action] {
        a->given = layoutFlagsGiven(*cmd);
        action = [a] { return runExport(*a); };
    });
}

int runExport(const ExportArgs& args) {
    if (args.output.size() < 4 || args.output.substr(args.output.size() - 4) != ".glb")
        return fail("-o " + args.output + ": export writes a binary glTF, name it <name>.glb");
    auto loaded = loadSceneWithBakeLayout(args.scene, args.given, args.bakeDir);
    if (!loaded) return fail(loaded.error());
    auto maps = readBakedLightmaps(args.bakeDir, loaded->layout);
    if (!maps) return fail(maps.error());
    auto report = exportBakedGltf(args.scene.scene, loaded->scene, loaded->layout, *maps, args.output);
    if (!report) return fail(report.error());
    for (const std::string& w : report->warnings) logWarning("export: " + w);
    char line[256];
    std::snprintf(line, sizeof line, "exported %zu node(s), %zu mesh(es) (geometry of %zu), %zu page(s) (RGBM, range %g), "
                  "%.1f MiB -> ",
                  report->nodes, report->meshes, report->sharedGeometry, report->pageScale.size(), double(RGBM_RANGE),
                  double(report->bytes) / (1024.0 * 1024.0));
    logInfo(line + args.output);
    return 0;
}

}  // namespace bb::cli
