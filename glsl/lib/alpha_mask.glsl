// Cut-outs (glTF alphaMode MASK): is a material's surface there at TEXCOORD_0
// uv? Alpha = factor x the mask texture (bilinear, repeating, level 0, 8-bit
// texels; row 0 = v 0 as GL samples the uploaded image), compared with the
// cutoff. Step for step as materialAlpha() in engine/scene/alpha_mask.cpp.
// Needs shared/material_layout.h.
layout(std430, binding = BINDING_MATERIAL_ALPHA) readonly buffer MaterialAlphas { MaterialAlpha materialAlphas[]; };
layout(std430, binding = BINDING_ALPHA_TEXELS) readonly buffer AlphaTexels { uint alphaTexels[]; };

float alphaTexel(uint offset, int width, int x, int y) {
    uint b = offset + uint(y * width + x);
    return float((alphaTexels[b >> 2u] >> ((b & 3u) * 8u)) & 255u) / 255.0;
}

float materialAlpha(uint material, vec2 uv) {
    MaterialAlpha m = materialAlphas[material];
    if (m.texelOffset == ALPHA_NO_TEXTURE) return m.factor;
    int w = int(m.size & 65535u), h = int(m.size >> 16u);
    float x = uv.x * float(w) - 0.5, y = uv.y * float(h) - 0.5;
    float fx0 = floor(x), fy0 = floor(y);
    float fx = x - fx0, fy = y - fy0;
    // repeat (glTF's default wrap): floor-mod, as the reference's textures
    int x0 = int(fx0 - float(w) * floor(fx0 / float(w))), y0 = int(fy0 - float(h) * floor(fy0 / float(h)));
    x0 = min(x0, w - 1);
    y0 = min(y0, h - 1);
    int x1 = x0 + 1 == w ? 0 : x0 + 1, y1 = y0 + 1 == h ? 0 : y0 + 1;
    float a = mix(mix(alphaTexel(m.texelOffset, w, x0, y0), alphaTexel(m.texelOffset, w, x1, y0), fx),
                  mix(alphaTexel(m.texelOffset, w, x0, y1), alphaTexel(m.texelOffset, w, x1, y1), fx), fy);
    return m.factor * a;
}

// True where the surface is cut away (no fragment, no shadow, no texel).
bool alphaCut(uint material, vec2 uv) {
    float cutoff = materialAlphas[material].cutoff;
    return cutoff >= 0.0 && materialAlpha(material, uv) < cutoff;
}
