// The ray-bundle baker: diffuse global illumination (all bounces) into light
// maps by radiance exchange along ray bundles on the GL 4.3 raster pipeline.
//
// Based on: Y. Tokuyoshi, T. Sekine, T. da Silva, T. Kanai, "Adaptive
// Ray-bundle Tracing with Memory Usage Prediction: Efficient Global
// Illumination in Large Scenes", CGF 32(7), 2013 (supplement §2-3), and
// J. Hermes, N. Henrich, T. Grosch, S. Mueller, "Global Illumination using
// Parallel Global Ray-Bundles", VMV 2010.
//
// A bake you can step (lightmapper's lmBegin/lmEnd idea): the CLI loops on
// step(), the viewer calls it once per frame; one code path, one seed, the
// same bytes. Requires a current GL 4.3 context for its whole life.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "bake/direction_share.h"
#include "bake/rounding.h"
#include "core/status.h"
#include "io/image_io.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"

namespace bb {

struct BakeOptions {
    int directions = 256;             // bundle directions (each serves d and -d); typ. 64..4096
    int bundleResolution = 0;         // pixels across the scene's bounding sphere, every tile; 0 = from the
                                      // importance (adaptive: each leaf's pixel is half its densest texel,
                                      // which keeps light from leaking through walls >= 1 texel thick;
                                      // uniform: half the scene's mean texel)
    // Adaptive (the paper): a quadtree of leaves over the bundle plane, each
    // with the pixel its importance asks for and its own projection
    // (engine/tiler/tiler.h). Uniform (Hermes et al. 2010, the baseline): one
    // grid over the whole scene at the mean texel density, cut into tiles.
    enum class Tiling { Adaptive, Uniform } tiling = Tiling::Adaptive;
    bool cull = true;                 // per tile, draw only the clusters whose bounds meet it (both passes)
    // GL bytes for the whole bake: light-map state (33 bytes a page texel, 46
    // with double-sided materials), mesh (172 bytes a triangle), materials, and
    // what is left for one tile's node buffer and head image. A bake that does
    // not fit fails at create().
    int64_t memoryBudget = 4ll << 30;
    int64_t bundleMemory = 0;         // > 0: one tile's node buffer + head image exactly (tests); 0 = what the budget leaves
    uint64_t seed = 1;
    glm::vec3 sky{0.0f};              // uniform sky radiance (scene units)
    std::optional<io::ImageRgb> environment;  // equirectangular environment radiance; replaces sky
    Rounding rounding = Rounding::Stochastic;
    // History ramp: direction k is weighted min(k, plateau)^power, so early
    // directions (which saw light maps with few bounces) fade out. < 0 = from
    // the scene's transport albedo (defaultHistoryPower, bake/transport_albedo.h).
    float historyPower = -1.0f;
    // The round from which the ramp's weights stay equal; <= 0: the earliest
    // the bounce-lag model allows (noise.cpp chooseHistoryPlateau), at most
    // half the rounds (where the ramp ended until 2026-12-05).
    int historyPlateau = 0;
    // Cut each tile until its predicted node count (projected cluster areas /
    // pixel area) fits 80 % of the budget's node buffer, and size the buffer
    // from the predictions. false: the buffer is allocated at the budget and
    // only overflow detection splits tiles (tests).
    bool predictTiles = true;
    // Update runs of whole leaves at once (bundle_tracer.h). false: every tile
    // alone (tests: the same bits).
    bool leafRuns = true;
    // Sun bundles per axis, each jittered sub-pixel and at another point of
    // every texel's footprint (antialiased shadows: a texel across a shadow
    // edge reads its lit fraction in steps of 1 / sunJitter^2). 0 = from the
    // directions (sunJitterFor).
    int sunJitter = 0;
    // Direct light from emissive triangles: Explicit = exact polygon form
    // factor times visibility from `emitterSamples` shadow cube maps (small
    // area lights, which uniform bundle directions rarely see); Bundles = the
    // bundles carry emission like any radiance; Auto = Explicit when emitters
    // are at most 1024 triangles and 25% of the surface area.
    enum class DirectLight { Auto, Explicit, Bundles } directLight = DirectLight::Auto;
    // visibility samples over all explicit emitters (>= 1 per triangle); 0 =
    // max(128, directions / 4), so that the direct light's noise keeps
    // falling with the directions as the bounces' does
    int emitterSamples = 0;
    int emitterShadowSize = 0;        // cube face size of each sample's distance map; 0 = from the bundle
                                      // resolution (4 cube texels per bundle pixel), 64..512
    // Directions shared with other bakers (MPI ranks; bake/direction_share.h):
    // this one bakes every count()-th direction and combines accumulators with
    // the others at each refresh. Null: the bake is this baker's alone.
    std::shared_ptr<DirectionShare> share;
    // > 0: stop once the estimated relative noise of the light maps is at most
    // this (checked at radiance refreshes, from 16 directions on); `directions` is then the most
    double targetNoise = 0;
    // 2: bake every light map texel as 2 x 2 half-size ones and reduce them to
    // it, each weighted by its part of the texel's footprint (bake/supersample.h):
    // the bounced light is read at twice the resolution. 4x the texels and
    // light-map state, about 2x the time. 4: 4 x 4 quarter-size ones (16x the
    // texels, about 3x the time of 2). 1: texels as laid out. 0: as
    // autoSupersample decides by the layout and the memory budget
    // (BakeStats::supersample says which).
    int supersample = 1;
    // The resolution probe (bake/resolution_probe.cpp), after the last
    // direction of a supersampled bake: this many directions gathered three
    // times, reading the radiance at the baked texels, the output's and twice
    // the output's, whose differences estimate the bias of reading light at
    // the light map's resolution (BakeStats::noiseResolution). 0: none; -1:
    // the directions / 64, at least 8, from 256 directions on.
    int resolutionProbe = 0;
};

// The resolution probe's directions for `options` (0: none).
int resolutionProbeDirections(const BakeOptions& options);

// The most sun passes per axis: a texel's sample count is held in fp16 (exact to 2048).
constexpr int kMaxSunJitter = 45;

// The sun's passes per axis for `options`: sunJitter, or from the directions
// sqrt(directions / 16) in [2, 16], so that the shadow edges' error falls
// with the bundles' (mixed_lighting stopped at 6.5 % with 4). The cap was 8
// until 2026-12-06: mixed_lighting's sun light alone (albedo 0, against a
// 16384-spp reference) reads 0.39 / 0.31 / 0.31 % with 8 / 16 / 32 a side,
// so past 16 what is left is the footprint's, not the sun's sampling.
int sunJitterFor(const BakeOptions& options);

// Figures every bake reports (stats.json).
struct BakeStats {
    int directionsDone = 0;
    int directionsTotal = 0;
    double bundleResolution = 0;      // pixels across the bounding sphere (the uniform grid)
    double pixelSize = 0;             // scene units (the uniform grid's; tiles: tilePixelSizes)
    double historyPower = 0;
    int historyPlateau = 0;           // rounds: the ramp's weights are equal from this one on
    double transportAlbedo = 0;       // the light's share kept per bounce (bake/transport_albedo.h)
    double transportAlbedoSlowest = 0;  // the share a pocket that keeps its light longest keeps (its `slowest`)
    double radianceUnit = 1;          // the light-map state holds radiance / this (a power of two; fp16 range)
    int64_t tilesDrawn = 0;
    int64_t leafRunUpdates = 0;       // update passes over a run of several whole leaves at once (bundle_tracer.h)
    int64_t overflows = 0;            // tile draws whose node count exceeded the buffer: redrawn (bigger buffer, or split)
    int64_t fragments = 0;            // nodes appended (kept) for the tiles' own pixels, over all tiles
    int64_t updatedTexels = 0;        // texel samples accumulated
    int64_t peakNodesPerTile = 0;
    int64_t nodeCapacity = 0;
    int64_t nodeBufferBytes = 0;
    int64_t headImageBytes = 0;
    int64_t peakGpuBytes = 0;
    int64_t memoryBudget = 0;
    int64_t lightmapStateBytes = 0;   // the light-map textures (accumulators, radiance, direct, dilation)
    std::map<std::string, int64_t> peakGpuBytesByCategory;  // MemoryCategory names
    int64_t lightmapTexels = 0;
    int64_t coveredTexels = 0;
    int64_t sharedTexels = 0;  // covered texels another chart also overlaps (layout/bake_mesh.h sharedTexels)
    int64_t curvedTexels = 0;  // covered texels whose chart folds or curves within them (layout/bake_mesh.h curvedTexels)
                               // and partial texels (texelOwners), which are drawn as curved ones
    int64_t partialTexels = 0;      // covered texels whose centre is on no chart (layout/bake_mesh.h texelOwners)
    int64_t exactFootprintTexels = 0;  // flat ones among the curved whose points their triangles keep (CurvedTexel::exact)
    // supersampled bakes (BakeOptions::supersample; the texel counts above are
    // the half-size ones): texels of the layout filled from their neighbours by the last
    // readLightmaps (LightmapPages::filledTexels)
    int64_t supersampleFilledTexels = 0;
    int64_t supersampleLostTexels = 0;  // left as padding (no neighbour on their chart either)
    int supersample = 1;  // baked texels a texel across (BakeOptions::supersample, auto resolved)
    int64_t curvedTexelBytes = 0;   // their records (bake/curved_footprints.h), part of lightmapStateBytes
    std::vector<double> predictedOverActual;  // per tile: predicted nodes / actual nodes
    std::vector<int> tilesPerDirection;
    std::vector<int> leavesPerDirection;
    std::vector<float> tilePixelSizes;        // per tile drawn without overflow, scene units
    int64_t curvatureRefinedTriangles = 0;    // receivers whose curvature asks finer pixels than their texels
    int64_t triangles = 0;
    int64_t clusters = 0;
    int64_t bundleTrianglesDrawn = 0;         // over all bundle-pass draws (culling: << triangles x tiles)
    int64_t updateTrianglesDrawn = 0;         // over all update-pass draws
    bool explicitEmitters = false;
    int emitterSampleCount = 0;
    int sunJitter = 0;  // the sun's passes per axis (sunJitterFor); 0 without a sun
    double secondsEmitters = 0;
    double secondsImportance = 0;     // part of setup
    double secondsTiling = 0;         // cluster projection, quadtree and prediction (CPU), per direction
    double secondsSetup = 0, secondsSun = 0, secondsBundle = 0, secondsUpdate = 0, secondsResolve = 0;
    // shared bakes: accumulators combined at refreshes (read back, summed with
    // the other bakers, stored), and the bytes this baker sent to the sum each time
    int64_t combines = 0;
    int64_t combineBytes = 0;
    double secondsCombine = 0;        // all of it, including the share's waiting and transfer
    // The noise estimate (noise.cpp): the light maps' relative error without a
    // reference, sqrt(noiseHalves^2 + noiseLag^2); < 0: not yet estimated
    double noiseRelative = -1;
    double noiseHalves = 0;           // RMS of the maps' standard deviation over their mean (odd and even halves)
    double noiseDirect = 0;           // of which the direct light's: explicit emitters' and suns' (their odd and even samples)
    double noiseLag = 0;              // RMS of the bounces still to come over the maps' mean (bounceLag)
    int noiseStride = 1;              // every noiseStride-th texel of each axis is sampled
    int64_t noiseTexels = 0;          // sampled texels the last estimate used
    std::vector<std::pair<int, double>> noiseHistory;  // (directions done, noiseRelative) at refreshes
    bool stoppedAtTargetNoise = false;
    // The resolution probe's estimate (bake/resolution_probe.cpp): the RMS of
    // the bias of reading the light at the light map's resolution, over the
    // maps' mean, at the same texels; < 0: not probed. Not in noiseRelative
    // (more directions do not lower it); errorEstimate() adds the two.
    double noiseResolution = -1;
    int resolutionProbeDirections = 0;
    double resolutionOrder = 0;      // p in the bias's h^p, from the probe's two steps, in [1, 2]; 0: none in range
    double resolutionPastRange = 0;  // share of what coarser reads change in texels past Richardson's range
    double secondsProbe = 0;
    double errorEstimate() const {
        return noiseResolution < 0 || noiseRelative < 0 ? noiseRelative : std::hypot(noiseRelative, noiseResolution);
    }
    double secondsTotal() const {
        return secondsSetup + secondsSun + secondsEmitters + secondsTiling + secondsBundle + secondsUpdate +
               secondsResolve + secondsCombine + secondsProbe;
    }
    nlohmann::json toJson() const;
};

struct BakeProgress {
    int directionsDone = 0;
    int directionsTotal = 0;
    bool midDirection = false;  // stepTiles stopped between a direction's tiles
    // shared bakes: the accumulators are combined (the last round ended on a
    // refresh), so a checkpoint may be written now
    bool combined = true;
    bool done() const { return directionsDone >= directionsTotal; }
};

// BakeOptions::historyPower < 0: round(2 rho / (1 - rho)^1.5) in [1, 1024] for
// the scene's transport albedo rho (capped at 0.99): the more bounces light
// needs, the faster the early directions fade (docs/design-notes.md).
double defaultHistoryPower(double transportAlbedo);

// The light maps of a bake: one image per page, L_lm = E/pi (DESIGN.md Units),
// texel row 0 = v 0 (GL order), padding dilated. `covered` marks texels whose
// centre lies on a triangle.
struct LightmapPages {
    int resolution = 0;
    std::vector<io::ImageRgb> pages;
    std::vector<std::vector<uint8_t>> covered;
    // covered texels a supersampled bake's reduction filled from their neighbours (bake/supersample.h)
    int64_t filledTexels = 0;
    int64_t lostTexels = 0;  // and those left as padding: no neighbour on their chart either
};

class Baker {
public:
    // Clusters the scene's triangles and analyzes their importance (the tiler's
    // inputs), uploads it, rasterizes albedo/emission into light map space and
    // bakes the direct light. Errors: scene too large for the GL limits, bad options.
    static Expected<std::unique_ptr<Baker>> create(const Scene& scene, const Layout& layout, const BakeOptions& options);
    ~Baker();

