// The bundle's orthographic frame: direction d (rays travel along +d), plane
// axes u, v (u x v = d), the tile's rectangle in (u, v) and its pixel grid.
uniform vec3 bundleDir;
uniform vec3 bundleU;
uniform vec3 bundleV;
uniform vec2 tileOrigin;     // (u, v) of the tile's lower-left corner, scene units
uniform float pixelSize;     // scene units per bundle pixel
uniform ivec2 tileSize;      // pixels

vec3 bundleFromWorld(vec3 p) { return vec3(dot(p, bundleU), dot(p, bundleV), dot(p, bundleDir)); }
