#include "bake/transport_albedo.h"

#include <algorithm>
#include <cmath>

#include "core/hash.h"
#include "reference/embree_mesh.h"

namespace bb {
namespace {

constexpr int kBounces = 5;       // lambda = E_5 / E_4
constexpr int kSlowBounces = 24;  // slowest = E_24 / E_23

struct Triangle {
    glm::vec3 p0, e1, e2;
    glm::vec3 n;  // unit geometric normal on the side the shading normal faces
};

}  // namespace

TransportAlbedo transportAlbedo(const BakeMesh& mesh, const std::vector<glm::vec3>& albedo,
                                const std::vector<bool>& doubleSided, int paths) {
    const size_t n = mesh.triangles.size();
    if (n == 0 || paths <= 0) return {};
    std::vector<Triangle> tris(n);
    std::vector<double> cdf(n);
    double area = 0.0;
    for (size_t t = 0; t < n; ++t) {
        const glm::vec3 a(mesh.vertices[3 * t].position), b(mesh.vertices[3 * t + 1].position),
            c(mesh.vertices[3 * t + 2].position);
        Triangle& tri = tris[t];
        tri.p0 = a;
        tri.e1 = b - a;
        tri.e2 = c - a;
        const glm::vec3 cr = glm::cross(tri.e1, tri.e2);
        const float len = glm::length(cr);
        tri.n = len > 0.0f ? cr / len : glm::vec3(0.0f);
        const glm::vec3 ns(mesh.vertices[3 * t].normal + mesh.vertices[3 * t + 1].normal + mesh.vertices[3 * t + 2].normal);
        if (glm::dot(ns, tri.n) < 0.0f) tri.n = -tri.n;
        area += 0.5 * double(len);
        cdf[t] = area;
    }
    if (area <= 0.0) return {};

    RTCDevice device = rtcNewDevice("threads=1");
    if (!device) return {};
    RTCScene scene = commitBakeMeshScene(device, mesh, RTC_BUILD_QUALITY_MEDIUM);
    if (!scene) {
        rtcReleaseDevice(device);
        return {};
    }

    const float offset = rayOffset(mesh);

    std::vector<glm::dvec3> sums(kSlowBounces + 1, glm::dvec3(0.0));  // E_k x paths, k = 0..kSlowBounces
    // the first kBounces bounces from one sequence, their continuations from
    // another: lambda the same numbers whatever the slowest's bounces draw
    SplitMix64 rng{0x5eed5eedull}, slowRng{0x510e510eull};
    for (int p = 0; p < paths; ++p) {
        // a point by area, then k cosine rays
        const double pick = (double(p) + double(rng.uniformFloat())) / double(paths) * area;
        size_t t = size_t(std::lower_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
        t = std::min(t, n - 1);
        bool flip = false;  // on a double-sided triangle's back
        glm::vec3 weight(1.0f);
        for (int k = 0; k <= kSlowBounces; ++k) {
            const Triangle& tri = tris[t];
            const glm::vec3 normal = flip ? -tri.n : tri.n;
            SplitMix64& pointRng = k <= kBounces ? rng : slowRng;
            float u = pointRng.uniformFloat(), v = pointRng.uniformFloat();
            if (u + v > 1.0f) {
                u = 1.0f - u;
                v = 1.0f - v;
            }
            const glm::vec3 point = tri.p0 + u * tri.e1 + v * tri.e2;
            weight *= albedo[mesh.triangles[t].material];
            sums[size_t(k)] += glm::dvec3(weight);
            if (k == kSlowBounces) break;
            // a cosine direction about the normal
            SplitMix64& rayRng = k < kBounces ? rng : slowRng;
            const float r = std::sqrt(rayRng.uniformFloat()), phi = 6.28318531f * rayRng.uniformFloat();
            const glm::vec3 axis = std::abs(normal.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
            const glm::vec3 tx = glm::normalize(glm::cross(axis, normal)), ty = glm::cross(normal, tx);
            const glm::vec3 dir = r * std::cos(phi) * tx + r * std::sin(phi) * ty +
                                  std::sqrt(std::max(0.0f, 1.0f - r * r)) * normal;
            RTCRayHit rh;
            if (!intersectRay(scene, point + offset * normal, dir, rh)) break;
            t = rh.hit.primID;
            // a single-sided surface's back absorbs; a double-sided one is seen from the side the ray meets
            flip = glm::dot(dir, tris[t].n) > 0.0f;
            if (flip && !doubleSided[mesh.triangles[t].material]) break;
        }
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    // E_k / E_(k-1), the largest channel's; 0 where no path made k bounces
    auto ratio = [&](int k) {
        double lambda = 0.0;
        for (int c = 0; c < 3; ++c)
            if (sums[size_t(k - 1)][c] > 0.0) lambda = std::max(lambda, sums[size_t(k)][c] / sums[size_t(k - 1)][c]);
        return std::min(lambda, 0.999);
    };
    TransportAlbedo out;
    out.lambda = ratio(kBounces);
    out.slowest = std::max(out.lambda, ratio(kSlowBounces));
    return out;
}

}  // namespace bb
