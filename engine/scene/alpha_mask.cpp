#include "scene/alpha_mask.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/check.h"

namespace bb {
namespace {

uint8_t alphaByte(float a) { return uint8_t(std::lround(std::clamp(a, 0.0f, 1.0f) * 255.0f)); }

float alphaTexel(const Texture& t, int x, int y) {
    return float(alphaByte(t.texels[size_t(y) * size_t(t.width) + size_t(x)].a)) / 255.0f;
}

}  // namespace

AlphaMaskTables packAlphaMasks(const std::vector<Material>& materials, const std::vector<Texture>& textures) {
    AlphaMaskTables out;
    std::vector<uint8_t> bytes;
    std::map<int, uint32_t> offsets;  // texture -> first byte
    for (const Material& m : materials) {
        shared::MaterialAlpha a{float(ALPHA_OPAQUE), 1.0f, ALPHA_NO_TEXTURE, 0u};
        if (m.alphaMask) {
            out.anyMask = true;
            a.cutoff = std::max(m.alphaCutoff, 0.0f);
            a.factor = m.alpha;
            const int ti = m.albedoTexture;
            if (ti >= 0 && size_t(ti) < textures.size() && textures[size_t(ti)].width > 0 &&
                textures[size_t(ti)].height > 0) {
                const Texture& t = textures[size_t(ti)];
                CHECK_LE(t.width, 65535);
                CHECK_LE(t.height, 65535);
                auto it = offsets.find(ti);
                if (it == offsets.end()) {
                    it = offsets.emplace(ti, uint32_t(bytes.size())).first;
                    for (const glm::vec4& texel : t.texels) bytes.push_back(alphaByte(texel.a));
                }
                a.texelOffset = it->second;
                a.size = uint32_t(t.width) | (uint32_t(t.height) << 16);
            }
        }
        out.materials.push_back(a);
    }
    if (out.materials.empty()) out.materials.push_back({float(ALPHA_OPAQUE), 1.0f, ALPHA_NO_TEXTURE, 0u});
    out.texels.assign(std::max<size_t>(1, (bytes.size() + 3) / 4), 0u);
    for (size_t b = 0; b < bytes.size(); ++b) out.texels[b / 4] |= uint32_t(bytes[b]) << (8 * (b % 4));
    return out;
}

float materialAlpha(const Material& m, const std::vector<Texture>& textures, glm::vec2 uv) {
    const int ti = m.albedoTexture;
    if (ti < 0 || size_t(ti) >= textures.size() || textures[size_t(ti)].width <= 0 || textures[size_t(ti)].height <= 0)
        return m.alpha;
    const Texture& t = textures[size_t(ti)];
    const int w = t.width, h = t.height;
    const float x = uv.x * float(w) - 0.5f, y = uv.y * float(h) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y)) return m.alpha * alphaTexel(t, 0, 0);
    const float fx0 = std::floor(x), fy0 = std::floor(y);
    const float fx = x - fx0, fy = y - fy0;
    int x0 = int(fx0 - float(w) * std::floor(fx0 / float(w))), y0 = int(fy0 - float(h) * std::floor(fy0 / float(h)));
    x0 = std::clamp(x0, 0, w - 1);
    y0 = std::clamp(y0, 0, h - 1);
    const int x1 = x0 + 1 == w ? 0 : x0 + 1, y1 = y0 + 1 == h ? 0 : y0 + 1;
    auto mix = [](float a, float b, float f) { return a * (1.0f - f) + b * f; };
    const float a = mix(mix(alphaTexel(t, x0, y0), alphaTexel(t, x1, y0), fx),
                        mix(alphaTexel(t, x0, y1), alphaTexel(t, x1, y1), fx), fy);
    return m.alpha * a;
}

bool alphaCut(const Material& m, const std::vector<Texture>& textures, glm::vec2 uv) {
    return m.alphaMask && materialAlpha(m, textures, uv) < std::max(m.alphaCutoff, 0.0f);
}

}  // namespace bb
