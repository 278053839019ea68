// The bundle's orthographic frame: direction d (rays travel along +d), plane
// axes u, v (u x v = d), and one pixel grid over the whole bundle. A tile is
// an integer window of that grid, so every tile computes a point's pixel with
// the same float operations: no pixel is drawn or read by two tiles, or none.
uniform vec3 bundleDir;
uniform vec3 bundleU;
uniform vec3 bundleV;
uniform vec2 gridOrigin;     // (u, v) of the grid's pixel (0, 0) lower-left corner, scene units
uniform float pixelSize;     // scene units per bundle pixel
uniform int gridSize;        // pixels across the whole bundle
uniform ivec2 tileOffset;    // the tile's first pixel in the grid
uniform ivec2 tileSize;      // pixels

vec3 bundleFromWorld(vec3 p) { return vec3(dot(p, bundleU), dot(p, bundleV), dot(p, bundleDir)); }

// Position in grid pixels (continuous).
vec2 gridFromBundle(vec2 uv) { return (uv - gridOrigin) / pixelSize; }
