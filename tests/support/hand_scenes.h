// Scenes built by hand for the tests (no file): quads and boxes, each
// face its own instance with TEXCOORD_1 over [0,1]^2, for the `pack` layout
// (every face gets its own rectangle). Object space = world space (identity
// instance transforms), Scene::origin 0. Header-only, GL-free.
//
// Also: bake helpers that take a Scene (bake_helper.h's makeBake loads a
// file), per-instance texel walks over a pack layout, and the CPU reference
// baker on the same scene and layout.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bake/baker.h"
#include "layout/layout.h"
#include "reference/reference_baker.h"
#include "scene/scene.h"

namespace bb::test {

// Adds a material; returns its index.
inline int addMaterial(Scene& scene, glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.name = "material " + std::to_string(scene.materials.size());
    m.albedo = albedo;
    m.emission = emission;
    scene.materials.push_back(m);
    return int(scene.materials.size()) - 1;
}

// `p` as its own mesh and instance `name` (identity transform); returns the instance index.
inline int addPrimitive(Scene& scene, Primitive p, const std::string& name) {
    for (const glm::vec3& x : p.positions) scene.bounds.extend(x);
    Mesh m;
    m.name = name;
    m.primitives.push_back(std::move(p));
    scene.meshes.push_back(std::move(m));
    Instance inst;
    inst.name = name;
    inst.mesh = int(scene.meshes.size()) - 1;
    inst.node = int(scene.instances.size());
    scene.instances.push_back(inst);
    return int(scene.instances.size()) - 1;
}

// A single-sided parallelogram centre +- e1 +- e2 facing normalize(e1 x e2),
// as its own mesh and instance; TEXCOORD_1 (0,0) at centre - e1 - e2, u along
// e1, v along e2. Returns the instance index.
inline int addQuad(Scene& scene, const glm::vec3& centre, const glm::vec3& e1, const glm::vec3& e2, int material,
                   const std::string& name) {
    const glm::vec3 n = glm::normalize(glm::cross(e1, e2));
    Primitive p;
    p.positions = {centre - e1 - e2, centre + e1 - e2, centre + e1 + e2, centre - e1 + e2};
    p.normals.assign(4, n);
    p.uv1 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p.uv0 = p.uv1;
    p.indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from n
    p.material = material;
    return addPrimitive(scene, std::move(p), name);
}

// The six faces of a box (centre, half extents along the columns of `axes`, a
// rotation), facing out (`outward`) or in; instance names "<name> +x" etc.
// Returns the first instance index (faces in the order +x, -x, +y, -y, +z, -z).
inline int addBox(Scene& scene, const glm::vec3& centre, const glm::vec3& half, int material, bool outward,
                  const std::string& name, const glm::mat3& axes = glm::mat3(1.0f)) {
    const int first = int(scene.instances.size());
    static const char* NAMES[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    for (int f = 0; f < 6; ++f) {
        const int a = f / 2;
        const float s = (f % 2 == 0) ? 1.0f : -1.0f;
        const int b = (a + 1) % 3, c = (a + 2) % 3;  // e_b x e_c = e_a
        const glm::vec3 e1 = axes[b] * half[b];
        const glm::vec3 e2 = axes[c] * (half[c] * s * (outward ? 1.0f : -1.0f));  // e1 x e2 along +-s e_a
        addQuad(scene, centre + axes[a] * (s * half[a]), e1, e2, material, name + " " + NAMES[f]);
    }
    return first;
}

// The unit normal of a quad instance (its first triangle's).
inline glm::vec3 instanceNormal(const Scene& scene, int instance) {
    return scene.meshes[size_t(scene.instances[size_t(instance)].mesh)].primitives[0].normals[0];
}

inline Expected<Layout> packLayout(const Scene& scene, int resolution, float texelDensity, int padding = 2) {
    LayoutOptions o;
    o.mode = UvLayout::Pack;
    o.resolution = resolution;
    o.texelDensity = texelDensity;
    o.padding = padding;
    return computeLayout(scene, o);
}

// The world point of a quad instance at TEXCOORD_1 (s, t) (bilinear over the parallelogram).
inline glm::dvec3 quadPoint(const Scene& scene, int instance, double s, double t) {
    const auto& p = scene.meshes[size_t(scene.instances[size_t(instance)].mesh)].primitives[0].positions;
    const glm::dvec3 p0(p[0]), p1(p[1]), p3(p[3]);
    return p0 + s * (p1 - p0) + t * (p3 - p0);
}

// Lambert's point-to-polygon form factor F from x with unit normal n: a
// uniform emitter of radiance 1 gives x L_lm = F (closed-form checks).
inline double polygonFormFactor(const glm::dvec3& x, const glm::dvec3& n, const std::vector<glm::dvec3>& polygon) {
    double sum = 0.0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3 a = glm::normalize(polygon[i] - x), b = glm::normalize(polygon[(i + 1) % polygon.size()] - x);
        sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::dot(glm::normalize(glm::cross(a, b)), n);
    }
    return std::fabs(sum) / (2.0 * M_PI);
}

// Visits every covered texel of a quad instance's pack rectangle: f(page,
// texel index, world point of the texel centre). The quads' TEXCOORD_1 spans
// [0,1]^2, so the rectangle is exactly the quad: texel (x + a, y + b) has its
// centre at TEXCOORD_1 ((a + 0.5) / width, (b + 0.5) / height).
template <class F>
void forEachQuadTexel(const Scene& scene, const Layout& layout, const LightmapPages& maps, int instance, F&& f) {
    const InstanceRect& r = layout.rects[size_t(instance)];
    for (int b = 0; b < r.height; ++b)
        for (int a = 0; a < r.width; ++a) {
            const size_t i = size_t(r.y + b) * size_t(layout.resolution) + size_t(r.x + a);
            if (!maps.covered[size_t(r.page)][i]) continue;
            f(r.page, i, quadPoint(scene, instance, (a + 0.5) / r.width, (b + 0.5) / r.height), a, b);
        }
}

// Both bakers on one scene and layout.
inline Expected<LightmapPages> bakeGpu(const Scene& scene, const Layout& layout, const BakeOptions& options,
                                       double* seconds = nullptr, BakeStats* stats = nullptr) {
    auto baker = Baker::create(scene, layout, options);
    if (!baker) return Expected<LightmapPages>::failure("Baker::create: " + baker.error());
    const auto t0 = std::chrono::steady_clock::now();
    while (!(*baker)->step(1e9).done()) {
    }
    LightmapPages maps = (*baker)->readLightmaps();
    if (seconds) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats) *stats = (*baker)->stats();
    return maps;
}

