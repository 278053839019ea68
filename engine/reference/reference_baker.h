// The CPU reference baker: Monte Carlo path tracing on Intel Embree 3 from
// points spread over every covered light map texel's footprint, into the same
// light maps as the ray-bundle baker (same layout, same texels, same units
// L_lm = E/pi).
//
// Based on: J. Kajiya, "The Rendering Equation", SIGGRAPH 1986 (path tracing);
// E. Veach, "Robust Monte Carlo Methods for Light Transport Simulation", PhD
// thesis, 1997, ch. 9 (multiple importance sampling, power heuristic); M. Pharr,
// W. Jakob, G. Humphreys, "Physically Based Rendering", 4th ed. (Russian
// roulette, Owen-scrambled Sobol' samples); Cycles (Blender 3.2 on: a ray
// skips the primitive it leaves instead of starting off it).
//
// What it computes, per covered texel (centre inside a triangle in page space):
// the mean over the texel's footprint, i.e. the part of its square (page
// space) that lies on its chart (the owner triangle's chart: triangles joined
// by shared light map edges), uniform in page space, of
//   L_lm(x) = (1/pi) * integral over the hemisphere of the shading normal of L_in cos
// at each point x with its own position and interpolated normal; not the value
// at the texel's centre. This is what Cycles' and Unity's bakers store and
// what bilinear filtering of the map reconstructs best; at a shadow edge or a
// chart border through a texel the centre's value can be anything from 0 to
// the full value (issue 11: one definition for the bake and the reference).
// L_in is the radiance arriving from the first hit: Le + albedo * L_lm(hit),
// recursively (all bounces, Russian roulette), a uniform sky or an
// equirectangular environment where a ray escapes, and directional suns
// (next-event estimated at every vertex, exact shadow test). The texel's own
// emission is not part of its L_lm (DESIGN.md Units).
//
// Model, matched to the GPU baker (engine/bake/baker.h):
// - coverage: a texel is covered when its centre lies inside a triangle in page
//   space; edge ties follow a top-left rule (GL's rasterizer uses one too, but
//   llvmpipe snaps to 1/256 texel, so a handful of texels exactly on chart
//   edges may differ: compare over the texels both cover). Overlapping charts:
//   the last triangle in the GPU meta pass's order (page, then material) wins.
// - single-sided surfaces: a ray that hits a back face sees 0 (opaque black);
//   emitters emit from their front only. Double-sided: either side is seen, with
//   its own emission, and a path continues on the side it hit (the GPU baker
//   reuses the front's L_lm for the back: they differ only where the two sides
//   of a double-sided surface are lit differently).
// - materials: albedo = factor x albedo texture (clamped to [0,1]), emission =
//   factor x emission texture, textures sampled bilinearly (level 0, repeat) at
//   the hit's TEXCOORD_0. (The GPU bakes them once per light map texel with
//   trilinear filtering: the reference resolves texture detail below a texel.)
// - environment: u = 0.5 + atan2(d.z, d.x) / 2pi, v = acos(d.y) / pi, image row
//   0 = v 0 = the top (glsl/lightmap/update.frag environment()), bilinear,
//   repeating in u and clamped in v (the GPU also repeats v, which blends the
//   two poles in the first and last half row; nothing else differs).
// - shading normals: the texel's hemisphere is that of its interpolated normal;
//   a sampled direction below its triangle's plane is blocked (counts 0).
//
// Sampling: sample i of a texel starts at a point of its footprint and goes in
// a cosine-weighted direction, both from a per-texel Owen-scrambled 4D Sobol'
// sequence (dimensions 1-2 the direction, a (0,2)-sequence; 3-4 the point,
// picked among the footprint's pieces by area), so every power-of-two prefix
// is stratified over the footprint and the hemisphere jointly. Next-event
// estimation of emissive triangles (picked by power, uniform by area) is
// combined with the cosine samples by MIS, Russian roulette after
// `rouletteDepth` bounces. Sample i of texel t depends only on (seed, page,
// t, i): results are the same bits for any thread count and any pass split.
//
// Space: the BakeMesh's local space (world - Scene::origin, layout/bake_mesh.h),
// so precision follows the scene's size, not its distance from the world
// origin; suns and the sky are directions, the same in both spaces. Points on
// surfaces (footprint samples, hits) are kept 1e-5 of the way inside their
// triangle: a point on the seam of two walls would start rays behind the other
// wall (the rho 0.9 furnace read 5.8 % low where chart borders crossed texel
// centres). Their rays start on them and skip their triangle (and an emitter
// sample's shadow ray the emitter's; reference/embree_mesh.h SkipContext): no
// offset, which sees past a blocker within it (a wall 4.5 cm off itself under
// a 25 cm overhang, in a scene 2 km wide). estimate()'s probe points, on no
// known triangle, start off their surface by rayOffset.
//
// Thread-safe: no. One ReferenceBaker is driven from one thread; it runs its
// own worker threads inside step().
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "bake/baker.h"  // LightmapPages
#include "core/status.h"
#include "io/image_io.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb {

