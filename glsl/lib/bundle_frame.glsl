// The bundle's orthographic frame: direction d (rays travel along +d), plane
// axes u, v (u x v = d). The bundle plane's root square [rootOrigin,
// rootOrigin + rootSize]^2 is cut into leaves (engine/tiler/tiler.h); a leaf
// is one pixel grid of leafPixels^2 pixels over [leafMin, leafMin +
// leafExtent]^2 in root units, and a tile is an integer window of that grid.
// Every tile computes a point's root coordinates with the same float
// operations and leaf bounds are exact in float (powers of 1/2), so a point
// belongs to exactly one leaf and, within it, one tile: no texel's sample is
// taken by two tiles, or by none. A tile also draws a one-pixel apron of its
// neighbours' pixels (within the leaf), whose lists its samples may read.
uniform vec3 bundleDir;
uniform vec3 bundleU;
uniform vec3 bundleV;
uniform vec2 rootOrigin;     // (u, v) of the root square's lower-left corner, scene units
uniform float rootSize;      // the root square's side, scene units
// The leaf's and the tile's parameters: uniforms, or (LEAF_TABLE: one update
// over a run of leaves, lightmap/update.frag) set per fragment
// from the leaf that holds its texel.
#ifdef LEAF_TABLE
#define LEAF_PARAM
#else
#define LEAF_PARAM uniform
#endif
LEAF_PARAM vec2 leafMin;        // the leaf's lower-left corner, root units
LEAF_PARAM float leafExtent;    // the leaf's side, root units
LEAF_PARAM int leafPixels;      // pixels across the leaf
LEAF_PARAM float pixelSize;     // scene units per pixel of this leaf
LEAF_PARAM ivec2 tileOffset;    // head image pixel p is the leaf grid's pixel p + tileOffset
LEAF_PARAM ivec4 drawnPixels;   // the pixels the tile draws in the head image: [xy, zw) (its own and a one-pixel apron within the leaf)
LEAF_PARAM ivec4 ownedPixels;   // the tile's own pixels in the head image: [xy, zw)

// Whether head-image pixel p is the tile's own, or drawn at all (own or apron).
bool ownedPixel(ivec2 p) { return all(greaterThanEqual(p, ownedPixels.xy)) && all(lessThan(p, ownedPixels.zw)); }
bool drawnPixel(ivec2 p) { return all(greaterThanEqual(p, drawnPixels.xy)) && all(lessThan(p, drawnPixels.zw)); }

vec3 bundleFromWorld(vec3 p) { return vec3(dot(p, bundleU), dot(p, bundleV), dot(p, bundleDir)); }

// Root units: [0, 1]^2 spans the root square.
vec2 rootFromBundle(vec2 uv) { return (uv - rootOrigin) / rootSize; }
// Whether q lies in the square [lo, lo + extent)^2 (root units): the one test
// of a leaf's bounds, for a tile's uniforms and a run's table alike.
bool inSquare(vec2 q, vec2 lo, float extent) { return all(greaterThanEqual(q, lo)) && all(lessThan(q, lo + vec2(extent))); }
bool leafOwns(vec2 q) { return inSquare(q, leafMin, leafExtent); }
// Position in the leaf's pixels (continuous).
vec2 gridFromRoot(vec2 q) { return (q - leafMin) * (float(leafPixels) / leafExtent); }
