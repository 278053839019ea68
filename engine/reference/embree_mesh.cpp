#include "reference/embree_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bb {

RTCScene commitBakeMeshScene(RTCDevice device, const BakeMesh& mesh, RTCBuildQuality quality) {
    const size_t n = mesh.triangles.size();
    RTCScene scene = rtcNewScene(device);
    if (!scene) return nullptr;
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
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

bool intersectRay(RTCScene scene, const glm::vec3& origin, const glm::vec3& dir, RTCRayHit& rh) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rh.ray.org_x = origin.x;
    rh.ray.org_y = origin.y;
    rh.ray.org_z = origin.z;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

}  // namespace bb
