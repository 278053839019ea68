// Point and spot lights (KHR_lights_punctual), the spec's recommended
// falloff: step for step as engine/scene/punctual_light.h (which states the formulas).
uniform vec3 lightPosition;     // local space (world - the scene's origin)
uniform vec3 lightIntensity;    // candela / the light-map state's radiance unit
uniform float lightRange;       // > 0: the smooth window; 0: infinite
uniform bool lightIsSpot;
uniform vec3 spotDirection;     // unit, the way the cone points
uniform float spotCosOuter;
uniform float spotScale;        // 1 / max(0.001, cos(inner) - cos(outer))

float punctualAttenuation(float d, vec3 toX) {
    float a = 1.0;
    if (lightRange > 0.0) {
        float r = d / lightRange;
        a = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    if (lightIsSpot) {
        float t = clamp((dot(spotDirection, toX) - spotCosOuter) * spotScale, 0.0, 1.0);
        a *= t * t;
    }
    return a;
}

// Irradiance at x (unit normal n), unoccluded.
vec3 punctualIrradiance(vec3 x, vec3 n) {
    vec3 toLight = lightPosition - x;
    float d2 = dot(toLight, toLight);
    if (!(d2 > 0.0)) return vec3(0.0);
    float d = sqrt(d2);
    float c = dot(n, toLight) / d;
    if (c <= 0.0) return vec3(0.0);
    return lightIntensity * (c / d2 * punctualAttenuation(d, -toLight / d));
}
