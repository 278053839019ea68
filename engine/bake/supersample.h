// Supersampled bakes (BakeOptions::supersample): the bake runs on the layout
// with 2 x 2 texels a texel (the same TEXCOORD_1, charts and pages; twice the
// resolution and padding) and its light maps are reduced to the layout's.
//
// A texel's value is the mean over its footprint, the part of its square on
// its chart (docs/design-notes.md "Texels partly on their chart"): the mean
// of its four half-size texels' values, each weighted by the part of the
// texel's footprint in its quarter (TexelFootprint::quarters). A quarter's
// texel that the fine bake leaves as padding (less than a quarter of it on
// the chart) holds its neighbours' dilated value, the nearest the fine bake
// has; a texel none of whose half-size texels was baked (a sliver a few
// hundredths of it wide) is padding. Coverage is otherwise the layout's own (texelOwners), and the padding is
// dilated again, as the GPU dilates it.
//
// Why: the bounced light a texel reads is its neighbours' means, and a mean
// over a texel is wrong by its curvature across it (the lintel over a window
// band, the strips a fifth of a texel across; "The city with its own UVs, by
// texel class"): half-size texels halve that, and four of them average their
// noise.
//
// GL-free.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "bake/baker.h"  // LightmapPages
#include "layout/bake_mesh.h"
#include "layout/layout.h"

namespace bb {

// The layout with every texel cut into k x k: resolution, padding, density
// and rectangles times k; the page UVs (rectangles' scale and offset) stay.
Layout supersampledLayout(const Layout& layout, int k);

// `fine`: the light maps of a bake on supersampledLayout(layout, 2), padding
// dilated; `mesh`: the bake's mesh (either layout's: page UVs are the same).
// Returns the light maps of `layout`, with `covered` and `area` by texelOwners
// and texelFootprints at its resolution.
LightmapPages reduceLightmaps(const LightmapPages& fine, const BakeMesh& mesh, const Layout& layout);

// Dilation: a texel without a value (w 0) takes the mean of its 8-neighbours
// with one (w 1), `passes` times. (The GPU's dilate.comp copies the nearest
// covered texel instead; both fill what bilinear filtering at chart borders reads.)
void dilate(std::vector<glm::vec4>& map, int res, int passes);

}  // namespace bb
