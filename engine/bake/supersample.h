// Supersampled bakes (BakeOptions::supersample): the bake runs on the layout
// with 2 x 2 texels a texel (the same TEXCOORD_1, charts and pages; twice the
// resolution and padding) and its light maps are reduced to the layout's.
//
// A texel's value is the mean over its footprint, the part of its square on
// its chart (docs/design-notes.md "Texels partly on their chart"): the mean
// of its four half-size texels' values, each weighted by the part of the
// texel's footprint in its quarter (TexelFootprint::part; at 4 x 4 its
// sixteen quarter-size texels', fineTexelWeights). Where charts
// share a texel (an asset's atlas packed tighter than its texels) the fine
// bake gives a half-size texel to the chart of the texel it lies in wherever
// that chart holds a sixteenth of its square (halfTexelOwners): the texel's
// whole footprint is baked on its chart. A quarter with less than that is
// left out, and a texel no quarter is left of (a sliver a few hundredths of
// it wide) takes its chart's covered neighbours' mean (LightmapPages::
// filledTexels), and without one is padding (lostTexels; the bake warns): the
// bench city's own atlas, whose generator packs strips several to a texel,
// has none of either (before halfTexelOwners 27 and 374 of 16442). Coverage
// is the layout's own (texelOwners, as the reference's), and the padding is
// dilated again (dilatedImage below).
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

// The light-map state's bytes a baked texel (Baker::Impl::init allocates
// them; the CLI bake test checks 65): 28 a page (direct light 8, footprint
// 16, owner's chart 2, dilation 1, same-chart neighbours 1) and 37 a layer
// (accumulator 8, radiance 4, read modes 1, moments 16, slopes 8), which a
// scene with double-sided triangles has twice (its back sides'). The curved
// texels' records come on top (a few percent of the texels).
constexpr int64_t lightmapStateBytesPerTexel(bool backSides) { return 28 + 37 * (backSides ? 2 : 1); }

// Whether the state has back sides' layers: any triangle is double-sided.
inline bool hasBackSides(const BakeMesh& mesh) { return mesh.anyTriangle(TRIANGLE_DOUBLE_SIDED); }

// BakeOptions::supersample auto: the k whose light-map state
// (lightmapStateBytesPerTexel) fits half the memory budget, 4 only where a fifth or more of
// the half-size texels are partial (a chart's edge cuts them off their
// centre) or shared with another chart; else 2 (and 1 where neither fits).
// Why (docs/design-notes.md "Quarter-size texels"): at 2 x 2 the bias of
// texels on strips and at chart edges is what is left on such layouts, and
// 4 x 4 cuts it by a third for about 3x the time; on layouts of wide charts
// (the Cornell box) the noise leads, and more directions buy more.
int autoSupersample(const BakeMesh& mesh, const std::vector<uint32_t>& charts, const Layout& layout, int64_t memoryBudget);

// The owners of a bake's texels k x k to a layout texel at resolution `res`
// (k res of them a side): texelOwners (k 1), halfTexelOwners (2), and at 4
// halfTexelOwners at 2 res with each half-size texel's texel's owner standing
// for its own: a texel's chart takes its parts of the quarter-size texels
// first, wherever a strip took the half-size texel they lie in (a strip a
// tenth of a texel wide ending at a wall, half of whose texel went to the
// strip beside it, read the other half's light alone: 25-30 % dark on the
// bench city).
std::vector<int32_t> fineTexelOwners(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res, int k,
                                     std::vector<uint8_t>* partial = nullptr);

// Per texel of a bake k x k to a layout texel (k res a side; k 2 or 4), its
// weight in its layout texel's value as reduceLightmaps composes it: the
// texel's footprint's points in it (TexelFootprint::part), 0 where the fine
// texel is another chart's. The noise estimate weighs the texels by them too
// (Baker::Impl::estimateNoise). `owners`: texelOwners at res, if at hand.
std::vector<float> fineTexelWeights(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res, int k,
                                    const std::vector<int32_t>* owners = nullptr);

// `fine`: the light maps of a bake on supersampledLayout(layout, k), k 2 or 4, padding
// dilated; `mesh`: the bake's mesh (either layout's: page UVs are the same);
// `charts`: its findLightmapCharts.
// Returns the light maps of `layout`, with `covered` by texelOwners at its
// resolution.
LightmapPages reduceLightmaps(const LightmapPages& fine, const BakeMesh& mesh, const std::vector<uint32_t>& charts,
                              const Layout& layout);

// Dilation: a texel without a value (w 0) takes the mean of its 8-neighbours
// with one (w 1), `passes` times; returns the map's rgb as an image. (The
// GPU's dilate.comp copies the nearest covered texel instead; both fill what
// bilinear filtering at chart borders reads.)
io::ImageRgb dilatedImage(std::vector<glm::vec4> map, int res, int passes);

}  // namespace bb