    // Bakes directions until `seconds` have passed (at least one direction,
    // unless done). Deterministic whatever the budget: the same directions in
    // the same order give the same bytes.
    BakeProgress step(double seconds);
    // The same, tile by tile: stops once `seconds` have passed (after at least
    // one tile), possibly between a direction's tiles, so one call costs about
    // one tile, not one direction (the viewer's frame budget). The tiles and
    // their order are those of step(): the same bytes in the end.
    BakeProgress stepTiles(double seconds);
    BakeProgress progress() const;

    // Checkpoints: the accumulators and progress, written atomically. A bake
    // restored from a checkpoint continues to the same bytes an uninterrupted
    // bake gives. loadCheckpoint fails (one line) if the file is not a
    // checkpoint of this scene, layout and options.
    Status saveCheckpoint(const std::string& path);
    Status loadCheckpoint(const std::string& path);

    // Reads the current light maps back (resolve + dilate on the GPU).
    LightmapPages readLightmaps();
    // Raw accumulator read-back for tests: per page, per texel (mean R, G, B of the
    // cosine-weighted incoming radiance, weight W) as stored (bake/rounding.h's accumulator).
    std::vector<std::vector<glm::vec4>> readAccumulators();

    // One bundle along d drawn as a single tile, read back (tests, tools):
    // per pixel, the depths of its list (sorted), and the frame to cast rays
    // through pixel centres on the CPU. Precondition: the bundle fits one tile.
    struct BundleCapture {
        glm::vec3 dir{0.0f}, u{0.0f}, v{0.0f};
        glm::vec2 origin{0.0f};   // (u, v) of pixel (0, 0)'s lower-left corner
        float pixelSize = 0.0f;
        int width = 0, height = 0;
        uint32_t nodeCount = 0;   // the atomic counter
        std::vector<std::vector<float>> depths;       // [y * width + x], ascending
        std::vector<std::vector<uint32_t>> flags;     // NODE_VISIBLE_* per depth (same order)
        std::vector<std::vector<glm::vec3>> radiance; // decoded RGBE per depth (same order)
        bool listsWellFormed = true;                  // no cycle, every index < nodeCount
    };
    BundleCapture captureBundle(const glm::vec3& dir);

