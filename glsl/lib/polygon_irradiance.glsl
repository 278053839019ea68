// Irradiance from a uniform Lambertian polygon (Lambert 1760; Baum,
// Rushmeier & Winget 1989): E(x) = (L / 2) |sum_i theta_i (n . u_i)|, after
// clipping the polygon to the hemisphere above x. Returns E / (pi L): the
// point-to-polygon form factor, so L_lm += L * formFactor.

// Clips triangle (a, b, c) to the half-space dot(n, p - x) >= 0; writes up to 4 vertices.
int clipToHemisphere(vec3 x, vec3 n, vec3 a, vec3 b, vec3 c, out vec3 poly[4]) {
    vec3 v[3] = vec3[3](a, b, c);
    float d[3] = float[3](dot(n, a - x), dot(n, b - x), dot(n, c - x));
    int count = 0;
    for (int i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        if (d[i] >= 0.0 && count < 4) poly[count++] = v[i];
        if ((d[i] >= 0.0) != (d[j] >= 0.0) && count < 4) {
            float t = d[i] / (d[i] - d[j]);
            poly[count++] = mix(v[i], v[j], t);
        }
    }
    return count;
}

float polygonFormFactor(vec3 x, vec3 n, vec3 a, vec3 b, vec3 c) {
    vec3 poly[4];
    int count = clipToHemisphere(x, n, a, b, c, poly);
    if (count < 3) return 0.0;
    float sum = 0.0;
    for (int i = 0; i < count; ++i) {
        vec3 ri = normalize(poly[i] - x);
        vec3 rj = normalize(poly[(i + 1) % count] - x);
        vec3 cr = cross(ri, rj);
        float len = length(cr);
        if (len < 1e-12) continue;
        float theta = acos(clamp(dot(ri, rj), -1.0, 1.0));
        sum += theta * dot(n, cr / len);
    }
    return abs(sum) / (2.0 * 3.14159265358979);
}
