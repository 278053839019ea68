// The scene's transport albedo: the share of its reflected light that comes
// back to its surfaces each bounce, once the light has spread over them (the
// dominant eigenvalue of the light transport, per colour channel, the largest
// of the three). The bake's history ramp and refresh rounds follow it: how
// many bounces the light needs before what is left is negligible is
// log(1e-3) / log(lambda) (Baker::Impl::init).
//
// In a closed room of one albedo rho it is rho (every ray from a surface
// meets a surface); open to a sky, light escapes at every bounce, and the
// largest albedo alone overstated it: mixed_lighting's red velvet (rho 0.995
// in red) set the ramp's power to 1024 (only the last directions counted)
// for a room whose light leaves through its windows, and the generated city
// (rho 0.62, power 5) counts a third of its directions' samples for light
// that mostly escapes to the sky after one bounce.
//
// Estimated by paths: from points spread by area over the scene, cosine rays
// over the side the shading normal faces, k bounces; E_k is the mean of the
// albedos' product along paths whose k rays all meet a front side (a single-
// sided surface's back absorbs, as in the bake), and lambda = E_5 / E_4 (the
// first bounces' ratios still hold the start's shape). Exact in a closed room
// of one albedo; 0 where no ray from a surface meets another. Deterministic
// (fixed seed, single-threaded Embree build and queries). GL-free.
#pragma once

#include <vector>

#include "layout/bake_mesh.h"

namespace bb {

struct TransportAlbedo {
    double lambda = 0.0;  // E_5 / E_4, in [0, 1)
    // E_24 / E_23 (at least lambda): the paths still bouncing by then are
    // those a pocket of the scene keeps (the shared Cornell box's 0.9 mm gap
    // between its light panel and the ceiling), whose light settles slowest
    double slowest = 0.0;
};

// `albedo`: per material, the linear RGB albedo (times its texture's mean);
// `doubleSided`: per material.
TransportAlbedo transportAlbedo(const BakeMesh& mesh, const std::vector<glm::vec3>& albedo,
                                const std::vector<bool>& doubleSided, int paths = 16384);

}  // namespace bb