    const BakeStats& stats() const;
    const BakeMesh& mesh() const;

    // --- live view (viewer, render tests) -------------------------------------
    // Resolves the current light maps into the texture lightmapTextureId()
    // names (made on the first call: 16 bytes a page texel, outside the bake's
    // state), on the GPU, without reading back. One compute pass over the pages.
    void resolveLightmaps();
    // GL name of the resolved light maps: RGBA32F 2D array, one layer per page,
    // rgb = L_lm (E/pi), a = 1 where a value exists (padding dilated). Owned by
    // the Baker; 0 before the first resolveLightmaps(), which fills it.
    uint32_t lightmapTextureId() const;
    // The bundle plane of the latest direction (direction 0's uniform grid
    // before any), for overlays: frame, the finest leaf's pixel grid over the
    // root square, and that leaf's side in pixels as the tile step.
    struct BundleGrid {
        glm::vec3 dir{0.0f, 0.0f, 1.0f}, u{1.0f, 0.0f, 0.0f}, v{0.0f, 1.0f, 0.0f};
        glm::vec2 origin{0.0f};  // (u, v) of pixel (0, 0)'s lower-left corner
        float pixelSize = 1.0f;  // scene units
        int gridSize = 1;        // pixels across the bundle
        int tileStep = 1;        // pixels per tile side
        int tiles = 0;           // tiles drawn for that direction (with splits); 0 before any
    };
    BundleGrid bundleGrid() const;

    struct Impl;

private:
    explicit Baker(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace bb
