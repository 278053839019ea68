// Synthetic bake meshes for the importance tests (unit and gl), built
// directly as BakeMesh: world positions and page-space light map UVs.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <numeric>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "layout/bake_mesh.h"

namespace bb::test {

// Collects triangles, then sorts them by page into a BakeMesh.
class MeshBuilder {
public:
    void add(const glm::vec3 p[3], const glm::vec2 uv[3], uint32_t page = 0) {
        for (int k = 0; k < 3; ++k) {
            BakeVertex v;
            v.position = glm::vec4(p[k], 1.0f);
            v.normal = glm::vec4(0, 0, 1, 0);
            v.uv0 = glm::vec2(0.0f);
            v.lightmapUv = uv[k];
            vertices_.push_back(v);
        }
        pages_.push_back(page);
    }
    size_t triangleCount() const { return pages_.size(); }

    BakeMesh finish(int pageCount = 1) const {
        std::vector<size_t> order(pages_.size());
        std::iota(order.begin(), order.end(), size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return pages_[a] < pages_[b]; });
        BakeMesh m;
        m.pageFirstTriangle.assign(size_t(pageCount) + 1, 0);
        for (size_t t : order) {
            for (int k = 0; k < 3; ++k) {
                m.vertices.push_back(vertices_[t * 3 + k]);
                m.bounds.extend(glm::vec3(vertices_[t * 3 + k].position));
            }
            m.triangles.push_back(BakeTriangle{0, pages_[t], 0, 0});
            ++m.pageFirstTriangle[pages_[t] + 1];
        }
        for (int p = 0; p < pageCount; ++p) m.pageFirstTriangle[size_t(p) + 1] += m.pageFirstTriangle[size_t(p)];
        return m;
    }

private:
    std::vector<BakeVertex> vertices_;
    std::vector<uint32_t> pages_;
};

// A planar grid of cellsX x cellsY quads (two triangles each): parameter
// (s, t) in [0,1]^2 goes to world worldFromPlane * (s, t, 0, 1) and to page uv
// mix(uvMin, uvMax, (s, t)) + uvNoise(vertex index) (noise per grid vertex,
// so neighbouring triangles share their noisy corners, as an unwrap would).
inline void addGrid(MeshBuilder& b, const glm::mat4& worldFromPlane, int cellsX, int cellsY, glm::vec2 uvMin,
                    glm::vec2 uvMax, uint32_t page = 0,
                    const std::function<glm::vec2(int, int)>& uvNoise = nullptr) {
    auto world = [&](int i, int j) {
        return glm::vec3(worldFromPlane * glm::vec4(float(i) / cellsX, float(j) / cellsY, 0.0f, 1.0f));
    };
    std::vector<glm::vec2> uv(size_t(cellsX + 1) * (cellsY + 1));
    for (int j = 0; j <= cellsY; ++j)
        for (int i = 0; i <= cellsX; ++i) {
            glm::vec2 st(float(i) / cellsX, float(j) / cellsY);
            uv[size_t(j) * (cellsX + 1) + i] = uvMin + (uvMax - uvMin) * st + (uvNoise ? uvNoise(i, j) : glm::vec2(0.0f));
        }
    auto at = [&](int i, int j) { return uv[size_t(j) * (cellsX + 1) + i]; };
    for (int j = 0; j < cellsY; ++j)
        for (int i = 0; i < cellsX; ++i) {
            const glm::vec3 p0[3] = {world(i, j), world(i + 1, j), world(i + 1, j + 1)};
            const glm::vec2 u0[3] = {at(i, j), at(i + 1, j), at(i + 1, j + 1)};
            b.add(p0, u0, page);
            const glm::vec3 p1[3] = {world(i, j), world(i + 1, j + 1), world(i, j + 1)};
            const glm::vec2 u1[3] = {at(i, j), at(i + 1, j + 1), at(i, j + 1)};
            b.add(p1, u1, page);
        }
}

// Tiny triangles with noisy UVs (the supplement's Figure 2 (a) failure case):
// a side x side world square in the z = 0 plane, mapped onto texelsAcross x
// texelsAcross texels at `origin` (in texels) of a page of `resolution`,
// cut into cells x cells quads, each grid vertex's UV moved by uniform noise
// of +-noiseTexels texels. The true density is (texelsAcross / side)^2.
inline void addNoisyTinyGrid(MeshBuilder& b, float side, int texelsAcross, glm::vec2 origin, int resolution,
                             int cells, float noiseTexels, uint32_t seed, uint32_t page = 0) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-noiseTexels, noiseTexels);
    std::vector<glm::vec2> noise(size_t(cells + 1) * (cells + 1));
    for (auto& n : noise) n = glm::vec2(u(rng), u(rng)) / float(resolution);
    glm::mat4 m(1.0f);
    m[0][0] = side;
    m[1][1] = side;
    const glm::vec2 uvMin = origin / float(resolution);
    const glm::vec2 uvMax = (origin + glm::vec2(float(texelsAcross))) / float(resolution);
    addGrid(b, m, cells, cells, uvMin, uvMax, page,
            [&](int i, int j) { return noise[size_t(j) * (cells + 1) + i]; });
}

}  // namespace bb::test
