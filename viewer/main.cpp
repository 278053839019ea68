// bundlebake-viewer: watch the light maps converge while the bake runs in the
// same GL context. Each frame bakes directions for up to a frame budget
// (Baker::stepTiles, default 30 ms: at least one tile per frame), resolves the
// light maps on the GPU (Baker::resolveLightmaps) and draws the scene with
// them (engine/render/scene_renderer.h), then a Dear ImGui panel.
//
// --open BAKE_DIR shows a finished bake instead (its manifest.json gives the
// layout, its EXR pages the light maps): nothing is baked.
//
// Scripted use: --screenshot FILE --frames N renders N frames while baking,
// writes the scene view (without the panel) and exits 0. At exit the log
// gives the frame time (mean, p95, max) of the frames that baked.
#define GLFW_INCLUDE_NONE  // GL comes from glad (engine/gl/gl.h)
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_stdlib.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "bake/bake_output.h"
#include "bake/baker.h"
#include "bake/seam_stitch.h"
#include "core/timer.h"
#include "core/log.h"
#include "core/memory.h"
#include "gl/gl.h"
#include "headless/cli/options.h"
#include "render/scene_renderer.h"
#include "viewer/glfw_context.h"

#if __has_include("importance/importance.h")
#include "importance/importance.h"
#define BUNDLEBAKE_VIEWER_IMPORTANCE 1
#endif

namespace bb::viewer {
namespace {


struct ViewerArgs {
    cli::SceneArgs scene;
    // lighting and bake flags, as `bundlebake bake`
    int directions = 256;
    int bundleRes = 0;
    std::string memoryBudget = "4G";
    uint64_t seed = 1;
    std::string sky = "0,0,0";
    std::string env;
    std::string rounding = "stochastic";
    float historyPower = -1.0f;
    int historyPlateau = 0;
    std::string supersample = "auto";  // auto | 1 | 2 | 4, as the bake command's
    // viewer
    int width = 1280, height = 720;
    double frameBudgetMs = 30.0;
    int camera = -1;
    std::string view = "lit";
    std::string exposure = "auto";
    bool tiles = false;
    std::string screenshot;
    bool screenshotPanel = false;
    bool saveAtExit = false;
    int frames = 0;
    std::string output = "viewer_out";
    std::string open;            // a bake directory to show instead of baking
    cli::LayoutFlagsGiven given;
};

// --- camera: orbit about a target or fly from the eye ----------------------------
struct ViewCamera {
    glm::vec3 target{0.0f};
    float yaw = 0.0f, pitch = 0.0f;  // radians; (0, 0) looks down -Z
    float distance = 1.0f;            // eye = target - forward * distance
    float yfov = 0.8f;
    bool fly = false;                 // mouse looks around the eye (fly) or orbits the target

    glm::vec3 forward() const {
        return {std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw)};
    }
    glm::vec3 right() const { return glm::normalize(glm::cross(forward(), glm::vec3(0, 1, 0))); }
    glm::vec3 eye() const { return target - forward() * distance; }
    void setForward(const glm::vec3& f) {
        glm::vec3 n = glm::normalize(f);
        pitch = std::asin(std::clamp(n.y, -1.0f, 1.0f));
        yaw = std::atan2(n.x, -n.z);
    }
    void rotate(float dYaw, float dPitch) {
        const glm::vec3 e = eye();
        yaw += dYaw;
        pitch = std::clamp(pitch + dPitch, -1.55f, 1.55f);
        if (fly) target = e + forward() * distance;  // keep the eye where it is
    }
    Camera toCamera(float sceneRadius) const {
        Camera c;
        c.name = "viewer";
        const glm::vec3 e = eye();
        const glm::vec3 f = forward();
        const glm::vec3 up = std::abs(f.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
        c.worldFromCamera = glm::inverse(glm::lookAt(e, e + f, up));
        c.yfov = yfov;
        c.znear = std::max(sceneRadius * 1e-4f, std::min(distance * 0.05f, sceneRadius * 0.05f));
        c.zfar = 0.0f;  // from the bounds
        return c;
    }
};

void frameScene(ViewCamera& cam, const Bounds& bounds, float aspect) {
    Camera framed = framingCamera(bounds, cam.forward(), cam.yfov, aspect);
    cam.target = bounds.center();
    cam.distance = glm::length(glm::vec3(framed.worldFromCamera[3]) - cam.target);
}

void useSceneCamera(ViewCamera& cam, const Camera& c, const Bounds& bounds) {
    const glm::vec3 eye(c.worldFromCamera[3]);
    cam.setForward(-glm::vec3(c.worldFromCamera[2]));
    if (c.perspective && c.yfov > 0) cam.yfov = c.yfov;
    // orbit about the point of the view ray nearest the scene centre
    const float radius = std::max(0.5f * glm::length(bounds.size()), 1e-4f);
    cam.distance = std::max(glm::dot(bounds.center() - eye, cam.forward()), 0.1f * radius);
    cam.target = eye + cam.forward() * cam.distance;
}

// --- frame time statistics ----------------------------------------------------
struct FrameTimes {
    std::vector<double> seconds;
    void add(double s) { seconds.push_back(s); }
    std::string describe() const {
        if (seconds.empty()) return "no frames";
        std::vector<double> sorted = seconds;
        std::sort(sorted.begin(), sorted.end());
        double mean = 0;
        for (double s : sorted) mean += s;
        mean /= double(sorted.size());
        const double p95 = sorted[std::min(sorted.size() - 1, size_t(std::ceil(0.95 * double(sorted.size()))) - 1)];
        char line[160];
        std::snprintf(line, sizeof line, "%zu frames, mean %.1f ms, p95 %.1f ms, max %.1f ms", sorted.size(),
                      mean * 1e3, p95 * 1e3, sorted.back() * 1e3);
        return line;
    }
};

std::string megabytes(int64_t bytes) {
    char s[32];
    std::snprintf(s, sizeof s, "%.1f MiB", double(bytes) / (1024.0 * 1024.0));
    return s;
}

std::string duration(double seconds) {
    char s[32];
    if (!std::isfinite(seconds)) return "-";
    if (seconds < 60) std::snprintf(s, sizeof s, "%.0f s", seconds);
    else std::snprintf(s, sizeof s, "%dm%02ds", int(seconds) / 60, int(seconds) % 60);
    return s;
}

class Viewer {
public:
    Viewer(ViewerArgs args, cli::LoadedScene loaded, BakeOptions options, std::unique_ptr<GlfwContext> context,
           std::optional<LightmapPages> opened = std::nullopt)
        : args_(std::move(args)), loaded_(std::move(loaded)), options_(std::move(options)), context_(std::move(context)),
          opened_(std::move(opened)) {}

