// Points and triangles in a plane (a light-map page's texels, a leaf's
// pixel grid). Included by lib/curved_footprint.glsl and bundle/append.frag.

// Twice triangle (a, b, d)'s signed area.
float doubleArea(vec2 a, vec2 b, vec2 d) { return (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x); }

// Whether point p lies on triangle (a, b, d) (its edges count; every p where
// it has no area).
bool triangleHolds(vec2 a, vec2 b, vec2 d, vec2 p) {
    float area = doubleArea(a, b, d);
    vec3 w = vec3((d.x - b.x) * (p.y - b.y) - (d.y - b.y) * (p.x - b.x),
                  (a.x - d.x) * (p.y - d.y) - (a.y - d.y) * (p.x - d.x),
                  (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x));
    return all(greaterThanEqual(w * sign(area), vec3(0.0)));
}

// Where along segment [a, b] (0 at a, 1 at b) its point nearest p lies.
float segmentParameter(vec2 a, vec2 b, vec2 p) {
    vec2 e = b - a;
    return clamp(dot(p - a, e) / max(dot(e, e), 1e-30), 0.0, 1.0);
}

// The point of segment [a, b] nearest p.
vec2 nearestOnSegment(vec2 a, vec2 b, vec2 p) { return a + (b - a) * segmentParameter(a, b, p); }

// The point of triangle (a, b, d) nearest p (p where the triangle holds it).
vec2 nearestOnTriangle(vec2 a, vec2 b, vec2 d, vec2 p) {
    if (triangleHolds(a, b, d, p)) return p;
    vec2 best = nearestOnSegment(a, b, p);
    vec2 other = nearestOnSegment(b, d, p);
    if (distance(other, p) < distance(best, p)) best = other;
    other = nearestOnSegment(d, a, p);
    return distance(other, p) < distance(best, p) ? other : best;
}