inline Expected<LightmapPages> bakeReference(const Scene& scene, const Layout& layout, const ReferenceOptions& options,
                                             double* seconds = nullptr) {
    auto ref = ReferenceBaker::create(scene, layout, options);
    if (!ref) return Expected<LightmapPages>::failure("ReferenceBaker::create: " + ref.error());
    const auto t0 = std::chrono::steady_clock::now();
    while (!(*ref)->step(1e9).done()) {
    }
    if (seconds) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return (*ref)->readLightmaps();
}

// Over the texels both maps cover, every page: relative RMSE of `a` against
// `b` (sqrt(mean (a - b)^2) / mean b, all channels) and the count.
struct MapAgreement {
    size_t texels = 0, onlyA = 0, onlyB = 0;
    double meanA = 0, meanB = 0, rmse = 0;
    double relativeRmse() const { return meanB > 0 ? rmse / meanB : INFINITY; }
};
inline MapAgreement compareMaps(const LightmapPages& a, const LightmapPages& b) {
    MapAgreement m;
    for (size_t p = 0; p < std::min(a.pages.size(), b.pages.size()); ++p)
        for (size_t i = 0; i < a.covered[p].size(); ++i) {
            const bool ca = a.covered[p][i], cb = b.covered[p][i];
            m.onlyA += ca && !cb;
            m.onlyB += cb && !ca;
            if (!ca || !cb) continue;
            ++m.texels;
            for (int c = 0; c < 3; ++c) {
                const double x = a.pages[p].pixels[i][c], y = b.pages[p].pixels[i][c];
                m.meanA += x;
                m.meanB += y;
                m.rmse += (x - y) * (x - y);
            }
        }
    const double n = 3.0 * double(std::max<size_t>(m.texels, 1));
    m.meanA /= n;
    m.meanB /= n;
    m.rmse = std::sqrt(m.rmse / n);
    return m;
}

}  // namespace bb::test
