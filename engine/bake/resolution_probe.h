// The resolution probe's estimate from its sums (resolution_probe.cpp), apart
// from GL so that its arithmetic can be tested on its own.
#pragma once

#include <span>

#include <glm/vec3.hpp>

namespace bb {

// One sampled texel's changes in the probe: the first step (the output
// layout's reads less the baked texels') and the second (texels of twice the
// output's side less the output's), each from the even and from the odd probe
// directions, in radiance.
struct ProbeSteps {
    glm::dvec3 firstEven{0.0}, firstOdd{0.0}, secondEven{0.0}, secondOdd{0.0};
};

struct ResolutionBias {
    double meanSquare = 0;  // the baked reads' bias, mean square a channel over every texel, radiance^2
    double order = 0;       // p in b(h) = c h^p, over the texels in range, weighted by their bias; 0: none
    double pastRange = 0;   // the share of the first step's change in texels past Richardson's range
};

// Richardson's extrapolation, texel by texel: for a bias c h^p the first step
// is b (k^p - 1) and the second k^p (2^p - 1) / (k^p - 1) times it (k the
// supersampling), p held to [1, 2]. A texel whose second step changes less
// than its first is past the range: the output's texels lose its light's
// detail outright, and the coarser steps say nothing of the baked texels'
// error. Each half's steps decide its texel's range and order and the other
// half's enter the product, so where there is no bias the sum stays noise
// about 0, shrunk by its own variance.
ResolutionBias richardsonBias(std::span<const ProbeSteps> texels, int k);

}  // namespace bb
