#include "bake/supersample.h"

namespace bb {

Layout supersampledLayout(const Layout& layout, int k) {
    Layout out = layout;
    out.resolution *= k;
    out.padding *= k;
    out.texelDensity *= float(k);
    for (InstanceRect& r : out.rects) {
        r.x *= k;
        r.y *= k;
        r.width *= k;
        r.height *= k;
        r.texelDensity *= float(k);
    }
    return out;
}

TexelQuarters texelQuarters(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res) {
    TexelQuarters out;
    out.owner = texelOwners(mesh, page, res);
    const std::vector<TexelFootprint> footprints = texelFootprints(mesh, page, res, out.owner, charts);
    const std::vector<int32_t> fineOwner = halfTexelOwners(mesh, charts, page, res);
    const size_t perPage = size_t(res) * res;
    out.area.resize(perPage);
    out.weights.assign(perPage, glm::vec4(0.0f));
    for (size_t i = 0; i < perPage; ++i) {
        if (out.owner[i] < 0) continue;
        const int x = int(i % size_t(res)), y = int(i / size_t(res));
        out.area[i] = footprints[i].area;
        for (int q = 0; q < 4; ++q) {
            const int32_t o = fineOwner[size_t(2 * y + q / 2) * size_t(2 * res) + size_t(2 * x + q % 2)];
            if (o >= 0 && charts[size_t(o)] == charts[size_t(out.owner[i])])
                out.weights[i][q] = float(footprints[i].quarters[size_t(q)]);
        }
    }
    return out;
}

LightmapPages reduceLightmaps(const LightmapPages& fine, const BakeMesh& mesh, const std::vector<uint32_t>& charts,
                              const Layout& layout) {
    const int res = layout.resolution, fineRes = fine.resolution;
    const size_t perPage = size_t(res) * res;
    LightmapPages out;
    out.resolution = res;
    std::vector<std::pair<size_t, glm::vec4>> fill;
    for (int p = 0; p < layout.pageCount; ++p) {
        const TexelQuarters quarters = texelQuarters(mesh, charts, p, res);
        const std::vector<int32_t>& owner = quarters.owner;
        const io::ImageRgb& from = fine.pages[size_t(p)];
        std::vector<glm::vec4> map(perPage, glm::vec4(0.0f));
        std::vector<uint8_t> covered(perPage), area = quarters.area;
        for (size_t i = 0; i < perPage; ++i) {
            const int x = int(i % size_t(res)), y = int(i / size_t(res));
            if (owner[i] < 0) continue;
            glm::dvec3 sum(0.0);
            double weight = 0.0;
            for (int q = 0; q < 4; ++q) {
                const size_t j = size_t(2 * y + q / 2) * size_t(fineRes) + size_t(2 * x + q % 2);
                const double w = quarters.weights[i][q];
                if (w == 0.0 || !fine.covered[size_t(p)][j]) continue;
                sum += glm::dvec3(from.pixels[j]) * w;
                weight += w;
            }
            covered[i] = 1;
            if (weight > 0.0) map[i] = glm::vec4(glm::vec3(sum / weight), 1.0f);
        }
        // texels with no half-size texel of their own: their chart's neighbours' mean, else padding
        for (size_t i = 0; i < perPage; ++i) {
            if (!covered[i] || map[i].w > 0.0f) continue;
            const int x = int(i % size_t(res)), y = int(i / size_t(res));
            glm::vec3 sum(0.0f);
            float n = 0.0f;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= res || qy >= res) continue;
                    const size_t j = size_t(qy) * size_t(res) + size_t(qx);
                    if (map[j].w > 0.0f && covered[j] && charts[size_t(owner[j])] == charts[size_t(owner[i])]) {
                        sum += glm::vec3(map[j]);
                        n += 1.0f;
                    }
                }
            if (n == 0.0f) continue;
            fill.push_back({i, glm::vec4(sum / n, 1.0f)});
            ++out.filledTexels;
        }
        for (const auto& [i, value] : fill) map[i] = value;
        for (size_t i = 0; i < perPage; ++i)
            if (covered[i] && map[i].w == 0.0f) {
                covered[i] = 0;
                area[i] = 0;
                ++out.lostTexels;
            }
        fill.clear();
        out.pages.push_back(dilatedImage(std::move(map), res, layout.padding + 1));
        out.covered.push_back(std::move(covered));
        out.area.push_back(std::move(area));
    }
    return out;
}

io::ImageRgb dilatedImage(std::vector<glm::vec4> map, int res, int passes) {
    for (int pass = 0; pass < passes; ++pass) {
        std::vector<glm::vec4> next = map;
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                if (map[size_t(y) * res + x].w > 0.0f) continue;
                glm::vec3 sum(0.0f);
                float count = 0.0f;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int qx = x + dx, qy = y + dy;
                        if (qx < 0 || qy < 0 || qx >= res || qy >= res) continue;
                        const glm::vec4& s = map[size_t(qy) * res + qx];
                        if (s.w > 0.0f) {
                            sum += glm::vec3(s);
                            count += 1.0f;
                        }
                    }
                if (count > 0.0f) next[size_t(y) * res + x] = glm::vec4(sum / count, 1.0f);
            }
        map.swap(next);
    }
    io::ImageRgb img;
    img.width = img.height = res;
    img.pixels.resize(map.size());
    for (size_t k = 0; k < map.size(); ++k) img.pixels[k] = glm::vec3(map[k]);
    return img;
}

}  // namespace bb
