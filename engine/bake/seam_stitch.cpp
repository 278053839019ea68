// Seam stitching by sparse least squares (see seam_stitch.h).
#include "bake/seam_stitch.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

namespace bb {
namespace {

// A texel of a page: page in the high bits, row-major index in the low.
uint64_t texelKey(uint32_t page, size_t index) { return (uint64_t(page) << 40) | uint64_t(index); }

struct Tap {
    uint64_t key;
    double weight;
};

// GL_LINEAR's four taps at texel coordinates p (clamp to edge); taps of weight
// 0 (a lookup exactly on a texel row or column) are dropped.
int bilinearTaps(uint32_t page, glm::vec2 p, int resolution, Tap* out) {
    const double x = double(p.x) - 0.5, y = double(p.y) - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const double tx = x - fx, ty = y - fy;
    int n = 0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const double w = (i ? tx : 1.0 - tx) * (j ? ty : 1.0 - ty);
            if (w <= 0.0) continue;
            const int xi = std::clamp(int(fx) + i, 0, resolution - 1);
            const int yi = std::clamp(int(fy) + j, 0, resolution - 1);
            out[n++] = {texelKey(page, size_t(yi) * size_t(resolution) + size_t(xi)), w};
        }
    return n;
}

glm::dvec3 lookup(const LightmapPages& maps, const Tap* taps, int n) {
    glm::dvec3 sum(0.0);
    for (int k = 0; k < n; ++k) {
        const uint32_t page = uint32_t(taps[k].key >> 40);
        const size_t index = size_t(taps[k].key & ((uint64_t(1) << 40) - 1));
        sum += glm::dvec3(maps.pages[page].pixels[index]) * taps[k].weight;
    }
    return sum;
}

// Texels that hold a baked value: covered, or padding within 2 texels
// (Euclidean) of a covered texel, which the baker's dilation always fills
// (its radius is max(padding, 1) + 1); a texel further out may be unwritten.
std::vector<std::vector<uint8_t>> valuedTexels(const LightmapPages& maps) {
    const int res = maps.resolution;
    std::vector<std::vector<uint8_t>> valued(maps.pages.size());
    for (size_t p = 0; p < maps.pages.size(); ++p) {
        const std::vector<uint8_t>& cov = maps.covered[p];
        std::vector<uint8_t>& v = valued[p];
        v.assign(cov.size(), 0);
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                if (!cov[size_t(y) * size_t(res) + size_t(x)]) continue;
                for (int j = std::max(0, y - 2); j <= std::min(res - 1, y + 2); ++j)
                    for (int i = std::max(0, x - 2); i <= std::min(res - 1, x + 2); ++i)
                        if ((i - x) * (i - x) + (j - y) * (j - y) <= 4) v[size_t(j) * size_t(res) + size_t(i)] = 1;
            }
    }
    return valued;
}

// The pair's taps (A's with +weight, B's with -weight); 0 when a page is out
// of range or a tap has no baked value (the pair is skipped).
int pairTaps(const LightmapPages& maps, const std::vector<std::vector<uint8_t>>& valued, const SeamSamplePair& s,
             Tap* taps) {
    if (s.pageA >= maps.pages.size() || s.pageB >= maps.pages.size()) return 0;
    const int na = bilinearTaps(s.pageA, s.texelA, maps.resolution, taps);
    const int nb = bilinearTaps(s.pageB, s.texelB, maps.resolution, taps + na);
    for (int k = 0; k < na + nb; ++k) {
        if (!valued[size_t(taps[k].key >> 40)][size_t(taps[k].key & ((uint64_t(1) << 40) - 1))]) return 0;
        if (k >= na) taps[k].weight = -taps[k].weight;
    }
    return na + nb;
}

// Calls f(pair index, A's lookup, B's lookup) for every pair whose taps all
// have baked values, skipped(pair index) for the others.
template <typename F, typename G>
void forEachPair(const LightmapPages& maps, const Seams& seams, F&& f, G&& skipped) {
    const std::vector<std::vector<uint8_t>> valued = valuedTexels(maps);
    Tap taps[8];
    for (size_t i = 0; i < seams.samples.size(); ++i) {
        const int n = pairTaps(maps, valued, seams.samples[i], taps);
        if (n == 0) {
            skipped(i);
            continue;
        }
        glm::dvec3 va(0.0), vb(0.0);  // A's taps have weight > 0, B's < 0
        for (int k = 0; k < n; ++k) {
            const glm::dvec3 v = lookup(maps, taps + k, 1);
            if (taps[k].weight > 0) va += v;
            else vb -= v;
        }
        f(i, va, vb);
    }
}

}  // namespace

SeamDifference seamDifference(const LightmapPages& maps, const Seams& seams) {
    SeamDifference d;
    double sq = 0.0, sum = 0.0;
    forEachPair(
        maps, seams,
        [&](size_t, const glm::dvec3& va, const glm::dvec3& vb) {
            sq += glm::dot(va - vb, va - vb) / 3.0;
            sum += (va.x + va.y + va.z + vb.x + vb.y + vb.z) / 6.0;
            ++d.pairs;
        },
        [&](size_t) { ++d.skipped; });
    if (d.pairs > 0) {
        d.rms = std::sqrt(sq / double(d.pairs));
        d.mean = sum / double(d.pairs);
    }
    return d;
}

