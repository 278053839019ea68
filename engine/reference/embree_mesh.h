// The bake mesh as Embree sees it, for the CPU's rays: the reference baker's
// paths and the transport albedo's (bake/transport_albedo.h).
#pragma once

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "layout/bake_mesh.h"

namespace bb {

// A committed scene of one triangle geometry, triangle i of `mesh` as
// primitive i, robust (watertight: no leaks through shared edges); nullptr if
// Embree fails (the device's error function says why).
RTCScene commitBakeMeshScene(RTCDevice device, const BakeMesh& mesh, RTCBuildQuality quality);

// How far a ray starts off its surface: a few hundred float ulps at the
// mesh's largest (local) coordinate or its diagonal, whichever is larger.
float rayOffset(const BakeMesh& mesh);

// The nearest hit from `origin` along `dir` (tnear 0, no tfar); false: none.
bool intersectRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, RTCRayHit& rh);

}  // namespace bb