    int run();

private:
    Status startBake();
    Status showOpened();  // --open: the bake's light maps, no Baker
    const BakeMesh& mesh() const { return baker_ ? baker_->mesh() : *openedMesh_; }
    void bakeStep();
    void handleInput(double dt);
    void drawPanel();
    void updateAutoExposure(bool force);
    Status saveScreenshot(const std::string& path);
    Status saveWindow(const std::string& path, int width, int height);
    Status saveLightmaps(const std::string& dir);
    RenderView currentView(int width, int height) const;
    void logFrameTimes() const;

    ViewerArgs args_;
    cli::LoadedScene loaded_;
    BakeOptions options_;
    std::unique_ptr<GlfwContext> context_;  // declared before the GL objects: destroyed after them
    std::unique_ptr<Baker> baker_;
    std::optional<LightmapPages> opened_;  // --open: the pages read from the bake directory
    std::optional<BakeMesh> openedMesh_;
    std::unique_ptr<SceneRenderer> renderer_;
    float sceneRadius_ = 1.0f;

    ViewCamera camera_;
    int cameraChoice_ = -1;   // -1 free, else a glTF camera (until moved)
    RenderSettings settings_;
    bool autoExposure_ = true;
    double lastExposureUpdate_ = -1e9;

    bool paused_ = false;
    double frameBudgetMs_ = 30.0;
    double tileSeconds_ = 0.0;     // running mean of one tile's bake time (bundle + update)
    std::deque<std::pair<double, int>> rateWindow_;  // (time, directions done) over the last seconds
    double directionsPerSecond_ = 0.0;
    double bakeSeconds_ = 0.0;           // wall time spent in Baker::step
    Clock::time_point bakeStart_;
    double bakeDoneAt_ = -1.0;