std::vector<double> seamPairDifferences(const LightmapPages& maps, const Seams& seams) {
    std::vector<double> out(seams.samples.size(), -1.0);
    forEachPair(
        maps, seams,
        [&](size_t i, const glm::dvec3& va, const glm::dvec3& vb) { out[i] = glm::length(va - vb) / std::sqrt(3.0); },
        [](size_t) {});
    return out;
}

nlohmann::json SeamStitchStats::toJson() const {
    return {{"seam_edges", seamEdges},     {"hard_edges", hardEdges},         {"narrow_pairs", narrowPairs},
            {"sample_pairs", samplePairs},   {"skipped_pairs", skippedPairs},   {"texels_adjusted", texelsAdjusted},
            {"rms_before", rmsBefore},       {"rms_after", rmsAfter},           {"mean_value", meanValue},
            {"seconds", seconds},            {"solved", solved}};
}

SeamStitchStats stitchSeams(LightmapPages& maps, const Seams& seams, const SeamStitchOptions& options) {
    const auto t0 = std::chrono::steady_clock::now();
    SeamStitchStats st;
    st.seamEdges = seams.seamEdges;
    st.hardEdges = seams.hardEdges;
    st.narrowPairs = seams.narrowPairs;
    const SeamDifference before = seamDifference(maps, seams);
    st.samplePairs = before.pairs;
    st.skippedPairs = before.skipped;
    st.rmsBefore = st.rmsAfter = before.rms;
    st.meanValue = before.mean;
    if (before.pairs == 0 || maps.resolution < 1) return st;

    // the taps of every pair (A's with +w, B's with -w), and the texels they touch
    std::vector<std::array<Tap, 8>> rows;
    std::vector<int> rowSize;
    rows.reserve(before.pairs);
    std::vector<uint64_t> texels;
    const std::vector<std::vector<uint8_t>> valued = valuedTexels(maps);
    for (const SeamSamplePair& s : seams.samples) {
        std::array<Tap, 8> r{};
        const int n = pairTaps(maps, valued, s, r.data());
        if (n == 0) continue;
        for (int k = 0; k < n; ++k) texels.push_back(r[size_t(k)].key);
        rows.push_back(r);
        rowSize.push_back(n);
    }
    std::sort(texels.begin(), texels.end());
    texels.erase(std::unique(texels.begin(), texels.end()), texels.end());
    const auto var = [&](uint64_t key) {
        return Eigen::Index(std::lower_bound(texels.begin(), texels.end(), key) - texels.begin());
    };
    const Eigen::Index n = Eigen::Index(texels.size());

    // normal equations: (J^T J + K) x = K x_baked, K the texels' keep weights
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(rows.size() * 64 + size_t(n));
    for (size_t r = 0; r < rows.size(); ++r)
        for (int i = 0; i < rowSize[r]; ++i)
            for (int j = 0; j < rowSize[r]; ++j)
                triplets.emplace_back(var(rows[r][size_t(i)].key), var(rows[r][size_t(j)].key),
                                      rows[r][size_t(i)].weight * rows[r][size_t(j)].weight);
    // covered texels hold what the bake measured (their footprints' means): they
    // move coveredKeepFactor times less than the padding texels the seams'
    // lookups tap, less so as their part on the chart shrinks (Seams::texelArea):
    // a bundle pixel's centre crosses a texel a tenth on its chart in a tenth
    // of the directions (update.frag footprintPixel), and its value is that
    // much noisier
    Eigen::VectorXd keep(n);
    for (Eigen::Index i = 0; i < n; ++i) {
        const uint64_t key = texels[size_t(i)];
        const size_t page = size_t(key >> 40), texel = size_t(key & ((uint64_t(1) << 40) - 1));
        const double area = page < seams.texelArea.size() && !seams.texelArea[page].empty()
                                ? std::max(double(seams.texelArea[page][texel]), 1.0) / 255.0
                                : 1.0;
        keep(i) = options.keepWeight * (maps.covered[page][texel] ? options.coveredKeepFactor * area : 1.0);
        triplets.emplace_back(i, i, keep(i));
    }
    Eigen::SparseMatrix<double> a(n, n);
    a.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(a);
    if (solver.info() != Eigen::Success) {
        st.solved = false;
        return st;
    }
    Eigen::MatrixXd baked(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
        const uint64_t key = texels[size_t(i)];
        const glm::vec3& v = maps.pages[size_t(key >> 40)].pixels[size_t(key & ((uint64_t(1) << 40) - 1))];
        baked(i, 0) = v.r;
        baked(i, 1) = v.g;
        baked(i, 2) = v.b;
    }
    const Eigen::MatrixXd x = solver.solve(keep.asDiagonal() * baked);
    if (solver.info() != Eigen::Success) {
        st.solved = false;
        return st;
    }
    // write back: light is never negative (a stitch of a step may undershoot)
    for (Eigen::Index i = 0; i < n; ++i) {
        const uint64_t key = texels[size_t(i)];
        glm::vec3& v = maps.pages[size_t(key >> 40)].pixels[size_t(key & ((uint64_t(1) << 40) - 1))];
        v = glm::vec3(float(std::max(0.0, x(i, 0))), float(std::max(0.0, x(i, 1))), float(std::max(0.0, x(i, 2))));
    }
    st.texelsAdjusted = size_t(n);
    st.rmsAfter = seamDifference(maps, seams).rms;
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return st;
}

}  // namespace bb
