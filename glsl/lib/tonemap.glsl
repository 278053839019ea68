// Display transform of bundlebake's images, the same curve as
// io::writePngToneMapped (engine/io/image_io.cpp): radiance x 2^exposure,
// ACES fit (Narkowicz 2015), sRGB encoding (IEC 61966-2-1).

// Narkowicz 2015: a fit of the ACES RRT+ODT, input pre-exposed, output [0,1].
vec3 acesFitted(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// linear [0,1] -> sRGB-encoded [0,1]
vec3 srgbOetf(vec3 linear) {
    vec3 lo = 12.92 * linear;
    vec3 hi = 1.055 * pow(linear, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(linear, vec3(0.0031308)));
}

// Negative and NaN radiance -> 0, as the CPU's sanitize(); +Inf saturates.
vec3 toneMap(vec3 radiance, float exposureScale) {
    vec3 x = max(radiance, vec3(0.0));
    x = mix(vec3(0.0), x, equal(x, x));  // NaN -> 0
    return srgbOetf(acesFitted(min(x * exposureScale, vec3(1e30))));
}
