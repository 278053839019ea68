// The Baker's state, shared by the files of its stages (private to engine/bake):
//   baker.cpp           setup (programs, meta pass, importance -> clusters,
//                       buffers), the public API, read-backs, captures
//   bundle_tracer.cpp   the bundle pass and a direction's tiles (engine/tiler)
//   radiance_exchange.cpp  a direction: history ramp, update pass, resolve
//   direct_light.cpp    the sun (shadow bundles) and explicit emitters
//   checkpoint.cpp      checkpoints
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "bake/baker.h"
#include "bake/bundle_tracer.h"
#include "bake/curved_footprints.h"
#include "core/timer.h"
#include "gl/objects.h"
#include "tiler/tiler.h"

namespace bb {

// One page's CHART_NEIGHBOUR_* bits (glsl/shared/bundle_layout.h) from its
// coverage codes (before dilation) and texel owners (baker.cpp).
void chartNeighbourBits(const std::vector<uint8_t>& codes, const std::vector<int32_t>& owner,
                        const std::vector<uint32_t>& chart, int res, std::vector<uint8_t>& bits);
// One page's texelCharts codes: each texel's owner's chart, TEXEL_CHART_MASK where none owns it (baker.cpp).
void ownerChartCodes(const std::vector<int32_t>& owner, const std::vector<uint32_t>& chart, std::vector<uint16_t>& codes);

// The direct light's distance cube at its largest, where any light may take
// one (direct_light.cpp): before the bake's pixels, and so the cube's size,
// are known (supersample auto).
int64_t largestDistanceCubeBytes(const Scene& scene, const BakeMesh& mesh, const BakeOptions& options);

struct Baker::Impl {
    BakeOptions options;
    BakeMesh mesh;
    std::vector<uint32_t> charts;  // per triangle, its light map chart (findLightmapCharts; uploadMesh)
    Layout layout;        // what the bake runs on: outputLayout, or its supersampled one
    Layout outputLayout;  // the caller's: readLightmaps reduces to it (bake/supersample.h)
    std::vector<Material> materials;
    std::vector<DirectionalLight> lights;
    std::vector<PunctualLight> punctualLights;  // point and spot (direct_light.cpp)
    BakeStats stats;
    uint64_t inputKey = 0;  // hash of the materials, their textures and the lights (checkpoints)
    std::vector<glm::vec3> directions;

    // scene frame
    glm::vec3 sphereCenter{0.0f};
    float sphereRadius = 1.0f;
    float pixelSize = 1.0f;
    double texelSize = 1.0;  // the mean texel's side, scene units (sqrt(world area / texel area))
    double sunPixelSize = 0;  // adaptive: the scene's finest pixel, for the sun's jittered bundles (0: pixelSize)
    int gridSize = 1;         // pixels across the uniform bundle (--tiling uniform, captures)
    int maxTileSize = 2048;   // largest head image side the budget allows
    float depthBias = 0.0f;
    double historyPower = 0.0;
    double accumLogScale = 0.0;  // stored weights are true weights / exp(accumLogScale)
    int refreshEveryRound = 64;  // rounds refreshed after each one before the schedule thins out (bounces)
    int historyPlateau = 1;      // the ramp's weights are equal from this round on (chooseHistoryPlateau)
    float radianceUnit = 1.0f;  // the light-map state holds radiance / radianceUnit (sanitizeInputs)
    std::vector<double> projectedArea;  // per triangle world area
    std::vector<Cluster> clusters;      // the mesh in culling units (engine/tiler)
    TilerOptions tilerOptions;

