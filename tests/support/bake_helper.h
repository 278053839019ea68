// Helpers for the GL and golden bake tests: load a scene from assets/, lay
// it out, create a bb::Baker on the shared headless context, bake to the
// end, and summarize light map texels. Header-only (tests/CMakeLists.txt
// compiles tests/gl/*.cpp and tests/golden/*.cpp plus gl_fixture.cpp).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <cstdlib>
#include <filesystem>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <glm/glm.hpp>

#include "bake/baker.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"
#include "support/gl_fixture.h"
#include "support/scratch_dirs.h"

namespace bb::test {

// A scene, its layout and a Baker made on the current context. `error` is
// set (and baker null) when any step fails.
struct SceneBake {
    Scene scene;
    Layout layout;
    std::unique_ptr<Baker> baker;
    std::string error;
    explicit operator bool() const { return baker != nullptr; }
};

// `edit`, if given, changes the loaded scene before it is laid out (materials, lights).
inline SceneBake makeBake(const std::string& assetRelative, const LayoutOptions& layoutOptions,
                          const BakeOptions& bakeOptions, const std::function<void(Scene&)>& edit = {}) {
    SceneBake out;
    auto scene = loadScene(sourcePath(assetRelative));
    if (!scene) {
        out.error = "loadScene: " + scene.error();
        return out;
    }
    out.scene = std::move(scene.value());
    if (edit) edit(out.scene);
    auto layout = computeLayout(out.scene, layoutOptions);
    if (!layout) {
        out.error = "computeLayout: " + layout.error();
        return out;
    }
    out.layout = std::move(layout.value());
    auto baker = Baker::create(out.scene, out.layout, bakeOptions);
    if (!baker) {
        out.error = "Baker::create: " + baker.error();
        return out;
    }
    out.baker = std::move(baker.value());
    return out;
}

// Generates a tiny city (scripts/generate_city.py, seeded by `flags`) into a
// per-process temp dir; returns its absolute path, or "" if the script failed.
inline std::string generateTinyCity(const std::string& name, const std::string& flags) {
    const std::string dir = removeAtExit(::testing::TempDir() + "/cities_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = dir + "/" + name + ".gltf";
    const std::string cmd = "python3 " + sourcePath("scripts/generate_city.py") + " --preset tiny " + flags + " -o " +
                            path + " > /dev/null";
    const int status = std::system(cmd.c_str());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "";
    return path;
}

inline LayoutOptions packLayout(int resolution) {
    LayoutOptions o;
    o.mode = UvLayout::Pack;
    o.resolution = resolution;
    return o;
}

// Bake options under a uniform white sky.
inline BakeOptions skyOptions(int directions, uint64_t seed) {
    BakeOptions o;
    o.directions = directions;
    o.seed = seed;
    o.sky = glm::vec3(1.0f);
    return o;
}

inline LayoutOptions assetLayout(int resolution) {
    LayoutOptions o;
    o.mode = UvLayout::Asset;
    o.resolution = resolution;
    return o;
}

// Bakes every remaining direction; returns the wall time in seconds.
inline double bakeToEnd(Baker& baker) {
    auto t0 = std::chrono::steady_clock::now();
    while (!baker.step(1e9).done()) {
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The uniform-sky plane (assets/sky_plane, 64 x 64 asset layout, sky S =
// (0.3, 0.6, 1.2), seed 1) baked with `directions`: every covered texel's
// L_lm should be S. Used by the sky-plane and rounding tests.
struct SkyPlaneBake {
    glm::vec3 sky{0.3f, 0.6f, 1.2f};
    LightmapPages maps;
    double seconds = 0;
    std::string error;
};

inline SkyPlaneBake bakeSkyPlane(int directions, BakeOptions::Tiling tiling = BakeOptions::Tiling::Adaptive) {
    SkyPlaneBake out;
    BakeOptions options;
    options.tiling = tiling;
    options.directions = directions;
    options.seed = 1;
    options.sky = out.sky;
    SceneBake bake = makeBake("assets/sky_plane/sky_plane.gltf", assetLayout(64), options);
    if (!bake) {
        out.error = bake.error;
        return out;
    }
    out.seconds = bakeToEnd(*bake.baker);
    out.maps = bake.baker->readLightmaps();
    return out;
}

// Min / max / mean of one channel (or all three) over a set of texels.
struct Summary {
    size_t count = 0;
    double mean = 0;
    double min = std::numeric_limits<double>::infinity();
    double max = -std::numeric_limits<double>::infinity();
    size_t argMin = 0, argMax = 0;  // texel index y * R + x
    void add(double value, size_t index) {
        ++count;
        mean += value;  // sum until finish()
        if (value < min) min = value, argMin = index;
        if (value > max) max = value, argMax = index;
    }
    void finish() {
        if (count) mean /= double(count);
    }
};

inline std::string texelName(size_t index, int resolution) {
    return "texel (" + std::to_string(index % size_t(resolution)) + ", " + std::to_string(index / size_t(resolution)) +
           ")";
}

// Summary of every channel of every covered texel of one page.
inline Summary summarizeCovered(const LightmapPages& maps, int page = 0) {
    Summary s;
    const auto& img = maps.pages[size_t(page)];
    const auto& cov = maps.covered[size_t(page)];
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        if (!cov[i]) continue;
        for (int c = 0; c < 3; ++c) s.add(img.pixels[i][c], i);
    }
    s.finish();
    return s;
}

inline std::string describe(const Summary& s, int resolution) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%zu values: mean %.6f, min %.6f at %s, max %.6f at %s", s.count, s.mean, s.min,
                  texelName(s.argMin, resolution).c_str(), s.max, texelName(s.argMax, resolution).c_str());
    return buf;
}

// The baker's radiance-map refresh schedule (Baker::Impl::refreshInterval,
// refreshEveryRound): after direction k (0-based) the outgoing radiance the
// next bundles read is refreshed after every direction until the bounces the
// largest albedo rho needs (ln 1000 / (1 - rho), at least 64), then when
// (k + 1) % clamp(min((k - shift) / 32, memory / 2), 1, 8) == 0, memory the
// ramp's (min(k + 1, plateau) / (power + 1) + max(0, k + 1 - plateau)), and
// after the last direction. Mirrored here for furnaceExpectation(); if the
// engine's schedule changes, update this (it moves the rho 0.9 expectations by ~0.1%).
inline bool radianceRefreshedAfter(int k, int directions, double rho, double historyPower, int plateau) {
    const int everyDirection = std::max(64, int(std::ceil(std::log(1000.0) / (1.0 - std::min(rho, 0.99)))));
    const int rampEnd = std::max(1, plateau);
    const double memory = std::min(k + 1, rampEnd) / (historyPower + 1.0) + std::max(0, k + 1 - rampEnd);
    const int interval = std::clamp(std::min((k - std::max(0, everyDirection - 64)) / 32, int(memory / 2.0)), 1, 8);
    return (k + 1) % interval == 0 || k + 1 == directions;
}

// The expected furnace value after N directions with the baker's history
// ramp (BakeOptions::historyPower; direction k, 1-based, weighs
// min(k, plateau)^p, BakeStats::historyPlateau): L_lm is the weighted mean of the incoming radiance seen by
// each direction, Le + rho * R, R the light map as last resolved into the
// radiance map (radianceRefreshedAfter), so
//   M_k = sum_j w_j (Le + rho R_j) / sum_j w_j,  R_j = M at the last refresh before j.
// This is the bake's expectation in a furnace (every texel sees the same
// value); its gap to Le / (1 - rho) is the start-up bias of the iteration.
inline double furnaceExpectation(double le, double rho, int directions, double historyPower, int plateau) {
    const double rampEnd = std::max(1, plateau);
    double sum = 0, weights = 0, m = 0, r = 0;
    for (int k = 0; k < directions; ++k) {
        // relative to the ramp's last weight (early ones underflow to 0 at large powers)
        const double w = std::exp(historyPower * (std::log(std::min(double(k + 1), rampEnd)) - std::log(rampEnd)));
        sum += w * (le + rho * r);
        weights += w;
        m = weights > 0 ? sum / weights : le + rho * r;  // early weights can underflow to 0
        if (radianceRefreshedAfter(k, directions, rho, historyPower, plateau)) r = m;
    }
    return m;
}

// --- texels to triangles (CPU) ----------------------------------------------

// Which triangle of the bake mesh covers each texel centre of a page
// (texel (x, y) centre at ((x + 0.5) / R, (y + 0.5) / R) in page UV, row y =
// v, as GL rasterizes the meta pass). -1 where none does. Texel centres
// exactly on a shared edge take the first triangle that contains them.
inline std::vector<int> texelTriangles(const BakeMesh& mesh, int resolution, int page = 0) {
    std::vector<int> owner(size_t(resolution) * resolution, -1);
    const float r = float(resolution);
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::vec2 a = mesh.vertices[3 * t].lightmapUv * r;
        glm::vec2 b = mesh.vertices[3 * t + 1].lightmapUv * r;
        glm::vec2 c = mesh.vertices[3 * t + 2].lightmapUv * r;
        auto edge = [](glm::vec2 p, glm::vec2 q, glm::vec2 x) {
            return double(q.x - p.x) * (x.y - p.y) - double(q.y - p.y) * (x.x - p.x);
        };
        const double area = edge(a, b, c);
        if (area == 0) continue;
        int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}))));
        int x1 = std::min(resolution - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
        int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}))));
        int y1 = std::min(resolution - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                glm::vec2 p(x + 0.5f, y + 0.5f);
                double w0 = edge(b, c, p), w1 = edge(c, a, p), w2 = edge(a, b, p);
                bool inside = area > 0 ? (w0 >= 0 && w1 >= 0 && w2 >= 0) : (w0 <= 0 && w1 <= 0 && w2 <= 0);
                size_t i = size_t(y) * resolution + x;
                if (inside && owner[i] < 0) owner[i] = int(t);
            }
    }
    return owner;
}