    FrameTimes bakingFrames_, idleFrames_;
    FrameTimes bakeParts_, drawParts_;  // per baking frame: Baker::step + resolve, scene + panel + swap
    std::deque<double> recentFrames_;
    std::string outputDir_, screenshotPath_ = "screenshot.png", message_;
    double lastMouseX_ = 0, lastMouseY_ = 0;
    bool dragging_ = false;
};

Status Viewer::startBake() {
    if (renderer_) renderer_->useLightmapTexture(0);  // the old bake's texture goes with it
    baker_.reset();  // free the previous bake's GPU memory first
    auto t0 = Clock::now();
    auto baker = Baker::create(loaded_.scene, loaded_.layout, options_);
    if (!baker) return baker.status();
    baker_ = std::move(baker.value());
    if (!renderer_) {  // kept across restarts: same mesh, textures uploaded once
        auto renderer = SceneRenderer::create(loaded_.scene, mesh(), loaded_.layout.resolution);
        if (!renderer) return renderer.status();
        renderer_ = std::move(renderer.value());
    }
    baker_->resolveLightmaps();
    renderer_->useLightmapTexture(baker_->lightmapTextureId());
    renderer_->setBundleGrid(baker_->bundleGrid());
    rateWindow_.clear();
    directionsPerSecond_ = 0;
    tileSeconds_ = 0;
    bakeSeconds_ = 0;
    bakeDoneAt_ = -1;
    bakeStart_ = Clock::now();
    lastExposureUpdate_ = -1e9;
    logInfo("bake set up in " + std::to_string(secondsSince(t0)) + " s: " + std::to_string(mesh().triangleCount()) +
            " triangles, " + std::to_string(loaded_.layout.pageCount) + " page(s) of " +
            std::to_string(loaded_.layout.resolution) + "^2 texels, " + std::to_string(options_.directions) + " directions");
    return Status::ok();
}

Status Viewer::showOpened() {
    openedMesh_ = buildBakeMesh(loaded_.scene, loaded_.layout);
    auto renderer = SceneRenderer::create(loaded_.scene, *openedMesh_, loaded_.layout.resolution);
    if (!renderer) return renderer.status();
    renderer_ = std::move(renderer.value());
    renderer_->uploadLightmaps(*opened_);
    logInfo("showing the bake in " + args_.open + ": " + std::to_string(openedMesh_->triangleCount()) + " triangles, " +
            std::to_string(loaded_.layout.pageCount) + " page(s) of " + std::to_string(loaded_.layout.resolution) +
            "^2 texels (" + cli::uvLayoutName(loaded_.layout.mode) + " layout from its manifest.json)");
    return Status::ok();
}

void Viewer::bakeStep() {
    if (!baker_ || paused_ || baker_->progress().done()) return;
    // tile by tile: budget minus one tile's expected time, so the last one ends near the budget
    // (a direction of a large scene takes seconds; one of its tiles a few milliseconds)
    const double budget = frameBudgetMs_ * 1e-3;
    const double stepBudget = std::max(0.0, budget - tileSeconds_);
    const int64_t before = baker_->stats().tilesDrawn;
    auto t0 = Clock::now();
    BakeProgress p = baker_->stepTiles(stepBudget);
    baker_->resolveLightmaps();
    const double spent = secondsSince(t0);
    bakeSeconds_ += spent;
    const int64_t stepped = baker_->stats().tilesDrawn - before;
    if (stepped > 0) {
        const double perTile = spent / double(stepped);
        tileSeconds_ = tileSeconds_ > 0 ? 0.8 * tileSeconds_ + 0.2 * perTile : perTile;
    }
    renderer_->setBundleGrid(baker_->bundleGrid());
    if (p.done()) {
        bakeDoneAt_ = secondsSince(bakeStart_);
        logInfo("bake done: " + std::to_string(p.directionsTotal) + " directions in " + duration(bakeDoneAt_) + " (" +
                std::to_string(bakeSeconds_) + " s in Baker::step)");
    }
}

RenderView Viewer::currentView(int width, int height) const {
    const float aspect = float(width) / float(std::max(height, 1));
    return viewFromCamera(camera_.toCamera(sceneRadius_), aspect, mesh().bounds);
}

void Viewer::updateAutoExposure(bool force) {
    const double now = glfwGetTime();
    if (!autoExposure_ || !renderer_ || (!force && now - lastExposureUpdate_ < 1.0)) return;
    lastExposureUpdate_ = now;
    LightmapPages maps = renderer_->readLightmaps();
    if (!maps.pages.empty()) settings_.exposure = autoExposure(maps);
}

Status Viewer::saveScreenshot(const std::string& path) {
    int width = 0, height = 0;
    glfwGetFramebufferSize(context_->window(), &width, &height);
    if (width <= 0 || height <= 0) return Status::error("the window has no area");
    Image8 image = renderer_->renderImage(currentView(width, height), settings_, width, height);
    return writeImagePng(path, image);
}

// The back buffer as drawn (scene and panel), before the swap.
Status Viewer::saveWindow(const std::string& path, int width, int height) {
    std::vector<uint8_t> rgba(size_t(width) * height * 4);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    Image8 image;
    image.width = width;
    image.height = height;
    image.rgb.resize(size_t(width) * height * 3);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
                image.rgb[(size_t(y) * width + x) * 3 + c] = rgba[(size_t(height - 1 - y) * width + x) * 4 + c];
    return writeImagePng(path, image);
}

Status Viewer::saveLightmaps(const std::string& dir) {
    BakeOutputInfo info;
    info.backend = "glfw";
    info.renderer = context_->caps().renderer;
    info.settings = {{"directions", options_.directions}, {"directions_done", baker_->progress().directionsDone},
                     {"bundle_res", args_.bundleRes}, {"memory_budget", args_.memoryBudget}, {"seed", args_.seed},
                     {"sky", args_.sky}, {"env", args_.env}, {"rounding", args_.rounding},
                     {"uv_layout", args_.scene.uvLayout}, {"resolution", args_.scene.resolution},
                     {"texel_density", args_.scene.texelDensity}, {"history_power", baker_->stats().historyPower},
                     {"history_plateau", baker_->stats().historyPlateau}, {"supersample", args_.supersample},
                     {"seams", "stitch"}};
    info.wallSeconds = bakeSeconds_;
    // as `bundlebake bake` writes them: the seams stitched (its default)
    LightmapPages maps = baker_->readLightmaps();
    nlohmann::json stats = baker_->stats().toJson();
    stats["seams"] = stitchSeams(maps, findSeams(baker_->mesh(), maps.resolution)).toJson();
    return writeBakeOutputs(dir, loaded_.scene, loaded_.layout, maps, stats, info);
}

void Viewer::handleInput(double dt) {
    GLFWwindow* w = context_->window();
    ImGuiIO& io = ImGui::GetIO();
    double mx = 0, my = 0;
    glfwGetCursorPos(w, &mx, &my);
    const double dx = mx - lastMouseX_, dy = my - lastMouseY_;
    lastMouseX_ = mx;
    lastMouseY_ = my;
    bool moved = false;
    if (!io.WantCaptureMouse) {
        const bool left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
        const bool right = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
        const bool middle = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
        if (dragging_ && left && (dx != 0 || dy != 0)) {
            camera_.rotate(float(dx) * 0.005f, float(-dy) * 0.005f);
            moved = true;
        }
        if (dragging_ && (right || middle) && (dx != 0 || dy != 0)) {  // pan in the view plane
            const glm::vec3 up = glm::cross(camera_.right(), camera_.forward());
            const float scale = camera_.distance * 0.0015f;
            camera_.target += (-float(dx) * camera_.right() + float(dy) * up) * scale;
            moved = true;
        }
        dragging_ = left || right || middle;
        if (io.MouseWheel != 0.0f) {
            if (camera_.fly)
                camera_.target += camera_.forward() * (io.MouseWheel * 0.1f * sceneRadius_);
            else
                camera_.distance = std::max(camera_.distance * std::pow(0.88f, io.MouseWheel), sceneRadius_ * 1e-3f);
            moved = true;
        }
    } else {
        dragging_ = false;
    }
    if (!io.WantCaptureKeyboard) {
        auto down = [&](int key) { return glfwGetKey(w, key) == GLFW_PRESS; };
        glm::vec3 move(0.0f);
        if (down(GLFW_KEY_W)) move += camera_.forward();
        if (down(GLFW_KEY_S)) move -= camera_.forward();
        if (down(GLFW_KEY_D)) move += camera_.right();
        if (down(GLFW_KEY_A)) move -= camera_.right();
        if (down(GLFW_KEY_E)) move += glm::vec3(0, 1, 0);
        if (down(GLFW_KEY_Q)) move -= glm::vec3(0, 1, 0);
        if (move != glm::vec3(0.0f)) {
            const float speed = sceneRadius_ * 0.6f * (down(GLFW_KEY_LEFT_SHIFT) ? 4.0f : 1.0f);
            camera_.target += glm::normalize(move) * speed * float(std::min(dt, 0.1));
            moved = true;
        }
        if (ImGui::IsKeyPressed(GLFW_KEY_F)) {
            int width = 0, height = 0;
            glfwGetFramebufferSize(w, &width, &height);
            frameScene(camera_, mesh().bounds, float(width) / float(std::max(height, 1)));
            moved = true;
        }
        if (ImGui::IsKeyPressed(GLFW_KEY_TAB)) camera_.fly = !camera_.fly;
        if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) paused_ = !paused_;
        if (ImGui::IsKeyPressed(GLFW_KEY_T)) settings_.tileOverlay = !settings_.tileOverlay;
        for (int k = 0; k < 9 && k < int(loaded_.scene.cameras.size()); ++k)
            if (ImGui::IsKeyPressed(GLFW_KEY_1 + k)) {
                useSceneCamera(camera_, cameraInLocalSpace(loaded_.scene.cameras[size_t(k)], mesh().origin), mesh().bounds);
                cameraChoice_ = k;
            }
    }
    if (moved) cameraChoice_ = -1;
}

void Viewer::drawPanel() {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(360, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("bundlebake");
    ImGui::TextUnformatted(loaded_.scene.path.c_str());
    ImGui::Text("%zu triangles, %d page(s) of %d^2 texels", mesh().triangleCount(), loaded_.layout.pageCount,
                loaded_.layout.resolution);
    if (!baker_) ImGui::Text("light maps of %s (%s layout)", args_.open.c_str(), cli::uvLayoutName(loaded_.layout.mode));
    static const BakeStats noStats;
    const BakeStats& stats = baker_ ? baker_->stats() : noStats;
    const BakeProgress progress = baker_ ? baker_->progress() : BakeProgress{};

    if (baker_ && ImGui::CollapsingHeader("Bake", ImGuiTreeNodeFlags_DefaultOpen)) {
        char overlay[64];
        std::snprintf(overlay, sizeof overlay, "%d / %d directions", progress.directionsDone, progress.directionsTotal);
        ImGui::ProgressBar(float(progress.directionsDone) / float(std::max(progress.directionsTotal, 1)), ImVec2(-1, 0),
                           overlay);
        const double remaining = progress.directionsTotal - progress.directionsDone;
        const double eta = directionsPerSecond_ > 0 ? remaining / directionsPerSecond_ : INFINITY;
        if (progress.done())
            ImGui::Text("done in %s", duration(bakeDoneAt_).c_str());
        else
            ImGui::Text("%.2f directions/s, ETA %s%s", directionsPerSecond_, paused_ ? "- (paused)" : duration(eta).c_str(),
                        "");
        // the bake's own estimate (engine/bake/noise.cpp), from the latest radiance refresh
        if (baker_->stats().noiseRelative >= 0)
            ImGui::Text("error %.2f %% (relative RMS, estimated: noise %.2f %%, bounces to come %.2f %%)",
                        100.0 * baker_->stats().noiseRelative, 100.0 * baker_->stats().noiseHalves,
                        100.0 * baker_->stats().noiseLag);
        ImGui::Text("%.1f ms per tile, %.1f s baking", tileSeconds_ * 1e3, bakeSeconds_);
        if (ImGui::Button(paused_ ? "Resume" : "Pause")) paused_ = !paused_;
        ImGui::SameLine();
        if (ImGui::Button("Restart")) {
            if (Status s = startBake(); !s) {
                logError("restart failed: " + s.message());
                ImGui::End();
                return;
            }
        }
        float budget = float(frameBudgetMs_);
        if (ImGui::SliderFloat("bake ms/frame", &budget, 1.0f, 500.0f, "%.0f", ImGuiSliderFlags_Logarithmic))
            frameBudgetMs_ = budget;
    }
    if (ImGui::CollapsingHeader("Frame", ImGuiTreeNodeFlags_DefaultOpen)) {
        double mean = 0, worst = 0;
        for (double s : recentFrames_) mean += s, worst = std::max(worst, s);
        mean /= std::max<size_t>(recentFrames_.size(), 1);
        ImGui::Text("frame %.1f ms (max %.1f over the last %zu)", mean * 1e3, worst * 1e3, recentFrames_.size());
    }
    if (baker_ && ImGui::CollapsingHeader("Memory", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::Text("budget          %s", megabytes(options_.memoryBudget).c_str());
        ImGui::Text("node buffer     %s (%lld nodes)", megabytes(stats.nodeBufferBytes).c_str(),
                    (long long)stats.nodeCapacity);
        const int headSide = int(std::lround(std::sqrt(double(stats.headImageBytes) / 4.0)));
        ImGui::Text("head image      %s (%d^2)", megabytes(stats.headImageBytes).c_str(), headSide);
        ImGui::Text("peak nodes/tile %lld (%.0f%% of capacity)", (long long)stats.peakNodesPerTile,
                    100.0 * double(stats.peakNodesPerTile) / double(std::max<int64_t>(stats.nodeCapacity, 1)));
        ImGui::Text("GPU now / peak  %s / %s", megabytes(MemoryTracker::gpu().current()).c_str(),
                    megabytes(MemoryTracker::gpu().peak()).c_str());
    }
    if (baker_ && ImGui::CollapsingHeader("Tiles", ImGuiTreeNodeFlags_DefaultOpen)) {
        const Baker::BundleGrid g = baker_->bundleGrid();
        const int perSide = (g.gridSize + g.tileStep - 1) / std::max(g.tileStep, 1);
        ImGui::Text("direction %d: (%.3f, %.3f, %.3f)", std::max(progress.directionsDone - 1, 0), g.dir.x, g.dir.y, g.dir.z);
        ImGui::Text("bundle %d^2 px, pixel %.4g units", g.gridSize, g.pixelSize);
        ImGui::Text("tiles drawn %d (finest leaf %d px, %d across the root)", g.tiles, g.tileStep, perSide);
        ImGui::Text("overflows redrawn %lld, tiles in all %lld", (long long)stats.overflows, (long long)stats.tilesDrawn);
        ImGui::Checkbox("show tile grid (T)", &settings_.tileOverlay);
        ImGui::TextDisabled("strong lines: tile edges; faint: every 64 bundle pixels");
    }
    if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
        static const char* names[VIEW_MODE_COUNT] = {"lit", "light map only", "albedo", "importance", "texel density"};
        if (ImGui::BeginCombo("mode", names[int(settings_.mode)])) {
            for (int m = 0; m < VIEW_MODE_COUNT; ++m) {
                const bool enabled = ViewMode(m) != ViewMode::Importance || renderer_->hasImportance();
                if (ImGui::Selectable(names[m], int(settings_.mode) == m,
                                      enabled ? 0 : ImGuiSelectableFlags_Disabled))
                    settings_.mode = ViewMode(m);
            }
            ImGui::EndCombo();
        }
#ifdef BUNDLEBAKE_VIEWER_IMPORTANCE
        if (!renderer_->hasImportance() && ImGui::Button("compute importance (CPU)")) {
            Importance imp = computeImportance(mesh(), loaded_.layout.resolution);
            if (Status s = renderer_->setImportance(imp.importance); !s) message_ = s.message();
        }
#else
        if (!renderer_->hasImportance()) ImGui::TextDisabled("importance: not available in this build");
#endif
        ImGui::Checkbox("auto exposure", &autoExposure_);
        ImGui::SameLine();
        if (ImGui::SliderFloat("stops", &settings_.exposure, -16.0f, 16.0f, "%+.2f")) autoExposure_ = false;
    }
    if (ImGui::CollapsingHeader("Camera")) {
        std::string current = cameraChoice_ >= 0 ? loaded_.scene.cameras[size_t(cameraChoice_)].name : "free";
        if (ImGui::BeginCombo("camera", current.c_str())) {
            if (ImGui::Selectable("free", cameraChoice_ < 0)) cameraChoice_ = -1;
            for (size_t c = 0; c < loaded_.scene.cameras.size(); ++c)
                if (ImGui::Selectable((std::to_string(c + 1) + ": " + loaded_.scene.cameras[c].name).c_str(),
                                      cameraChoice_ == int(c))) {
                    useSceneCamera(camera_, cameraInLocalSpace(loaded_.scene.cameras[c], mesh().origin), mesh().bounds);
                    cameraChoice_ = int(c);
                }
            ImGui::EndCombo();
        }
        int mode = camera_.fly ? 1 : 0;
        ImGui::RadioButton("orbit", &mode, 0);
        ImGui::SameLine();
        ImGui::RadioButton("fly (Tab)", &mode, 1);
        camera_.fly = mode == 1;
        ImGui::SameLine();
        if (ImGui::Button("frame (F)")) {
            int width = 0, height = 0;
            glfwGetFramebufferSize(context_->window(), &width, &height);
            frameScene(camera_, mesh().bounds, float(width) / float(std::max(height, 1)));
            cameraChoice_ = -1;
        }
        float fovDegrees = glm::degrees(camera_.yfov);
        if (ImGui::SliderFloat("fov", &fovDegrees, 10.0f, 120.0f, "%.0f deg")) camera_.yfov = glm::radians(fovDegrees);
        ImGui::TextDisabled("drag: rotate, right/middle drag: pan, wheel: zoom");
        ImGui::TextDisabled("WASD QE: move (Shift: faster), 1-9: glTF cameras");
    }
    if (ImGui::CollapsingHeader("Save")) {
        if (baker_) ImGui::InputText("light map dir", &outputDir_);
        if (baker_ && ImGui::Button("save light maps")) {
            Status s = saveLightmaps(outputDir_);
            message_ = s ? "wrote " + outputDir_ + " at " + std::to_string(progress.directionsDone) + " directions"
                         : s.message();
        }
        ImGui::InputText("screenshot", &screenshotPath_);
        if (ImGui::Button("save screenshot")) {
            Status s = saveScreenshot(screenshotPath_);
            message_ = s ? "wrote " + screenshotPath_ : s.message();
        }
    }
    if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
    ImGui::End();
}

void Viewer::logFrameTimes() const {
    char budget[96];
    std::snprintf(budget, sizeof budget, " (bake budget %.0f ms per frame, at least one tile)", frameBudgetMs_);
    logInfo("frame time while baking: " + bakingFrames_.describe() + budget);
    logInfo("  of which bake (step + resolve): " + bakeParts_.describe() + "; draw (scene + panel + swap): " +
            drawParts_.describe());
    if (!idleFrames_.seconds.empty()) logInfo("frame time idle (paused or done): " + idleFrames_.describe());
    if (baker_) {
        const BakeProgress p = baker_->progress();
        logInfo("directions " + std::to_string(p.directionsDone) + "/" + std::to_string(p.directionsTotal) + ", " +
                std::to_string(bakeSeconds_ > 0 ? p.directionsDone / bakeSeconds_ : 0.0) +
                " directions/s in Baker::step");
    }
}

int Viewer::run() {
    GLFWwindow* window = context_->window();
    frameBudgetMs_ = args_.frameBudgetMs;
    settings_.tileOverlay = args_.tiles;
    auto mode = parseViewMode(args_.view);
    if (!mode) return cli::fail("--view: " + mode.error());
    settings_.mode = *mode;
    if (args_.exposure != "auto") {
        char* end = nullptr;
        settings_.exposure = std::strtof(args_.exposure.c_str(), &end);
        if (end == args_.exposure.c_str() || *end != '\0' || !std::isfinite(settings_.exposure))
            return cli::fail("--exposure: '" + args_.exposure + "' is not a number of stops or auto");
        autoExposure_ = false;
    }
    outputDir_ = args_.output;
    if (Status s = opened_ ? showOpened() : startBake(); !s) return cli::fail(s.message());
    sceneRadius_ = std::max(0.5f * glm::length(mesh().bounds.size()), 1e-4f);

    // camera: frame the scene on load, along glTF camera 0's view if the scene has one
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    const float aspect = float(width) / float(std::max(height, 1));
    if (args_.camera >= int(loaded_.scene.cameras.size()))
        return cli::fail("--camera " + std::to_string(args_.camera) + ": the scene has " +
                         std::to_string(loaded_.scene.cameras.size()) + " camera(s)");
    if (args_.camera >= 0) {
        useSceneCamera(camera_, cameraInLocalSpace(loaded_.scene.cameras[size_t(args_.camera)], mesh().origin), mesh().bounds);
        cameraChoice_ = args_.camera;
    } else {
        if (!loaded_.scene.cameras.empty()) {
            useSceneCamera(camera_, cameraInLocalSpace(loaded_.scene.cameras[0], mesh().origin), mesh().bounds);
        } else {
            camera_.setForward(DEFAULT_FRAMING_DIRECTION);
        }
        frameScene(camera_, mesh().bounds, aspect);
    }

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working directory
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 430");

    int frame = 0;
    auto last = Clock::now();
    int exitCode = 0;
    while (!glfwWindowShouldClose(window)) {
        glfwPollEvents();
        const bool baking = baker_ && !paused_ && !baker_->progress().done();
        auto bakeBegin = Clock::now();
        bakeStep();
        const double bakePart = secondsSince(bakeBegin);
        const double now = glfwGetTime();
        rateWindow_.emplace_back(now, baker_ ? baker_->progress().directionsDone : 0);
        while (rateWindow_.size() > 2 && now - rateWindow_.front().first > 3.0) rateWindow_.pop_front();
        if (rateWindow_.size() >= 2 && rateWindow_.back().first > rateWindow_.front().first)
            directionsPerSecond_ = (rateWindow_.back().second - rateWindow_.front().second) /
                                   (rateWindow_.back().first - rateWindow_.front().first);
        updateAutoExposure(false);

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        auto nowTime = Clock::now();
        const double dt = std::chrono::duration<double>(nowTime - last).count();
        handleInput(dt);
        drawPanel();
        if ((!baker_ && !opened_) || !renderer_) {  // a restart failed (logged)
            ImGui::EndFrame();
            exitCode = 1;
            break;
        }
        ImGui::Render();

        auto drawBegin = Clock::now();
        glfwGetFramebufferSize(window, &width, &height);
        if (width > 0 && height > 0) renderer_->draw(currentView(width, height), settings_, 0, width, height);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        const bool lastFrame = args_.frames > 0 && frame + 1 >= args_.frames;
        if (lastFrame && !args_.screenshot.empty() && args_.screenshotPanel) {
            if (Status s = saveWindow(args_.screenshot, width, height); !s) exitCode = cli::fail(s.message());
        }
        glfwSwapBuffers(window);
        const double drawPart = secondsSince(drawBegin);

        // frame time: start of one frame to the start of the next
        nowTime = Clock::now();
        const double frameSeconds = std::chrono::duration<double>(nowTime - last).count();
        last = nowTime;
        if (frame > 0) (baking ? bakingFrames_ : idleFrames_).add(frameSeconds);
        if (frame > 0 && baking) bakeParts_.add(bakePart), drawParts_.add(drawPart);
        recentFrames_.push_back(frameSeconds);
        if (recentFrames_.size() > 60) recentFrames_.pop_front();
        ++frame;

        if (args_.frames > 0 && frame >= args_.frames) {
            if (!args_.screenshot.empty() && !args_.screenshotPanel) {
                updateAutoExposure(true);
                Status s = saveScreenshot(args_.screenshot);
                if (!s) {
                    exitCode = cli::fail(s.message());
                } else {
                    logInfo("screenshot after " + std::to_string(frame) + " frames (" +
                            std::to_string(baker_ ? baker_->progress().directionsDone : 0) + " directions" +
                            (baker_ ? "" : ", light maps of " + args_.open) + ") -> " + args_.screenshot);
                }
            }
            break;
        }
    }
    logFrameTimes();
    if (args_.saveAtExit && exitCode == 0 && !baker_) {
        exitCode = cli::fail("--save-lightmaps: nothing was baked (--open shows a bake)");
    } else if (args_.saveAtExit && exitCode == 0) {
        if (Status s = saveLightmaps(outputDir_); !s)
            exitCode = cli::fail(s.message());
        else
            logInfo("light maps at " + std::to_string(baker_->progress().directionsDone) + " directions -> " + outputDir_);
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    renderer_.reset();
    baker_.reset();
    return exitCode;
}

int runViewer(int argc, char** argv) {
    ViewerArgs a;
    CLI::App app{"bundlebake-viewer: watch the light maps of a bake converge (GLFW, OpenGL 4.3)"};
    cli::addSceneOptions(app, a.scene);
    app.get_option("scene")->required(false)->description(
        "glTF 2.0 scene (.gltf or .glb); with --open, the bake's scene when left out");
    app.add_option("--open", a.open,
                   "Show a finished bake (a `bundlebake bake` OUTDIR) instead of baking: its manifest.json gives the "
                   "layout and the scene, its EXR pages the light maps");
    app.add_option("--directions", a.directions, "Bundle directions (each serves d and -d)")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    app.add_option("--bundle-res", a.bundleRes, "Bundle resolution across the bounding sphere (0 = half a texel per pixel)")
        ->check(CLI::Range(0, 1 << 20))
        ->capture_default_str();
    app.add_option("--memory-budget", a.memoryBudget, "GL bytes for the whole bake: light maps, mesh, materials, and the rest for the bundle pass")
        ->capture_default_str();
    app.add_option("--seed", a.seed, "Random seed (directions, stochastic rounding)")->capture_default_str();
    app.add_option("--sky", a.sky, "Uniform sky radiance r,g,b (scene units)")->capture_default_str();
    app.add_option("--env", a.env, "Equirectangular environment map (EXR/HDR), radiance; replaces --sky")
        ->excludes(app.get_option("--sky"));
    app.add_option("--rounding", a.rounding, "fp16/RGBE conversion: stochastic or nearest")
        ->check(CLI::IsMember({"stochastic", "nearest"}))
        ->capture_default_str();
    cli::addHistoryOptions(app, a.historyPower, a.historyPlateau);
    cli::addSupersampleOption(app, a.supersample);
    app.add_option("--width", a.width, "Window width")->check(CLI::Range(64, 16384))->capture_default_str();
    app.add_option("--height", a.height, "Window height")->check(CLI::Range(64, 16384))->capture_default_str();
    app.add_option("--frame-budget", a.frameBudgetMs, "Bake milliseconds per frame (at least one bundle tile per frame)")
        ->check(CLI::Range(0.0, 10000.0))
        ->capture_default_str();
    app.add_option("--camera", a.camera, "Start at this glTF camera (-1: frame the scene along camera 0's view)")
        ->check(CLI::Range(-1, 1 << 20))
        ->capture_default_str();
    app.add_option("--view", a.view, "lit, lightmap, albedo or density")
        ->check(CLI::IsMember({"lit", "lightmap", "albedo", "density"}))
        ->capture_default_str();
    app.add_option("--exposure", a.exposure, "Stops before the tone curve, or auto (re-evaluated every second)")
        ->capture_default_str();
    app.add_flag("--tiles", a.tiles, "Show the tile grid of the current direction");
    app.add_option("--output", a.output, "Directory the panel's 'save light maps' writes to")->capture_default_str();
    app.add_flag("--save-lightmaps", a.saveAtExit, "At exit, write the current light maps to --output (as `bundlebake bake`)");
    app.add_option("--screenshot", a.screenshot, "After --frames frames, write the scene view to this PNG and exit");
    app.add_flag("--screenshot-panel", a.screenshotPanel, "The screenshot is the whole window, panel included");
    app.add_option("--frames", a.frames, "Exit after this many frames (0 = run until the window closes)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    bool verbose = false;
    app.add_flag("-v,--verbose", verbose, "Log debug messages");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);
        std::fprintf(stderr, "bundlebake-viewer: error: %s (see --help)\n", e.what());
        return 2;
    }
    setLogLevel(verbose ? LogLevel::Debug : LogLevel::Info);
    a.given = cli::layoutFlagsGiven(app);
    if (a.scene.scene.empty() && a.open.empty()) return cli::fail("a SCENE is needed (or --open BAKE_DIR)");
    if (!a.screenshot.empty() && a.frames <= 0) return cli::fail("--screenshot needs --frames N (N >= 1)");

    auto budget = cli::parseSize(a.memoryBudget, "--memory-budget");
    if (!budget) return cli::fail(budget.error());
    auto sky = cli::parseColor(a.sky, "--sky");
    if (!sky) return cli::fail(sky.error());
    BakeOptions options;
    options.directions = a.directions;
    options.bundleResolution = a.bundleRes;
    options.memoryBudget = *budget;
    options.seed = a.seed;
    options.sky = *sky;
    options.rounding = a.rounding == "nearest" ? Rounding::Nearest : Rounding::Stochastic;
    options.historyPower = a.historyPower;
    options.historyPlateau = a.historyPlateau;
    options.supersample = cli::supersampleValue(a.supersample);
    if (!a.env.empty()) {
        auto env = io::readImageRgb(a.env);
        if (!env) return cli::fail(env.error());
        options.environment = std::move(env.value());
    }
    std::optional<LightmapPages> opened;
    Expected<cli::LoadedScene> loaded = Expected<cli::LoadedScene>::failure("not loaded");
    if (!a.open.empty()) {
        if (a.scene.scene.empty()) {
            auto manifest = readBakeManifest(a.open);
            if (!manifest) return cli::fail(manifest.error());
            if (manifest->scene.empty()) return cli::fail(a.open + "/manifest.json names no scene: give the SCENE");
            a.scene.scene = manifest->scene;
        }
        loaded = cli::loadSceneWithBakeLayout(a.scene, a.given, a.open);
        if (!loaded) return cli::fail(loaded.error());
        auto maps = readBakedLightmaps(a.open, loaded->layout);
        if (!maps) return cli::fail(maps.error());
        opened = std::move(maps.value());
    } else {
        loaded = cli::loadSceneAndLayout(a.scene);
        if (!loaded) return cli::fail(loaded.error());
    }

    const std::string title = "bundlebake - " + std::filesystem::path(a.scene.scene).filename().string();
    auto context = GlfwContext::create(a.width, a.height, title);
    if (!context) return cli::fail(context.error());
    logInfo("viewer: " + context.value()->caps().describe());
    Viewer viewer(std::move(a), std::move(loaded.value()), std::move(options), std::move(context.value()),
                  std::move(opened));
    return viewer.run();
}

}  // namespace
}  // namespace bb::viewer

int main(int argc, char** argv) { return bb::viewer::runViewer(argc, argv); }