    // GL objects
    gl::Buffer vertexBuffer, triangleBuffer, metaIndexBuffer;
    gl::VertexArray vao;
    // Light-map state, per page texel (65 bytes, 102 with back sides; BakeStats::memory):
    //   accum      RG32UI  the running mean of incoming radiance and its weight (lib/rounding.glsl's accumulator)
    //   radiance   RGB9_E5 outgoing radiance Lo the bundle pass samples (meta.frag writes it)
    //   direct     RGBA16F direct light L_lm (sun + explicit emitters)
    //   dilation   R8UI    the covered texel each texel shows (DILATION_* codes)
    //   chartNeighbours R8UI the texels 1 and 2 away along its row and column on its chart (CHART_NEIGHBOUR_*)
    //   readModes  R8UI    how the bundle pass reads the radiance inside the texel (READ_* per axis)
    //   footprint  RGBA32UI which part of its square lies on its chart: eighth-texel cells, one more border
    //                      edge, the part's area and its spread (texelFootprints)
    //   texelCharts R16UI  its owner's chart, low 16 bits (TRIANGLE_CHART_SHIFT; read by the bundle pass)
    //   moments    RGBA32F the texel's first moments: the running means of L_in's sum times its
    //                      sample's point and of the point (update.frag)
    //   slopes     RGBA16F the slope of its reflected light inside it and the point it is taken about
    //                      (meta.frag), which the bundle pass reads where no neighbour on its chart gives one
    // While the direct light is baked, its float sums live in views of accum
    // and radiance (lib/direct_scratch.glsl). Albedo and emission are not
    // stored: the outgoing pass reads them from the materials.
    // Double-sided triangles light both sides differently (a panel light under a
    // ceiling: its back reflects the ceiling's light onto it again), so a scene
    // with any has accum, radiance, readModes, moments and slopes twice over: page p's back
    // sides at layer p + backLayerOffset (37 more bytes a texel; the direct light stays front-only).
    gl::Texture accum, radiance, direct, dilation, chartNeighbours, readModes, footprint, texelCharts;
    gl::Texture moments, slopes;
    int backLayerOffset = 0;  // 0: no double-sided triangles, one layer per page
    // page p's texel owners: texelOwners, or a supersampled bake's halfTexelOwners
    std::vector<int32_t> bakeTexelOwners(int page, std::vector<uint8_t>* partial) const;
    int stateLayers() const { return layout.pageCount + backLayerOffset; }  // accum's and radiance's layers
    // The bundle and update programs handle back sides only when built with it:
    // llvmpipe runs even a uniformly skipped branch's texture fetch (25 % of the bundle pass)
    std::string backSidesDefine() const { return backLayerOffset ? "#define BACK_SIDES 1\n" : ""; }
    std::string roundingDefine() const {
        return options.rounding == Rounding::Nearest ? "#define ROUNDING_NEAREST 1\n" : "";
    }
    // The seed's shift of every texel's footprint points (lib/texel_footprint.glsl FOOTPRINT_SHIFT)
    std::string footprintShiftDefine() const;
    gl::Texture accumAsFloat, radianceBits, radianceAsFloat;  // views: rg32f, r32ui, r32f
    gl::Texture resolved;  // the whole light map L_lm, made on first use (the viewer's)
    // the noise estimate (noise.cpp): the odd directions' accumulators at every
    // noiseStride-th texel (8 bytes / stride^2 a page texel; its own memory category)
    gl::Texture halfAccum;
    gl::Texture noiseTerms;  // noise.comp's per-texel terms (RGBA32F, halfAccum's size)
    gl::Texture noiseWeights;  // per half-size texel of halfAccum its weight in its texel (R16F, halfAccum's size)
    // halfAccum's side: ceil(output resolution / stride) x supersample. It keeps
    // every stride-th texel of the output layout's, all its half-size texels
    // (update.frag): the estimate is the reduced map's (noise.comp).
    int halfWidth = 1;
    // the direct light's variance (the explicit emitters' and the suns') per
    // sampled texel of the output layout (noiseTerms' texels;
    // direct/direct_noise.comp), or empty
    std::vector<float> directVariance;
    // texel (x, y)'s place in halfAccum's page, or -1 if it is not sampled
    int64_t halfTexel(int x, int y) const {
        const int k = options.supersample, stride = stats.noiseStride;
        if ((x / k) % stride != 0 || (y / k) % stride != 0) return -1;
        return int64_t(y / k / stride * k + y % k) * halfWidth + (x / k / stride * k + x % k);
    }
    gl::Texture envTexture;
    gl::Framebuffer pageFbo;
    // the update's programs over one tile, and over a run of whole leaves at once (bundle_tracer.h)
    gl::Program updateLeafRunProgram, updateCurvedLeafRunProgram, sunLeafRunProgram, sunCurvedLeafRunProgram;
    gl::Program updateProgram, sunProgram, updateCurvedProgram, sunCurvedProgram, resolveProgram, rescaleProgram, metaProgram, coverageProgram,
        dilateProgram, readModesProgram, directFoldProgram, distanceProgram, emitterProgram, emitterCurvedProgram,
        emitterFoldProgram, punctualProgram, punctualCurvedProgram,
        noiseProgram, emitterNoiseProgram, sunNoiseProgram;
    // curved texels (bake/curved_footprints.h): their records, and per cluster its first one
    gl::Buffer curvedTexelBuffer, curvedRefBuffer, curvedTriangleBuffer;
    std::vector<uint32_t> curvedClusterFirst;  // empty: none
    gl::VertexArray pointArray;                // no attributes: the rectangles read the curved texels' SSBO
    size_t curvedTexelCount() const { return curvedClusterFirst.empty() ? 0 : curvedClusterFirst.back(); }
    // Binds the curved texels' SSBOs, `program`'s pageResolution (bound) and
    // the empty vertex array, for a draw of them (lightmap/curved.vert).
    void bindCurvedTexels(GLuint program) const;
    gl::Buffer materialAlphaBuffer, alphaTexelBuffer;  // cut-outs (glsl/shared/material_layout.h; cutouts.cpp)
    std::vector<glm::vec3> textureMeans;  // mean linear RGB of each scene texture (explicit emitters)
    std::vector<gl::Texture> materialTextures;
    struct SurfaceRun {
        size_t first;  // position in metaIndexBuffer, in triangles
        uint32_t count, page, material;
    };
    std::vector<SurfaceRun> surfaceRuns;  // metaIndexBuffer's (page, material) runs
    // Partial texels (layout/bake_mesh.h texelOwners), which the raster misses:
    // one point each, at the texel's centre with its owner's attributes at the
    // owner's point nearest it, in (page, material) runs (first: in points).
    gl::Buffer partialPointBuffer;
    gl::VertexArray partialPointArray;
    std::vector<SurfaceRun> partialRuns;
    int64_t nodeCapacity = 0;     // nodes the budget allows in one tile
    int subpixelBits = 8;         // GL_SUBPIXEL_BITS
    std::unique_ptr<BundleTracer> tracer;
    // the direction in progress (Baker::stepTiles can stop between its tiles)
    bool directionActive = false;
    BundleTracer::UpdateFn directionUpdate;
    // shared bakes: the accumulators hold the combined sums (baker 0) or nothing (the others)
    bool combined = true;
    std::vector<std::vector<uint32_t>> coveredTexelIndex;      // per page, the covered texels (combines)
    std::vector<std::vector<uint32_t>> halfCoveredTexelIndex;  // per page, halfAccum's texels on covered ones

