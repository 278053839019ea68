#version 430
in vec2 vUv0;

layout(location = 0) out vec4 outAlbedo;    // rgb albedo, a = 1 (covered)
layout(location = 1) out vec4 outEmission;  // rgb emitted radiance

layout(binding = 2) uniform sampler2D albedoTexture;
layout(binding = 3) uniform sampler2D emissionTexture;
uniform vec3 albedo;
uniform vec3 emission;
uniform bool hasAlbedoTexture;
uniform bool hasEmissionTexture;

void main() {
    vec3 a = albedo;
    if (hasAlbedoTexture) a *= texture(albedoTexture, vUv0).rgb;
    vec3 e = emission;
    if (hasEmissionTexture) e *= texture(emissionTexture, vUv0).rgb;
    outAlbedo = vec4(clamp(a, 0.0, 1.0), 1.0);
    outEmission = vec4(e, 1.0);
}
