// Light map seams: mesh edges where two charts (or two sides of one chart)
// meet, found on the bake mesh, with pairs of sample points along each edge
// in both sides' page space. bake/seam_stitch.h makes the light map agree at
// those pairs, so a render shows no line along UV seams.
//
// Based on: M. Iwanicki, "Lighting Technology of The Last of Us", SIGGRAPH
// 2013 Advances course (seams as pairs of samples along edges mapped to
// disjoint light map regions), as ands' seamoptimizer
// (github.com/ands/seamoptimizer) and Godot's lightmapper find them: edges
// with equal positions and different texture coordinates, sampled along
// their length on both sides.
//
// A seam is an edge shared by exactly two triangles of one instance (vertices
// welded by their positions' exact bits, as uv_generate.cpp welds them),
// whose two page-space segments differ by more than 1e-3 texel at either end,
// whose shading normals agree at both ends (dot >= cosNormalThreshold), and
// whose triangles' face normals agree (dot >= cosFaceThreshold). A
// hard edge (normals split, as a cube's) is not a seam: the light really
// differs across it, and stitching would blur a true edge.
//
// GL-free, deterministic (the same mesh gives the same bytes). O(n log n) in
// the mesh's vertices (a sort); about 0.3 s per million triangles on one core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "layout/bake_mesh.h"

namespace bb {

struct SeamOptions {
    // Both ends' shading normals must agree this well on the two sides (cosine;
    // typ. 0.99..0.9999): otherwise the edge is hard and the light may differ.
    float cosNormalThreshold = 0.99f;
    // ... and the two triangles' face normals this well (cosine; typ. 0.866 =
    // 30 degrees: a sphere or cylinder of 12 or more segments). Bevels and
    // rims shaded smooth across 45 degrees or more face another way and are
    // lit another way: living_room's 1 cm lamp rims (a 0.2-texel band at 512
    // texels, 45-degree chamfer) differ by 0.3..0.45 in L_lm across such
    // edges, 4x the mean; stitching them would only smear the rim's light.
    float cosFaceThreshold = 0.866f;
    // Sample pairs per texel of edge length (the longer side's), at least 2 an
    // edge (typ. 2..4: bilinear lookups between them see the same texels).
    float samplesPerTexel = 3.0f;
};

// One sample point of a seam, seen from both sides. Texel coordinates: texel
// (i, j) of a page covers [i, i+1] x [j, j+1] (its centre at + 0.5), row 0 =
// v 0, i.e. page uv x resolution; bilinear filtering as GL_LINEAR does.
struct SeamSamplePair {
    uint32_t seam = 0;           // which seam edge (0 .. Seams::seamEdges - 1)
    uint32_t pageA = 0, pageB = 0;
    glm::vec2 texelA{0.0f}, texelB{0.0f};
};

struct Seams {
    size_t seamEdges = 0;        // smooth edges whose two sides differ in page space
    size_t hardEdges = 0;        // edges whose sides differ in page space and in normal (shading or face): left alone
    size_t nonManifoldEdges = 0; // welded edges with more than two triangles: left alone
    // Sample points where a side's bilinear lookup taps no texel owned by its
    // chart, or one owned by another chart, are left out: a chart a fraction
    // of a texel wide there (the bench city's sills and parapet tops) has no
    // texel of its own for the two sides to agree on (docs/design-notes.md).
    size_t narrowPairs = 0;
    std::vector<SeamSamplePair> samples;  // seam by seam, in triangle order
    // Per page that a seam is on, per texel the part of its square
    // on its chart in 255ths (texelFootprints' area; 0 off the charts); empty
    // for the other pages (whole squares, as for seams made by hand). The
    // stitch weighs texels by it (seam_stitch.h), so a bake and the
    // reference, whose maps carry no such record, stitch alike.
    std::vector<std::vector<uint8_t>> texelArea;
};

// The seams of `mesh` laid out on pages of `resolution` texels.
// Precondition: resolution >= 1; mesh as buildBakeMesh leaves it.
Seams findSeams(const BakeMesh& mesh, int resolution, const SeamOptions& options = {});

}  // namespace bb
