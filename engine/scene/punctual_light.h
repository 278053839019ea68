// Point and spot lights (KHR_lights_punctual) lit in closed form, the spec's
// recommended formulas, for the GPU pass (glsl/lib/punctual_light.glsl, step
// for step), the CPU reference and the tests:
//   E(x) = intensity * max(cos, 0) / d^2 * window(d) * cone(x)
//   window(d) = clamp(1 - (d / range)^4, 0, 1)   (1 when range is undefined: infinite)
//   cone = t^2, t = clamp((cos_s - cos(outer)) / max(0.001, cos(inner) - cos(outer)), 0, 1),
//          cos_s the cosine between the spot's direction and the light-to-x direction
// with cos the cosine between x's normal and the direction towards the light,
// d in scene units. The light map holds L_lm = E / pi (DESIGN.md Units).
// GL-free, header-only.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace bb {

// window(d) x cone, the attenuation without 1/d^2 and the cosine; `toX` is
// the unit direction from the light to the point, d its distance.
inline float punctualAttenuation(const PunctualLight& l, float d, const glm::vec3& toX) {
    float a = 1.0f;
    if (l.range > 0.0f) {
        const float r = d / l.range;
        a = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
    }
    if (l.type == PunctualLight::Type::Spot) {
        const float cosOuter = std::cos(l.outerConeAngle), cosInner = std::cos(l.innerConeAngle);
        const float scale = 1.0f / std::max(0.001f, cosInner - cosOuter);
        const float t = std::clamp((glm::dot(l.direction, toX) - cosOuter) * scale, 0.0f, 1.0f);
        a *= t * t;
    }
    return a;
}

// Irradiance E at x (unit normal n) from light l at `lightPosition` (the
// same space as x), unoccluded; 0 below x's horizon or at the light.
inline glm::vec3 punctualIrradiance(const PunctualLight& l, const glm::vec3& lightPosition, const glm::vec3& x,
                                    const glm::vec3& n) {
    const glm::vec3 toLight = lightPosition - x;
    const float d2 = glm::dot(toLight, toLight);
    if (!(d2 > 0.0f)) return glm::vec3(0.0f);
    const float d = std::sqrt(d2);
    const float c = glm::dot(n, toLight) / d;
    if (c <= 0.0f) return glm::vec3(0.0f);
    return l.intensity * (c / d2 * punctualAttenuation(l, d, -toLight / d));
}

}  // namespace bb
