#include "reference/embree_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bb {
namespace {

// SkipContext's filter: a hit on a skipped triangle is no hit.
void skipTriangles(const RTCFilterFunctionNArguments* args) {
    const auto* c = reinterpret_cast<const SkipContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        if (prim == c->skip[0] || prim == c->skip[1]) args->valid[i] = 0;
    }
}

// The segment [0, tfar] of the ray from `origin` along `dir`.
RTCRay makeRay(const glm::vec3& origin, const glm::vec3& dir, float tfar) {
    RTCRay ray;
    ray.org_x = origin.x;
    ray.org_y = origin.y;
    ray.org_z = origin.z;
    ray.dir_x = dir.x;
    ray.dir_y = dir.y;
    ray.dir_z = dir.z;
    ray.tnear = 0.0f;
    ray.tfar = tfar;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    return ray;
}

}  // namespace

SkipContext::SkipContext(uint32_t first, uint32_t second) : skip{first, second} {
    rtcInitIntersectContext(&context);
    if (first != kNoTriangle || second != kNoTriangle) context.filter = skipTriangles;
}

RTCScene commitBakeMeshScene(RTCDevice device, const BakeMesh& mesh, RTCBuildQuality quality) {
    const size_t n = mesh.triangles.size();
    RTCScene scene = rtcNewScene(device);
    if (!scene) return nullptr;
    rtcSetSceneFlags(scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
    auto* ib = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
    if (!vb || !ib) {
        rtcReleaseGeometry(geom);
        rtcReleaseScene(scene);
        return nullptr;
    }
    for (size_t i = 0; i < 3 * n; ++i) {
        vb[3 * i] = mesh.vertices[i].position.x;
        vb[3 * i + 1] = mesh.vertices[i].position.y;
        vb[3 * i + 2] = mesh.vertices[i].position.z;
        ib[i] = uint32_t(i);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
        rtcReleaseScene(scene);
        return nullptr;
    }
    return scene;
}

float rayOffset(const BakeMesh& mesh) {
    const Bounds& b = mesh.bounds;
    const float extent = std::max({std::fabs(b.min.x), std::fabs(b.min.y), std::fabs(b.min.z), std::fabs(b.max.x),
                                   std::fabs(b.max.y), std::fabs(b.max.z), glm::length(b.size())});
    return std::max(2e-5f * extent, 1e-7f);
}

bool intersectRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, RTCRayHit& rh, uint32_t skip) {
    SkipContext context(skip);
    rh.ray = makeRay(origin, dir, std::numeric_limits<float>::infinity());
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context.context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

bool occludedRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, float tfar, const SkipContext& skip) {
    SkipContext context = skip;  // Embree takes a mutable context
    RTCRay ray = makeRay(origin, dir, tfar);
    rtcOccluded1(scene, &context.context, &ray);
    return ray.tfar < 0.0f;  // set to -inf on a hit
}

}  // namespace bb
