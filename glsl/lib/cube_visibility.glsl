// Visibility of a light point from a surface point x in the light's distance
// cube map (direct/distance.frag: per cube texel, the distance to the nearest
// surface along the texel's centre ray, and that surface's plane).
//
// A nearest lookup reads the surface along the texel's centre ray, not along
// the ray to x. So x is occluded only where both of these say so:
// - the receiver's plane: something lies nearer along the centre ray than
//   where that ray meets x's own plane (receiver plane depth). Compared with
//   x's own distance instead, the receiver's own surface reads nearer than x
//   wherever it is seen at a slant (acne: the block sides a light above
//   lights at a grazing angle read 10-20 % dark on the Cornell box); pushing
//   x off its surface along the normal moved the test point beside walls and
//   shadowed it where they met another surface (penumbrae 20-40 % dark at the
//   tall block's foot).
// - the occluder's plane: the stored surface's plane crosses x's own ray
//   before x. At a concave contact (a block's face standing on the floor) the
//   centre ray meets the floor in front of the face, but the ray to a point
//   of the face does not reach the floor's plane before it: by the receiver's
//   plane alone the blocks' bottom rows read 15 % dark in their direct light.
// With both, acne needs no tolerance but float precision's: the comparisons
// take 2.5 % of a bundle pixel. Half a bundle pixel (until 2026-12-02) let
// the direct light through a 2 cm slab onto the texels of the room behind it
// that lie within a few centimetres of the slab (two rooms at 64^2, 14 cm
// texels: 4 % of the lit room's floor on the sealed room's floor beside it).
layout(binding = 0) uniform usamplerCube distances;  // (distance's bits, octahedral plane normal as 2 x snorm16)
uniform float rayOffset;  // scene units: half a bundle pixel
uniform int cubeSize;     // texels per face side
uniform mat3 cubeFromWorld;  // the cube's orientation (a rotation; emitter samples turn theirs at random)

// A unit vector from its octahedral encoding (direct/distance.frag), either way along it.
vec3 octahedralDecode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return normalize(n);
}

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

// Where `centreRay` (a unit direction from the light) meets the plane through
// x (fromLight = x - light) with normal planeNormal; 0 or less: it does not.
float planeCrossing(vec3 centreRay, vec3 planeNormal, vec3 fromLight) {
    float approach = dot(planeNormal, centreRay);
    return abs(approach) > 1e-4 * length(planeNormal) ? dot(planeNormal, fromLight) / approach : -1.0;
}

// planeNormal: x's surface (its facet's normal, on the light's side or not).
bool occludedFromLight(vec3 x, vec3 planeNormal, vec3 lightPoint) {
    vec3 fromLight = x - lightPoint;
    float dist = length(fromLight);
    float tolerance = 0.05 * rayOffset + 1e-5 * dist;
    // where the centre ray meets x's plane: x's own surface along that ray.
    // Past x, within one bundle pixel of x's own distance: at a grazing angle
    // it meets the plane far beyond x, past a partition that would pass for
    // an occluder. Before x by more than that, a surface in x's plane on the
    // light's side of a wall between them (the next room's floor) would pass
    // for x's own, and the wall go unseen: the texel one step shallower to
    // the plane is read instead, whose centre ray passes x before it meets
    // the plane, and meets the wall if there is one. (Counting any surface
    // met before x as an occluder shadowed a ceiling 1/16 texel over a
    // light from the light's points that see it at a grazing angle: the
    // texels along the light's outline up to 4 % dark at 128 samples.)
    vec3 look = fromLight;
    vec3 centreRay = transpose(cubeFromWorld) * cubeTexelCentre(cubeFromWorld * look);
    float t = planeCrossing(centreRay, planeNormal, fromLight);
    if (t > 0.0 && t < dist - 2.0 * rayOffset) {
        vec3 towardLight = dot(planeNormal, fromLight) < 0.0 ? planeNormal : -planeNormal;
        look = fromLight / dist + normalize(towardLight) * (2.0 / float(cubeSize));
        centreRay = transpose(cubeFromWorld) * cubeTexelCentre(cubeFromWorld * look);
        t = planeCrossing(centreRay, planeNormal, fromLight);
    }
    float receiver = t > 0.0 ? min(t, dist + 2.0 * rayOffset) : dist;
    uvec2 texel = texture(distances, cubeFromWorld * look).rg;
    float stored = uintBitsToFloat(texel.r);
    if (stored >= receiver - tolerance) return false;
    // where x's own ray meets the stored surface's plane; a plane the light
    // sees within 6 degrees of edge-on gives no precise crossing (mostly the
    // receiver's own surface, at a grazing light): the receiver's test then,
    // with the tolerance of half a bundle pixel
    vec3 occluderNormal = octahedralDecode(unpackSnorm2x16(texel.g));
    float across = dot(occluderNormal, fromLight) / dist;
    if (abs(across) < 0.1) return stored < receiver - rayOffset;
    float crossing = dot(occluderNormal, centreRay * stored) / across;
    return crossing > 0.0 && crossing < dist - tolerance;
}
