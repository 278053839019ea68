// The bake mesh as Embree sees it, for the CPU's rays: the reference baker's
// paths and the transport albedo's (bake/transport_albedo.h).
#pragma once

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "layout/bake_mesh.h"

namespace bb {

// A committed scene of one triangle geometry, triangle i of `mesh` as
// primitive i, robust (watertight: no leaks through shared edges), taking
// SkipContext's filter; nullptr if Embree fails (the device's error function
// says why).
RTCScene commitBakeMeshScene(RTCDevice device, const BakeMesh& mesh, RTCBuildQuality quality);

// How far a ray starts off its surface where the triangle it leaves is not
// known (a probe point): a few hundred float ulps at the mesh's largest
// (local) coordinate or its diagonal, whichever is larger.
float rayOffset(const BakeMesh& mesh);

constexpr uint32_t kNoTriangle = RTC_INVALID_GEOMETRY_ID;

// A ray's context that ignores up to two triangles: the one the ray leaves
// (it starts on it, with no offset) and the one it is aimed at (an emitter's
// sample). A ray that starts off its surface by an offset sees what lies
// within the offset wrongly: the offset grew with the scene's extent (2e-5 of
// it: 5.7 cm in a city cut-out on a 2 km ground), and a wall under a 22 cm
// soffit, its points moved 5.7 cm out from it, saw the sky past the soffit's
// edge in directions the soffit blocks (its top quarter-texel 24 % bright
// with every albedo 0). Cycles skips its rays' own primitives the same way
// (since Blender 3.2). Points are inset into their triangles (1e-5 of the
// way), so a ray cannot meet the coplanar neighbour at its start.
struct SkipContext {
    RTCIntersectContext context;  // first: Embree's filter gets a pointer to it
    uint32_t skip[2] = {kNoTriangle, kNoTriangle};
    explicit SkipContext(uint32_t first = kNoTriangle, uint32_t second = kNoTriangle);
};

// The nearest hit from `origin` along `dir` (tnear 0, no tfar), past the
// skipped triangles; false: none.
bool intersectRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, RTCRayHit& rh,
                  uint32_t skip = kNoTriangle);

// Whether anything but the skipped triangles lies on the segment [0, tfar] of the ray.
bool occludedRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, float tfar,
                 const SkipContext& skip);

}  // namespace bb