struct TexelId {
    uint32_t page = 0;
    uint32_t index = 0;  // y * resolution + x
};

struct ReferenceOptions {
    int spp = 1024;                 // samples (paths) per texel in all; typ. 64 .. 65536
    int passSpp = 16;               // samples per texel per progressive pass (step() granularity)
    int threads = 2;                // worker threads; 0 = std::thread::hardware_concurrency()
    uint64_t seed = 1;
    glm::vec3 sky{0.0f};            // uniform sky radiance (scene units)
    std::optional<io::ImageRgb> environment;  // equirectangular radiance; replaces sky
    bool emitterSampling = true;    // next-event estimation of emissive triangles (with MIS)
    int rouletteDepth = 3;          // bounces before Russian roulette starts; typ. 2..5
    int maxBounces = 1000;          // safety cap on path length (roulette ends paths long before)
    // Which covered texels to bake (page, y * resolution + x); empty: all. The others are neither
    // traced nor held (the error check's subset of a large map: reference/error_check.h).
    std::function<bool(uint32_t page, uint32_t index)> texelFilter;
};

struct ReferenceStats {
    int sppDone = 0;
    int sppTotal = 0;
    int threads = 0;
    int passes = 0;
    int64_t lightmapTexels = 0;
    int64_t coveredTexels = 0;
    int64_t emitterTriangles = 0;
    int64_t paths = 0;              // texel samples traced
    int64_t rays = 0;               // closest-hit rays (path segments)
    int64_t shadowRays = 0;         // occlusion rays (suns, emitters)
    double secondsSetup = 0;        // BVH build, texel coverage
    double secondsTrace = 0;        // path tracing passes
    nlohmann::json toJson() const;
};

struct ReferenceProgress {
    int sppDone = 0;
    int sppTotal = 0;
    bool done() const { return sppDone >= sppTotal; }
};

class ReferenceBaker {
public:
    // Builds the BVH and finds the covered texels. Errors: bad options
    // (spp < 1, passSpp < 1, threads < 0), a scene without triangles.
    static Expected<std::unique_ptr<ReferenceBaker>> create(const Scene& scene, const Layout& layout,
                                                            const ReferenceOptions& options);
    ~ReferenceBaker();

    // Traces passes of passSpp samples per texel until `seconds` have passed (at
    // least one pass, unless done).
    ReferenceProgress step(double seconds);
    ReferenceProgress progress() const;

    // The current estimate: L_lm = sum / samples per covered texel, padding
    // dilated as on the GPU (empty texels take the mean of their covered
    // 8-neighbours, repeated), `covered` as found at create().
    LightmapPages readLightmaps() const;

    // The estimator at one surface point (tests, probes): L_lm at `point`
    // (local space, as mesh() positions: world - BakeMesh::origin)
    // on the side `normal` faces, from `spp` samples of stream `stream`
    // (single-threaded). `normal` is used as both shading and geometric normal.
    glm::vec3 estimate(const glm::vec3& point, const glm::vec3& normal, int spp, uint64_t stream) const;

    // The covered texels, in the order sampleTexels() takes and returns them.
    std::vector<TexelId> coveredTexels() const;

    // Estimates independent of the progressive ones (the bake's error check,
    // reference/error_check.h): for covered texel i, samples [0, spp[i]) of its
    // stream under `seed` (another seed than options.seed: independent of
    // readLightmaps()), as step() traces them (on options.threads threads):
    // xyz their sum, w the sum of the squares of their channels' mean. Any
    // prefix of a texel's stream is an unbiased estimate of its value.
    std::vector<glm::dvec4> sampleTexels(uint64_t seed, const std::vector<uint32_t>& spp);

    const ReferenceStats& stats() const;
    const BakeMesh& mesh() const;

    struct Impl;

private:
    explicit ReferenceBaker(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace bb