    Status init(const Scene& scene);
    static uint64_t hashInputs(const Scene& scene);  // inputKey (checkpoint.cpp)
    // Bad emission, albedo and environment values warned about and replaced; radianceUnit.
    void sanitizeInputs(const Scene& scene);
    Status buildPrograms();
    void uploadMesh();
    void uploadMaterials(const Scene& scene);
    // Draws every page's triangles and partial texels' points (meta.vert) into
    // pageFbo in runs of one page and material, setting `page` and, if asked,
    // the material's uniforms and textures.
    void drawSurface(GLuint program, bool materialUniforms);
    // The baked texels' owners and partial flags of each page, as the partial
    // texels' points took them, kept for the coverage pass where all pages' fit
    // kKeptOwnersBytes (else it takes them again, page by page).
    struct PageOwners {
        std::vector<int32_t> owners;
        std::vector<uint8_t> partial;
    };
    static constexpr int64_t kKeptOwnersBytes = int64_t(256) << 20;
    std::vector<PageOwners> keptOwners;
    void uploadPartialPoints();
    void coveragePass();
    void uploadCurvedTexels(const std::vector<std::vector<CurvedTexel>>& pages);
    void bakeSun();
    void foldDirect(bool perSample);
    bool useExplicitEmitters() const;
    int emitterSamples() const;  // options.emitterSamples, or its automatic count
    void bakeEmitters();
    int64_t directLightPeakBytes() const;  // the emitters' and punctual lights' passes' GL memory
    void uploadAlphaMasks(const Scene& scene);      // cutouts.cpp: the tables, bound at their SSBO bindings
    void bindAlphaMasks() const;
    void bakePunctualLights();    // point and spot lights into the direct sums (direct_light.cpp)
    // The root square of direction d: the uniform grid, or the adaptive root.
    // jitter: in units of jitterUnit (scene units) in adaptive roots, of the uniform pixel otherwise.
    BundleFrame bundleFrame(const glm::vec3& d, glm::vec2 jitter, bool uniformGrid, double jitterUnit) const;
    // Direction k: the history ramp, then its tiles one by one; the round's end
    // (bake/direction_share.h), with the refresh when one is due.
    void beginDirection(int k);
    uint32_t directionSeed(int k) const;      // direction k's random numbers (bundle and update passes)
    BundleFrame directionFrame(int k) const;  // its root square, at its random phase
    // An update program's uniforms and textures for direction k at `sampleWeight` (used by it)
    void setUpdateUniforms(const gl::Program& program, double sampleWeight, int k) const;
    void stepTile();
    void stepDirection();  // tiles until the direction in flight (or the next) is done
    // Baker::step (whole directions) and stepTiles: until `seconds` have passed, at least one step.
    void run(double seconds, bool wholeDirections);
    void finishRound(int round);
    // Shared bakes: every baker's accumulators summed (weights and weighted
    // means) and stored on baker 0; the others keep only what they add next.
    void combineShares(int round);
    int shareIndex() const { return options.share ? options.share->index() : 0; }
    int shareCount() const { return options.share ? options.share->count() : 1; }
    int rounds() const { return (options.directions + shareCount() - 1) / shareCount(); }
    // ln of round j's weight in the history ramp, min(j+1, plateau)^historyPower (in logs: powers up to 1024)
    double rampLogWeight(int round, int plateau) const {
        return historyPower * std::log(std::min(double(round + 1), double(plateau)));
    }
    double rampLogWeight(int round) const { return rampLogWeight(round, historyPlateau); }
    // Rounds between radiance refreshes after round j: 1 while bounces are
    // still needed (refreshEveryRound), then one more every 32 rounds, at most
    // 8, and at most half the rounds the running mean remembers under a ramp
    // ending at `plateau` (rampMemory): a steep ramp's mean is its last few
    // rounds, which must read fresh radiance (design notes "Refreshes as
    // often as the mean forgets").
    int refreshInterval(int round, int plateau) const {
        const int thinned = (round - std::max(0, refreshEveryRound - 64)) / 32;
        return std::clamp(std::min(thinned, int(rampMemory(round, plateau) / 2.0)), 1, 8);
    }
    // Whether the outgoing radiance is refreshed after round j (finishRound, and bounceLag's model of it).
    bool refreshesAfter(int round, int plateau) const {
        return (round + 1) % refreshInterval(round, plateau) == 0 || round + 1 == rounds();
    }
    // The rounds' weights up to j over round j's, summed: min(j+1, plateau)^p
    // integrates to plateau / (p + 1) over the ramp, then 1 a round.
    double rampMemory(int round, int plateau) const {
        const int rampEnd = std::max(1, plateau);
        return std::min(round + 1, rampEnd) / (historyPower + 1.0) + std::max(0, round + 1 - rampEnd);
    }
    void noteMemory();  // peaks into stats
    // The outgoing radiance the bundles read: meta.frag over every page, then the padding.
    void refreshRadiance(uint32_t key);  // key: the direction just done (random numbers)
    void updateReadModes();              // readModes from the radiance map (after a refresh or a restore)
    // read_modes.comp over maps of `res` texels a side (the bake's, or the resolution probe's coarser ones)
    void computeReadModes(const gl::Texture& neighbours, const gl::Texture& bits, const gl::Texture& modes, int res);
    // L_lm of the region (x 0.., y0.., page) + (width, rows, pages) into `target` at (0, 0, 0).
    void resolveInto(const gl::Texture& target, int y0, int rows, int page0, int pages);
    void dispatchPages(GLuint program, int layers = 0);  // layers: 0 = the pages
    // The accumulators' weights times `factor` (both the whole's and the noise half's).
    void rescaleAccumulators(float factor, uint32_t seed);
    void clearAccumulators();  // both to zero: no sample (a share's bakers other than 0 after a combine)
    // noise.cpp: the relative noise now (stats.noiseRelative), kept in the
    // history; stops the bake (directionsGoal) when --target-noise is reached
    void estimateNoise();
    double noiseHalvesFactor() const;  // noise.cpp
    double bounceLag();                // noise.cpp
    int chooseHistoryPlateau() const;  // noise.cpp
    // bounceLag's model of one bounce mode over the bake's schedule: rounds
    // run, the mean, its weight (relative to the last round's) and the mean read
    struct LagModel {
        int rounds = 0;
        double mean = 0, weight = 0, read = 0;
        // round `rounds` of the schedule: its ramp weight over the last one's
        // (exp of their logs' difference), and whether a refresh follows it
        void advance(double weightStep, bool refresh, double lambda, double missed);
        double lag(double lambda) const { return std::max(0.0, 1.0 - mean * (1.0 - lambda)); }
    } lagModel;
    double lagMissedShare() const;  // noise.cpp: the model's share of samples that weigh 0
    // noise.cpp: `m` advanced through the schedule's rounds up to `rounds`
    // under a ramp ending at `plateau`, for a mode that keeps `lambda` a bounce
    void runLagModel(LagModel& m, int rounds, int plateau, double lambda) const;
    // resolution_probe.cpp: after the last direction, stats.noiseResolution (once)
    void probeResolution();
    bool probed = false;
    double noiseMean = 0;  // the maps' mean over the noise estimate's sampled texels (estimateNoise)
    int directionsGoal() const { return stats.stoppedAtTargetNoise ? stats.directionsDone : options.directions; }
};

}  // namespace bb
