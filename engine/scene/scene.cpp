// Scene member functions: instanced counts and world-space areas.
#include "scene/scene.h"

#include "core/check.h"

namespace bb {

size_t Scene::triangleCount() const {
    size_t n = 0;
    for (const Instance& inst : instances)
        for (const Primitive& p : meshes[size_t(inst.mesh)].primitives) n += p.triangleCount();
    return n;
}

size_t Scene::emitterTriangleCount() const {
    size_t n = 0;
    for (const Instance& inst : instances)
        for (const Primitive& p : meshes[size_t(inst.mesh)].primitives) {
            const glm::vec3& e = materials[size_t(p.material)].emission;
            if (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) n += p.triangleCount();
        }
    return n;
}

bool Scene::allHaveUv1() const {
    for (const Instance& inst : instances)
        for (const Primitive& p : meshes[size_t(inst.mesh)].primitives)
            if (p.uv1.empty() || p.uv1.size() != p.positions.size()) return false;
    return true;
}

double Scene::instanceArea(size_t instance) const {
    CHECK_LT(instance, instances.size());
    const Instance& inst = instances[instance];
    // area in double: world positions of large levels lose precision in float
    const glm::dmat4 worldFromObject = inst.exactWorldFromObject();
    double area2 = 0.0;  // twice the area
    for (const Primitive& p : meshes[size_t(inst.mesh)].primitives) {
        for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
            glm::dvec3 a(worldFromObject * glm::dvec4(glm::dvec3(p.positions[p.indices[t]]), 1.0));
            glm::dvec3 b(worldFromObject * glm::dvec4(glm::dvec3(p.positions[p.indices[t + 1]]), 1.0));
            glm::dvec3 c(worldFromObject * glm::dvec4(glm::dvec3(p.positions[p.indices[t + 2]]), 1.0));
            area2 += glm::length(glm::cross(b - a, c - a));
        }
    }
    return 0.5 * area2;
}

glm::dvec3 chooseLocalOrigin(const glm::dvec3& lo, const glm::dvec3& hi) {
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return glm::dvec3(0.0);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    const double radius = 0.5 * glm::length(hi - lo);
    return glm::length(centre) <= radius ? glm::dvec3(0.0) : centre;
}

}  // namespace bb
