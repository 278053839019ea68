// `bundlebake render`: the scene with light maps baked earlier (OUTDIR of
// `bundlebake bake`), drawn offscreen on a headless context by the viewer's
// renderer (engine/render/scene_renderer.h) into an sRGB PNG.
#include <cmath>
#include <cstdio>
#include <optional>

#include "core/log.h"
#include "export/gltf_export.h"
#include "headless/cli/options.h"
#include "headless/platform.h"
#include "layout/bake_mesh.h"
#include "render/scene_renderer.h"
#if __has_include("importance/importance.h")
#include "importance/importance.h"
#define BUNDLEBAKE_RENDER_IMPORTANCE 1
#endif

namespace bb::cli {

struct RenderArgs {
    SceneArgs scene;
    LayoutFlagsGiven given;
    std::string lightmapDir;             // empty: SCENE is a `bundlebake export` file with its own light maps
    std::string output;
    std::string backend = "egl";
    int camera = -2;             // -2 = camera 0 if the scene has one, else -1 (frame the scene)
    int width = 1024;
    int height = 0;              // 0 = from the camera's aspect ratio (4:3 without one)
    std::string exposure = "auto";
    std::string view = "lit";
};

int runRender(const RenderArgs& args);

void addRenderCommand(CLI::App& app, std::function<int()>& action) {
    auto a = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand(
        "render", "Render the scene with baked light maps (a `bake` OUTDIR, whose manifest.json gives the layout; or "
                  "a .glb written by `bundlebake export` alone) to a PNG");
    addSceneOptions(*cmd, a->scene);
    cmd->add_option("lightmaps", a->lightmapDir,
                    "Directory written by `bundlebake bake` (manifest.json, lightmap_<p>.exr); leave it out for a "
                    "`bundlebake export` file, which carries its light maps");
    cmd->add_option("-o,--output", a->output, "PNG to write (sRGB)")->required();
    cmd->add_option("--camera", a->camera, "glTF camera index; -1 frames the scene (default: camera 0 if any, else -1)")
        ->check(CLI::Range(-1, 1 << 20));
    cmd->add_option("--width", a->width, "Image width in pixels")->check(CLI::Range(1, 16384))->capture_default_str();
    cmd->add_option("--height", a->height, "Image height in pixels (0 = from the camera's aspect ratio, else 4:3)")
        ->check(CLI::Range(0, 16384))
        ->capture_default_str();
    cmd->add_option("--exposure", a->exposure,
                    "Stops before the tone curve (ACES fit + sRGB, as the PNG previews), or auto (the previews' rule)")
        ->capture_default_str();
    cmd->add_option("--view", a->view,
                    "lit, lightmap, albedo, density (light map texel checkerboard) or importance (per-triangle, CPU)")
        ->check(CLI::IsMember({"lit", "lightmap", "albedo", "density", "importance"}))
        ->capture_default_str();
    cmd->add_option("--backend", a->backend, "Headless GL: egl (surfaceless) or osmesa")
        ->check(CLI::IsMember({"egl", "osmesa"}))
        ->capture_default_str();
    cmd->callback([a, cmd, &action] {
        a->given = layoutFlagsGiven(*cmd);
        action = [a] { return runRender(*a); };
    });
}

int runRender(const RenderArgs& args) {
    auto backend = parseBackend(args.backend);
    if (!backend) return fail(backend.error());
    auto mode = parseViewMode(args.view);
    if (!mode) return fail("--view: " + mode.error());
    bool autoExposed = args.exposure == "auto";
    float exposure = 0.0f;
    if (!autoExposed) {
        char* end = nullptr;
        exposure = std::strtof(args.exposure.c_str(), &end);
        if (end == args.exposure.c_str() || *end != '\0' || !std::isfinite(exposure) || std::abs(exposure) > 64.0f)
            return fail("--exposure: '" + args.exposure + "' is not a number of stops in [-64, 64] or auto");
    }
    // the layout and light maps: the bake's manifest.json, or the export's extras
    std::optional<LoadedScene> loadedScene;
    std::optional<LightmapPages> lightmaps;
    std::string source = args.lightmapDir;
    std::optional<float> recordedExposure;
    if (!args.lightmapDir.empty()) {
        auto loaded = loadSceneWithBakeLayout(args.scene, args.given, args.lightmapDir);
        if (!loaded) return fail(loaded.error());
        auto maps = readBakedLightmaps(args.lightmapDir, loaded->layout);
        if (!maps) return fail(maps.error());
        loadedScene = std::move(loaded.value());
        lightmaps = std::move(maps.value());
    } else {
        if (args.given.uvLayout || args.given.resolution || args.given.texelDensity)
            return fail("the layout flags apply to a bake directory; an exported file's TEXCOORD_1 is its layout");
        auto scene = loadSceneFromArgs(args.scene);
        if (!scene) return fail(scene.error());
        auto exported = readExportedLightmaps(args.scene.scene, *scene);
        if (!exported) return fail(exported.error());
        source = args.scene.scene + " (" + exported->source + ")";
        recordedExposure = exported->autoExposureStops;
        loadedScene = LoadedScene{std::move(scene.value()), std::move(exported->layout)};
        lightmaps = std::move(exported->maps);
    }
    const LoadedScene* loaded = &*loadedScene;
    const LightmapPages* maps = &*lightmaps;
    const Scene& scene = loaded->scene;
    int cameraIndex = args.camera == -2 ? (scene.cameras.empty() ? -1 : 0) : args.camera;
    if (cameraIndex >= int(scene.cameras.size()))
        return fail("--camera " + std::to_string(cameraIndex) + ": the scene has " + std::to_string(scene.cameras.size()) +
                    " camera(s)" + (scene.cameras.empty() ? " (use -1 to frame the scene)" : ""));

    // image size: the camera's aspect ratio when the height is not given
    float cameraAspect = cameraIndex >= 0 ? scene.cameras[size_t(cameraIndex)].aspect : 0.0f;
    int width = args.width;
    int height = args.height > 0 ? args.height
                                 : std::max(1, int(std::lround(width / (cameraAspect > 0 ? cameraAspect : 4.0f / 3.0f))));
    const float aspect = float(width) / float(height);

    auto context = createHeadlessContext(*backend);
    if (!context) return fail(context.error());
    const gl::Caps& caps = context.value()->caps();
    if (width > caps.maxFramebufferWidth || height > caps.maxFramebufferHeight)
        return fail("image " + std::to_string(width) + "x" + std::to_string(height) + " exceeds the GL framebuffer limit " +
                    std::to_string(caps.maxFramebufferWidth) + "x" + std::to_string(caps.maxFramebufferHeight));
    const BakeMesh mesh = buildBakeMesh(scene, loaded->layout);
    auto renderer = SceneRenderer::create(scene, mesh, loaded->layout.resolution);
    if (!renderer) return fail(renderer.error());
    (*renderer)->uploadLightmaps(*maps);
    if (*mode == ViewMode::Importance) {
#ifdef BUNDLEBAKE_RENDER_IMPORTANCE
        const Importance importance = computeImportance(mesh, loaded->layout.resolution);
        if (Status s = (*renderer)->setImportance(importance.importance); !s) return fail(s.message());
#else
        return fail("--view importance: this build has no importance analysis");
#endif
    }

    // the mesh is in local space (world - mesh.origin): so is the camera
    Camera camera = cameraIndex >= 0 ? cameraInLocalSpace(scene.cameras[size_t(cameraIndex)], mesh.origin)
                                     : framingCamera(mesh.bounds, DEFAULT_FRAMING_DIRECTION, 0.8f, aspect);
    RenderSettings settings;
    settings.mode = *mode;
    settings.exposure = !autoExposed ? exposure : recordedExposure ? *recordedExposure : autoExposure(*maps);
    Image8 image = (*renderer)->renderImage(viewFromCamera(camera, aspect, mesh.bounds), settings, width, height);
    if (Status s = writeImagePng(args.output, image); !s) return fail(s.message());
    char line[256];
    std::snprintf(line, sizeof line, "rendered %dx%d from %s, exposure %+.2f stops (%s), light maps of ", width, height,
                  cameraIndex >= 0 ? ("camera " + std::to_string(cameraIndex)).c_str() : "a framing camera",
                  settings.exposure, autoExposed ? "auto" : "given");
    logInfo(line + source + " -> " + args.output);
    return 0;
}

}  // namespace bb::cli
