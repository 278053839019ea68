#include "bake/transport_albedo.h"

#include <algorithm>
#include <cmath>

#include "core/hash.h"
#include "reference/embree_mesh.h"

namespace bb {
namespace {

constexpr int kBounces = 5;

struct Triangle {
    glm::vec3 p0, e1, e2;
    glm::vec3 n;  // unit geometric normal on the side the shading normal faces
};

}  // namespace

double transportAlbedo(const BakeMesh& mesh, const std::vector<glm::vec3>& albedo, const std::vector<bool>& doubleSided,
                       int paths) {
    const size_t n = mesh.triangles.size();
    if (n == 0 || paths <= 0) return 0.0;
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
    if (area <= 0.0) return 0.0;

    RTCDevice device = rtcNewDevice("threads=1");
    if (!device) return 0.0;
    RTCScene scene = commitBakeMeshScene(device, mesh, RTC_BUILD_QUALITY_MEDIUM);
    if (!scene) {
        rtcReleaseDevice(device);
        return 0.0;
    }

    const float offset = rayOffset(mesh);

    std::vector<glm::dvec3> sums(kBounces + 1, glm::dvec3(0.0));  // E_k x paths, k = 0..kBounces
    SplitMix64 rng{0x5eed5eedull};
    for (int p = 0; p < paths; ++p) {
        // a point by area, then k cosine rays
        const double pick = (double(p) + double(rng.uniformFloat())) / double(paths) * area;
        size_t t = size_t(std::lower_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
        t = std::min(t, n - 1);
        bool flip = false;  // on a double-sided triangle's back
        glm::vec3 weight(1.0f);
        for (int k = 0; k <= kBounces; ++k) {
            const Triangle& tri = tris[t];
            const glm::vec3 normal = flip ? -tri.n : tri.n;
            float u = rng.uniformFloat(), v = rng.uniformFloat();
            if (u + v > 1.0f) {
                u = 1.0f - u;
                v = 1.0f - v;
            }
            const glm::vec3 point = tri.p0 + u * tri.e1 + v * tri.e2;
            weight *= albedo[mesh.triangles[t].material];
            sums[size_t(k)] += glm::dvec3(weight);
            if (k == kBounces) break;
            // a cosine direction about the normal
            const float r = std::sqrt(rng.uniformFloat()), phi = 6.28318531f * rng.uniformFloat();
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
    double lambda = 0.0;
    for (int c = 0; c < 3; ++c)
        if (sums[kBounces - 1][c] > 0.0) lambda = std::max(lambda, sums[kBounces][c] / sums[kBounces - 1][c]);
    return std::min(lambda, 0.999);
}

}  // namespace bb
