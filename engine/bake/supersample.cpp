#include "bake/supersample.h"

#include "core/check.h"
#include "core/parallel.h"

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

int autoSupersample(const BakeMesh& mesh, const std::vector<uint32_t>& charts, const Layout& layout, int64_t memoryBudget) {
    const int64_t bytesPerTexel = lightmapStateBytesPerTexel(hasBackSides(mesh));
    auto fits = [&](int k) {
        return int64_t(layout.texelCount()) * k * k * bytesPerTexel <= memoryBudget / 2 &&
               int64_t(layout.resolution) * k <= 16384;
    };
    if (!fits(2)) return 1;
    if (!fits(4)) return 2;
    int64_t covered = 0, cut = 0;
    for (int p = 0; p < layout.pageCount; ++p) {
        std::vector<uint8_t> partial;
        const std::vector<int32_t> owners = halfTexelOwners(mesh, charts, p, layout.resolution, &partial);
        for (size_t i = 0; i < owners.size(); ++i) {
            covered += owners[i] >= 0;
            cut += owners[i] >= 0 && partial[i];
        }
        cut += int64_t(sharedTexels(mesh, p, 2 * layout.resolution, owners, charts));
    }
    return cut * 5 >= covered ? 4 : 2;
}

namespace {
// A 4 x 4 bake's owners: halfTexelOwners at 2 res, each half-size texel's
// texel's owner (`coarse`, at res) standing for its own
std::vector<int32_t> quarterTexelOwners(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res,
                                        const std::vector<int32_t>& coarse, std::vector<uint8_t>* partial = nullptr) {
    std::vector<int32_t> up(size_t(4) * coarse.size());
    for (size_t i = 0; i < up.size(); ++i) up[i] = coarse[(i / size_t(2 * res)) / 2 * size_t(res) + (i % size_t(2 * res)) / 2];
    return halfTexelOwners(mesh, charts, page, 2 * res, partial, &up);
}
}  // namespace

std::vector<int32_t> fineTexelOwners(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res, int k,
                                     std::vector<uint8_t>* partial) {
    CHECK(k == 1 || k == 2 || k == 4);
    if (k == 1) return texelOwners(mesh, page, res, partial);
    if (k == 2) return halfTexelOwners(mesh, charts, page, res, partial);
    return quarterTexelOwners(mesh, charts, page, res, texelOwners(mesh, page, res), partial);
}

std::vector<float> fineTexelWeights(const BakeMesh& mesh, const std::vector<uint32_t>& charts, int page, int res, int k,
                                    const std::vector<int32_t>* owners) {
    CHECK(k == 2 || k == 4);
    const std::vector<int32_t> texels = owners ? *owners : texelOwners(mesh, page, res);
    const std::vector<int32_t> fine =
        k == 2 ? halfTexelOwners(mesh, charts, page, res) : quarterTexelOwners(mesh, charts, page, res, texels);
    const std::vector<TexelFootprint> footprints = texelFootprints(mesh, page, res, texels, charts);
    const int fineRes = k * res;
    std::vector<float> out(size_t(fineRes) * fineRes, 0.0f);
    for (int y = 0; y < fineRes; ++y)
        for (int x = 0; x < fineRes; ++x) {
            const size_t i = size_t(y / k) * size_t(res) + size_t(x / k), f = size_t(y) * size_t(fineRes) + size_t(x);
            if (texels[i] >= 0 && fine[f] >= 0 && charts[size_t(fine[f])] == charts[size_t(texels[i])])
                out[f] = float(footprints[i].part(k, x % k, y % k));
        }
    return out;
}

namespace {

// Page `page` of a bake k x k to a texel (`from`, k res a side, its coverage)
// to res: each texel its k x k texels' mean at `weights` (fineTexelWeights);
// texels with none their chart's covered neighbours' mean, else not covered
// (lost). Returns the values (w 1 where set).
std::vector<glm::vec4> reduceTexels(const io::ImageRgb& from, const std::vector<uint8_t>& fromCovered,
                                    const std::vector<float>& weights, const std::vector<int32_t>& owner,
                                    const std::vector<uint32_t>& charts, int res, int k, std::vector<uint8_t>& covered,
                                    LightmapPages& counts) {
    const size_t perPage = size_t(res) * res;
    std::vector<glm::vec4> map(perPage, glm::vec4(0.0f));
    covered.assign(perPage, 0);
    for (size_t i = 0; i < perPage; ++i) {
        const int x = int(i % size_t(res)), y = int(i / size_t(res));
        if (owner[i] < 0) continue;
        glm::dvec3 sum(0.0);
        double weight = 0.0;
        for (int fy = k * y; fy < k * y + k; ++fy)
            for (int fx = k * x; fx < k * x + k; ++fx) {
                const size_t j = size_t(fy) * size_t(from.width) + size_t(fx);
                const double w = weights[j];
                if (w == 0.0 || !fromCovered[j]) continue;
                sum += glm::dvec3(from.pixels[j]) * w;
                weight += w;
            }
        covered[i] = 1;
        if (weight > 0.0) map[i] = glm::vec4(glm::vec3(sum / weight), 1.0f);
    }
    // texels with no fine texel of their own: their chart's neighbours' mean, else padding
    std::vector<std::pair<size_t, glm::vec4>> fill;
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
        ++counts.filledTexels;
    }
    for (const auto& [i, value] : fill) map[i] = value;
    for (size_t i = 0; i < perPage; ++i)
        if (covered[i] && map[i].w == 0.0f) {
            covered[i] = 0;
            ++counts.lostTexels;
        }
    return map;
}

}  // namespace

LightmapPages reduceLightmaps(const LightmapPages& fine, const BakeMesh& mesh, const std::vector<uint32_t>& charts,
                              const Layout& layout) {
    const int res = layout.resolution, k = fine.resolution / res;
    CHECK(k == 2 || k == 4);
    LightmapPages out;
    out.resolution = res;
    out.pages.resize(size_t(layout.pageCount));
    out.covered.resize(size_t(layout.pageCount));
    std::vector<LightmapPages> pageCounts(size_t(layout.pageCount));  // each page's filled and lost texels
    parallelFor(size_t(layout.pageCount), [&](size_t pageIndex) {  // each page its own outputs
        const int p = int(pageIndex);
        const std::vector<int32_t> owner = texelOwners(mesh, p, res);
        std::vector<uint8_t> covered;
        std::vector<glm::vec4> map = reduceTexels(fine.pages[pageIndex], fine.covered[pageIndex],
                                                  fineTexelWeights(mesh, charts, p, res, k, &owner), owner, charts, res,
                                                  k, covered, pageCounts[pageIndex]);
        out.pages[pageIndex] = dilatedImage(std::move(map), res, layout.padding + 1);
        out.covered[pageIndex] = std::move(covered);
    });
    for (const LightmapPages& c : pageCounts) {
        out.filledTexels += c.filledTexels;
        out.lostTexels += c.lostTexels;
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
