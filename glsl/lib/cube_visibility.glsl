// Visibility of a light point from a surface point x in the light's distance
// cube map (direct/distance.frag: per cube texel, the distance to the nearest
// surface along the texel's centre ray).
//
// A nearest lookup reads the distance along the texel's centre ray, not along
// the ray to x. Compared with x's own distance, the receiver's own surface
// reads nearer than x wherever it is seen at a slant (acne: the block sides a
// light above lights at a grazing angle read 10-20 % dark on the Cornell box);
// pushing x off its surface along the normal instead moved the test point
// beside walls and shadowed it where they met another surface (penumbrae
// 20-40 % dark at the tall block's foot), and a slope-scaled tolerance let
// light through walls one texel thick. So the comparison is made along the
// texel's centre ray itself: x is occluded when something lies nearer than
// where that ray meets x's own plane (receiver plane depth, exact for a
// planar receiver), by more than rayOffset (scene units, along the ray).
layout(binding = 0) uniform samplerCube distances;
uniform float rayOffset;  // scene units
uniform int cubeSize;     // texels per face side
uniform mat3 cubeFromWorld;  // the cube's orientation (a rotation; emitter samples turn theirs at random)

// The centre ray of the cube texel a nearest lookup along w reads.
vec3 cubeTexelCentre(vec3 w) {
    vec3 a = abs(w);
    float major = max(a.x, max(a.y, a.z));
    vec3 q = w / major;  // the major component is +-1, the others in [-1, 1]
    vec3 snapped = (floor((q + 1.0) * 0.5 * float(cubeSize)) + 0.5) / float(cubeSize) * 2.0 - 1.0;
    snapped = clamp(snapped, -1.0 + 1.0 / float(cubeSize), 1.0 - 1.0 / float(cubeSize));
    if (a.x == major) return normalize(vec3(q.x, snapped.y, snapped.z));
    if (a.y == major) return normalize(vec3(snapped.x, q.y, snapped.z));
    return normalize(vec3(snapped.x, snapped.y, q.z));
}

// planeNormal: x's surface (its facet's normal, on the light's side or not).
bool occludedFromLight(vec3 x, vec3 planeNormal, vec3 lightPoint) {
    vec3 fromLight = x - lightPoint;
    float dist = length(fromLight);
    vec3 inCube = cubeFromWorld * fromLight;
    float stored = texture(distances, inCube).r;
    vec3 centreRay = transpose(cubeFromWorld) * cubeTexelCentre(inCube);
    // where the centre ray meets x's plane: x's own surface along that ray
    // (within one bundle pixel of x's own distance: at a grazing angle it
    // meets the plane far from x, where a coplanar wall on the other side of
    // a partition would pass for x's own)
    float approach = dot(planeNormal, centreRay);
    float receiver = dist;
    if (abs(approach) > 1e-4 * length(planeNormal)) {
        float t = dot(planeNormal, fromLight) / approach;
        if (t > 0.0) receiver = clamp(t, dist - 2.0 * rayOffset, dist + 2.0 * rayOffset);
    }
    return stored < receiver - rayOffset;
}