// The triangle whose light map footprint is nearest to the texel centre (for
// covered texels whose centre no triangle contains: GL rasterization and
// this test can disagree by rounding on an edge).
inline int nearestTriangle(const BakeMesh& mesh, int resolution, size_t texel, int page = 0) {
    const float r = float(resolution);
    glm::vec2 p((float(texel % size_t(resolution)) + 0.5f) / r, (float(texel / size_t(resolution)) + 0.5f) / r);
    auto segDist = [](glm::vec2 x, glm::vec2 a, glm::vec2 b) {
        glm::vec2 ab = b - a;
        float t = glm::clamp(glm::dot(x - a, ab) / std::max(glm::dot(ab, ab), 1e-20f), 0.0f, 1.0f);
        return glm::length(x - (a + t * ab));
    };
    int best = -1;
    float bestDist = 1e30f;
    for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
        glm::vec2 a = mesh.vertices[3 * t].lightmapUv, b = mesh.vertices[3 * t + 1].lightmapUv,
                  c = mesh.vertices[3 * t + 2].lightmapUv;
        float d = std::min({segDist(p, a, b), segDist(p, b, c), segDist(p, c, a)});
        if (d < bestDist) bestDist = d, best = int(t);
    }
    return best;
}

inline glm::vec3 triangleCentroid(const BakeMesh& mesh, int t) {
    return glm::vec3(mesh.vertices[3 * size_t(t)].position + mesh.vertices[3 * size_t(t) + 1].position +
                     mesh.vertices[3 * size_t(t) + 2].position) /
           3.0f;
}

// World position of a texel centre, through the triangle that covers it
// (barycentric coordinates in page UV; extrapolated if the centre is outside).
inline glm::dvec3 texelWorldPoint(const BakeMesh& mesh, int resolution, int triangle, size_t texel) {
    const size_t t = size_t(triangle);
    glm::dvec2 p((double(texel % size_t(resolution)) + 0.5) / resolution,
                 (double(texel / size_t(resolution)) + 0.5) / resolution);
    glm::dvec2 a(mesh.vertices[3 * t].lightmapUv), b(mesh.vertices[3 * t + 1].lightmapUv),
        c(mesh.vertices[3 * t + 2].lightmapUv);
    double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (det == 0) return glm::dvec3(mesh.vertices[3 * t].position);
    double l1 = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det;
    double l2 = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det;
    return (1 - l1 - l2) * glm::dvec3(mesh.vertices[3 * t].position) + l1 * glm::dvec3(mesh.vertices[3 * t + 1].position) +
           l2 * glm::dvec3(mesh.vertices[3 * t + 2].position);
}

}  // namespace bb::test
