// CPU reference baker: path tracing from light map texel footprints on Embree 3.
// See reference_baker.h for the model and the sampling; the notes here are
// about how.
#include "reference/reference_baker.h"
#include "bake/supersample.h"
#include "reference/embree_mesh.h"
#include "scene/punctual_light.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include <embree3/rtcore.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#define BB_HAVE_SSE_FTZ 1
#endif

#include "core/check.h"
#include "core/hash.h"
#include "core/timer.h"
#include "core/log.h"

namespace bb {
namespace {


constexpr float PI = 3.14159265358979323846f;
constexpr float INV_PI = 1.0f / PI;

// --- random numbers -----------------------------------------------------------


// PCG32 (O'Neill 2014), one stream per (texel, sample).
struct Pcg32 {
    uint64_t state = 0, inc = 1;
    explicit Pcg32(uint64_t seed) : state(0), inc((mix64(seed ^ 0x5851F42D4C957F2Dull) << 1) | 1u) {
        next();
        state += mix64(seed);
        next();
    }
    uint32_t next() {
        uint64_t old = state;
        state = old * 6364136223846793005ull + inc;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }
    float uniform() { return std::min(float(next()) * 0x1p-32f, 0x1.fffffep-1f); }
};

uint32_t reverseBits(uint32_t v) {
    v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
    v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
    return (v >> 16) | (v << 16);
}
// The first two Sobol' dimensions (a (0,2)-sequence), as 0.32 fixed point.
uint32_t sobol0(uint32_t i) { return reverseBits(i); }
uint32_t sobol1(uint32_t i) {
    uint32_t r = 0;
    for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}
// Sobol' dimensions 3 and 4 (Joe and Kuo 2008, new-joe-kuo-6.21201: s = 2,
// a = 1, m = 1 3 and s = 3, a = 1, m = 1 3 1), one column per index bit. They
// place a sample within its texel: with dimensions 1 and 2 (the direction)
// the four form a 4D Sobol' sequence, so position and direction are
// stratified jointly (the pair alone is a (t,2)-sequence with t <= 2).
constexpr std::array<uint32_t, 32> sobolColumns(int s, uint32_t a, std::array<uint32_t, 3> m) {
    std::array<uint32_t, 32> v{};
    for (int k = 0; k < 32; ++k) {
        if (k < s) {
            v[size_t(k)] = m[size_t(k)] << (31 - k);
            continue;
        }
        uint32_t x = v[size_t(k - s)] ^ (v[size_t(k - s)] >> s);
        for (int j = 1; j < s; ++j)
            if ((a >> (s - 1 - j)) & 1u) x ^= v[size_t(k - j)];
        v[size_t(k)] = x;
    }
    return v;
}
constexpr std::array<uint32_t, 32> SOBOL2 = sobolColumns(2, 1, {1, 3, 0});
constexpr std::array<uint32_t, 32> SOBOL3 = sobolColumns(3, 1, {1, 3, 1});
uint32_t sobol(uint32_t i, const std::array<uint32_t, 32>& columns) {
    uint32_t r = 0;
    for (size_t k = 0; i; i >>= 1, ++k)
        if (i & 1u) r ^= columns[k];
    return r;
}
// Owen scrambling by hashing (Laine and Karras 2011; constants of pbrt-v4's FastOwenScrambler).
uint32_t owenScramble(uint32_t v, uint32_t seed) {
    v = reverseBits(v);
    v ^= v * 0x3d20adeau;
    v += seed;
    v *= (seed >> 16) | 1u;
    v ^= v * 0x05526c56u;
    v ^= v * 0x53a22864u;
    return reverseBits(v);
}
float unit(uint32_t v) { return std::min(float(v) * 0x1p-32f, 0x1.fffffep-1f); }

// Per-texel scrambles of the low-discrepancy dimensions (first vertex and the
// point in the texel).
struct Scrambles {
    uint32_t dir0, dir1, light0, light1, pos0, pos1;
};
Scrambles makeScrambles(uint64_t key) {
    uint64_t a = hash(key, 0xA11CEull), b = hash(key, 0xB0Bull), c = hash(key, 0xC0DEull);
    return {uint32_t(a), uint32_t(a >> 32), uint32_t(b), uint32_t(b >> 32), uint32_t(c), uint32_t(c >> 32)};
}

// --- sampling -----------------------------------------------------------------

// Shirley-Chiu concentric map, then Malley's method: pdf = cos / pi.
glm::vec3 cosineHemisphere(float u1, float u2) {
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    float r = 0.0f, phi = 0.0f;
    if (a != 0.0f || b != 0.0f) {
        if (std::fabs(a) > std::fabs(b)) {
            r = a;
            phi = (PI / 4.0f) * (b / a);
        } else {
            r = b;
            phi = PI / 2.0f - (PI / 4.0f) * (a / b);
        }
    }
    float x = r * std::cos(phi), y = r * std::sin(phi);
    return {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y))};
}

// Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
void basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
    float s = std::copysign(1.0f, n.z);
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = glm::vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}

float maxComponent(const glm::vec3& v) { return std::max({v.x, v.y, v.z}); }

// Bilinear, repeating, level 0; texels row 0 = v 0 (glTF), as GL samples the uploaded image.
glm::vec3 sampleTexture(const Texture& t, glm::vec2 uv) {
    if (t.width <= 0 || t.height <= 0) return glm::vec3(1.0f);
    float x = uv.x * float(t.width) - 0.5f, y = uv.y * float(t.height) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y)) return glm::vec3(t.texels[0]);
    float fx0 = std::floor(x), fy0 = std::floor(y);
    float fx = x - fx0, fy = y - fy0;
    auto wrap = [](int64_t i, int n) { return int((i % n + n) % n); };
    int x0 = wrap(int64_t(fx0), t.width), x1 = wrap(int64_t(fx0) + 1, t.width);
    int y0 = wrap(int64_t(fy0), t.height), y1 = wrap(int64_t(fy0) + 1, t.height);
    auto at = [&](int px, int py) { return glm::vec3(t.texels[size_t(py) * t.width + px]); };
    return glm::mix(glm::mix(at(x0, y0), at(x1, y0), fx), glm::mix(at(x0, y1), at(x1, y1), fx), fy);
}

// A point being lit: the side of its surface that `ns` (shading) faces, `ng`
// the geometric normal turned to that side.
struct SurfacePoint {
    glm::vec3 p{0.0f}, ns{0.0f, 1.0f, 0.0f}, ng{0.0f, 1.0f, 0.0f};
    uint32_t triangle = kNoTriangle;  // the triangle p lies on (its rays skip it), if known
};

struct Counters {
    int64_t paths = 0, rays = 0, shadowRays = 0;
};

// A part of a texel's footprint on one triangle, in texel-local page space
// (the texel is [0,1]^2): the triangle origin, origin + e1, origin + e2, or,
// for a texel wholly inside its triangle, the square origin + u e1 + v e2.
struct FootprintPiece {
    uint32_t triangle = 0;
    uint32_t square = 0;  // 1: the parallelogram (u, v in [0,1)^2), 0: the triangle
    float cdf = 1.0f;     // area of this piece and the texel's pieces before it / the footprint's area
    glm::vec2 origin{0.0f}, e1{0.0f}, e2{0.0f};
};

struct Texel {
    uint32_t page = 0;
    uint32_t index = 0;       // y * resolution + x
    uint32_t firstPiece = 0;  // its footprint: pieces [firstPiece, firstPiece + pieceCount)
    uint32_t pieceCount = 0;
};

}  // namespace

nlohmann::json ReferenceStats::toJson() const {
    nlohmann::json j;
    j["spp"] = sppDone;
    j["spp_total"] = sppTotal;
    j["threads"] = threads;
    j["passes"] = passes;
    j["lightmap"] = {{"texels", lightmapTexels}, {"covered_texels", coveredTexels}};
    j["emitter_triangles"] = emitterTriangles;
    j["paths"] = paths;
    j["rays"] = rays;
    j["shadow_rays"] = shadowRays;
    double total = double(rays + shadowRays);
    j["rays_per_second"] = secondsTrace > 0 ? total / secondsTrace : 0.0;
    j["seconds"] = {{"setup", secondsSetup}, {"trace", secondsTrace}, {"total", secondsSetup + secondsTrace}};
    return j;
}

struct ReferenceBaker::Impl {
    ReferenceOptions options;
    Layout layout;
    BakeMesh mesh;
    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<DirectionalLight> lights;
    std::vector<PunctualLight> punctualLights;
    ReferenceStats stats;

    std::vector<glm::vec3> triNormal;     // geometric, unit, counter-clockwise front
    std::vector<float> lightPdfArea;      // per triangle: P(pick it) / its area (0: not sampled)
    std::vector<uint32_t> emitters;       // emissive triangles
    std::vector<float> emitterCdf;        // over emitters, by area x mean emission factor
    float eps = 1e-5f;                    // ray offset off a surface of no known triangle (a probe point), scene units

    std::vector<Texel> texels;
    std::vector<FootprintPiece> pieces;   // the texels' footprints
    std::vector<glm::dvec3> sums;         // per texel, over the samples done

    RTCDevice device = nullptr;
    RTCScene rtcScene = nullptr;

    ~Impl() {
        if (rtcScene) rtcReleaseScene(rtcScene);
        if (device) rtcReleaseDevice(device);
    }

    Status init(const Scene& scene);
    void findTexels();
    SurfacePoint footprintPoint(const Texel& texel, float u1, float u2) const;
    template <class F>
    void forEachTexel(F&& f);
    glm::dvec4 texelSamples(size_t i, uint64_t seed, uint32_t first, uint32_t count, Counters& c) const;
    void runPass(int first, int count);
    glm::vec3 sample(const SurfacePoint& start, uint32_t sampleIndex, uint64_t key, const Scrambles& s,
                     Counters& counters) const;

    glm::vec3 rayOrigin(const SurfacePoint& x) const;
    glm::vec3 environment(const glm::vec3& dir) const;
    glm::vec3 albedoAt(const Material& m, glm::vec2 uv0) const;
    glm::vec3 emissionAt(const Material& m, glm::vec2 uv0) const;
    glm::vec3 directLight(const SurfacePoint& x, const glm::vec3& beta, float u1, float u2, Counters& counters) const;
    glm::vec3 punctualLight(const SurfacePoint& x, Counters& counters) const;
};

void embreeError(void*, RTCError code, const char* message) {
    logError(std::string("embree: error ") + std::to_string(int(code)) + ": " + (message ? message : ""));
}

Status ReferenceBaker::Impl::init(const Scene& scene) {
    auto t0 = Clock::now();
    if (options.spp < 1) return Status::error("--spp must be at least 1");
    if (options.passSpp < 1) return Status::error("the pass size must be at least 1 sample");
    if (options.threads < 0) return Status::error("--threads must be >= 0");
    if (options.rouletteDepth < 1 || options.maxBounces < 1)
        return Status::error("roulette depth and bounce cap must be at least 1");
    if (mesh.triangles.empty()) return Status::error("nothing to bake: the scene has no triangles");
    if (options.threads == 0) options.threads = int(std::max(1u, std::thread::hardware_concurrency()));
    materials = scene.materials;
    textures = scene.textures;
    lights = scene.lights;
    punctualLights = scene.punctualLights;
    stats.sppTotal = options.spp;
    stats.threads = options.threads;
    stats.lightmapTexels = int64_t(layout.texelCount());

    eps = rayOffset(mesh);

    // triangles: geometric normals and the emitter distribution
    const size_t n = mesh.triangles.size();
    triNormal.resize(n);
    lightPdfArea.assign(n, 0.0f);
    std::vector<float> area(n);
    for (size_t t = 0; t < n; ++t) {
        const glm::vec3 a(mesh.vertices[3 * t].position), b(mesh.vertices[3 * t + 1].position),
            c(mesh.vertices[3 * t + 2].position);
        glm::vec3 cr = glm::cross(b - a, c - a);
        float len = glm::length(cr);
        area[t] = 0.5f * len;
        triNormal[t] = len > 0.0f ? cr / len : glm::vec3(0.0f);
    }
    double total = 0.0;
    for (size_t t = 0; t < n; ++t) {
        const Material& m = materials[mesh.triangles[t].material];
        float power = (m.emission.r + m.emission.g + m.emission.b) / 3.0f * area[t];
        if (power > 0.0f && area[t] > 0.0f) {
            emitters.push_back(uint32_t(t));
            total += power;
            emitterCdf.push_back(float(total));
        }
    }
    for (size_t k = 0; k < emitters.size(); ++k) {
        emitterCdf[k] = float(emitterCdf[k] / total);
        const Material& m = materials[mesh.triangles[emitters[k]].material];
        lightPdfArea[emitters[k]] = float((m.emission.r + m.emission.g + m.emission.b) / 3.0 / total);
    }
    if (!emitterCdf.empty()) emitterCdf.back() = 1.0f;
    stats.emitterTriangles = int64_t(emitters.size());

    // BVH
    std::string config = "threads=" + std::to_string(options.threads);
    device = rtcNewDevice(config.c_str());
    if (!device) return Status::error("embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device, embreeError, nullptr);
    rtcScene = commitBakeMeshScene(device, mesh, RTC_BUILD_QUALITY_HIGH);
    if (!rtcScene) return Status::error("embree: scene build failed (error " + std::to_string(int(rtcGetDeviceError(device))) + ")");

    findTexels();
    sums.assign(texels.size(), glm::dvec3(0.0));
    stats.coveredTexels = int64_t(texels.size());
    stats.secondsSetup = secondsSince(t0);
    return Status::ok();
}

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Barycentrics moved a hair (1e-5 of the way) towards the centroid, clamped
// into the triangle first. A surface point on (or rounded past) an edge where
// two walls of a closed surface meet starts its rays on the other wall's plane
// or behind it, and they leave through the seam: the furnace lost 5.8 % (up to
// 73 % per texel) where texel centres lay on chart borders, and a path here
// and there where a hit fell on an edge.
glm::dvec3 inset(glm::dvec3 w) {
    constexpr double INSET = 1e-5;
    w = glm::max(w, glm::dvec3(0.0));
    const double sum = w.x + w.y + w.z;
    w = sum > 0.0 && std::isfinite(sum) ? w / sum : glm::dvec3(1.0 / 3.0);
    return w * (1.0 - INSET) + glm::dvec3(INSET / 3.0);
}

}  // namespace

// Coverage: texel centres inside triangles in page space. The triangles of a
// page are visited in the GPU meta pass's order (stable by material), the last
// one covering a centre owns it, as with GL's draw order and no depth test.
// Footprint: the part of the texel's square on the owner's chart, as pieces
// (the square clipped to each of the chart's triangles).
void ReferenceBaker::Impl::findTexels() {
    const int res = layout.resolution;
    const std::vector<uint32_t> chart = findLightmapCharts(mesh);
    for (int page = 0; page < layout.pageCount; ++page) {
        const std::vector<uint32_t> order = pageDrawOrder(mesh, page);
        const std::vector<int32_t> owner = texelOwners(mesh, page, res);
        std::vector<int64_t> slot(owner.size(), -1);  // texel -> index into texels
        const size_t firstTexel = texels.size();
        for (size_t i = 0; i < owner.size(); ++i) {
            if (owner[i] < 0 || (options.texelFilter && !options.texelFilter(uint32_t(page), uint32_t(i)))) continue;
            slot[i] = int64_t(texels.size());
            Texel texel;
            texel.page = uint32_t(page);
            texel.index = uint32_t(i);
            texels.push_back(texel);
        }

        // footprints: every triangle against the covered texels its bounds touch
        std::vector<std::pair<uint32_t, FootprintPiece>> found;  // (texel, piece)
        for (uint32_t t : order) {
            glm::dvec2 q[3];
            const double absArea = pageCorners(mesh, t, res, q);
            if (absArea == 0.0 || !std::isfinite(absArea)) continue;
            double minX = std::min({q[0].x, q[1].x, q[2].x}), maxX = std::max({q[0].x, q[1].x, q[2].x});
            double minY = std::min({q[0].y, q[1].y, q[2].y}), maxY = std::max({q[0].y, q[1].y, q[2].y});
            int x0 = std::max(0, int(std::floor(minX))), x1 = std::min(res - 1, int(std::ceil(maxX)) - 1);
            int y0 = std::max(0, int(std::floor(minY))), y1 = std::min(res - 1, int(std::ceil(maxY)) - 1);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const size_t i = size_t(y) * res + x;
                    if (slot[i] < 0 || chart[size_t(owner[i])] != chart[t]) continue;
                    const glm::dvec2 origin(x, y);
                    const glm::dvec2 local[3] = {q[0] - origin, q[1] - origin, q[2] - origin};
                    const std::vector<glm::dvec2> poly = clipSquare(local);
                    if (poly.size() < 3) continue;
                    FootprintPiece piece;
                    piece.triangle = t;
                    const uint32_t texel = uint32_t(slot[i]);
                    if (poly.size() == 4 && poly[0] == glm::dvec2(0, 0) && poly[1] == glm::dvec2(1, 0) &&
                        poly[2] == glm::dvec2(1, 1) && poly[3] == glm::dvec2(0, 1)) {
                        // the whole square: sampled as one (a (0,2)-net stays one)
                        piece.square = 1;
                        piece.cdf = 1.0f;  // area, until normalised below
                        piece.origin = glm::vec2(0.0f);
                        piece.e1 = glm::vec2(1.0f, 0.0f);
                        piece.e2 = glm::vec2(0.0f, 1.0f);
                        found.emplace_back(texel, piece);
                        continue;
                    }
                    for (size_t k = 1; k + 1 < poly.size(); ++k) {  // fan
                        const double area = 0.5 * cross2(poly[k] - poly[0], poly[k + 1] - poly[0]);
                        if (!(area > 0.0)) continue;
                        piece.cdf = float(area);
                        piece.origin = glm::vec2(poly[0]);
                        piece.e1 = glm::vec2(poly[k] - poly[0]);
                        piece.e2 = glm::vec2(poly[k + 1] - poly[0]);
                        found.emplace_back(texel, piece);
                    }
                }
        }
        std::stable_sort(found.begin(), found.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        size_t f = 0;
        for (size_t k = firstTexel; k < texels.size(); ++k) {
            Texel& texel = texels[k];
            texel.firstPiece = uint32_t(pieces.size());
            double total = 0.0;
            for (; f < found.size() && found[f].first == k; ++f) {
                total += found[f].second.cdf;
                pieces.push_back(found[f].second);
                pieces.back().cdf = float(total);
            }
            texel.pieceCount = uint32_t(pieces.size() - texel.firstPiece);
            if (!(total > 0.0)) {
                // no area found (a sliver, rounding): the centre, as a point
                FootprintPiece centre;
                centre.triangle = uint32_t(owner[texel.index]);
                centre.square = 1;
                centre.origin = glm::vec2(0.5f);
                pieces.resize(texel.firstPiece);
                pieces.push_back(centre);
                texel.pieceCount = 1;
                continue;
            }
            for (uint32_t p = texel.firstPiece; p < texel.firstPiece + texel.pieceCount; ++p)
                pieces[p].cdf = float(pieces[p].cdf / total);
            pieces[texel.firstPiece + texel.pieceCount - 1].cdf = 1.0f;
        }
    }
}

// A point of the texel's footprint, uniform in page space for (u1, u2)
// uniform in [0,1)^2, with its own position and normals.
SurfacePoint ReferenceBaker::Impl::footprintPoint(const Texel& texel, float u1, float u2) const {
    // the piece by area with u1, then u1 reused within its interval (stays stratified)
    const FootprintPiece* first = &pieces[texel.firstPiece];
    const FootprintPiece* last = first + texel.pieceCount - 1;
    const FootprintPiece* piece = first;
    while (piece < last && u1 >= piece->cdf) ++piece;
    const float lo = piece > first ? piece[-1].cdf : 0.0f;
    u1 = piece->cdf > lo ? std::clamp((u1 - lo) / (piece->cdf - lo), 0.0f, 0x1.fffffep-1f) : 0.5f;
    glm::dvec2 local;
    if (piece->square) {
        local = glm::dvec2(piece->origin) + double(u1) * glm::dvec2(piece->e1) + double(u2) * glm::dvec2(piece->e2);
    } else {
        const double su = std::sqrt(double(u1));
        local = glm::dvec2(piece->origin) + u2 * su * glm::dvec2(piece->e1) + (1.0 - u2) * su * glm::dvec2(piece->e2);
    }
    // barycentrics in the owner triangle (page space relative to the texel, in double)
    const int res = layout.resolution;
    const uint32_t t = piece->triangle;
    const BakeVertex* v = &mesh.vertices[3 * size_t(t)];
    const glm::dvec2 origin(double(texel.index % uint32_t(res)), double(texel.index / uint32_t(res)));
    glm::dvec2 q[3];
    for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(v[k].lightmapUv) * double(res) - origin;
    const double area2 = cross2(q[1] - q[0], q[2] - q[0]);
    glm::dvec3 w(cross2(q[2] - q[1], local - q[1]), cross2(q[0] - q[2], local - q[2]), cross2(q[1] - q[0], local - q[0]));
    w = inset(w / area2);
    SurfacePoint x;
    x.p = glm::vec3(w.x * glm::dvec3(v[0].position) + w.y * glm::dvec3(v[1].position) + w.z * glm::dvec3(v[2].position));
    glm::vec3 ns = glm::vec3(w.x * glm::dvec3(v[0].normal) + w.y * glm::dvec3(v[1].normal) + w.z * glm::dvec3(v[2].normal));
    const glm::vec3 ng = triNormal[t];
    const float len = glm::length(ns);
    x.ns = len > 0.0f && std::isfinite(len) ? ns / len : ng;
    x.ng = glm::dot(x.ns, ng) >= 0.0f ? ng : -ng;  // the geometric normal on the side the texel looks at
    x.triangle = t;
    return x;
}

// Where x's rays start: on its triangle, which they skip (SkipContext), or,
// for a probe point off any known triangle, off the surface by eps.
glm::vec3 ReferenceBaker::Impl::rayOrigin(const SurfacePoint& x) const {
    return x.triangle != kNoTriangle ? x.p : x.p + x.ng * eps;
}

glm::vec3 ReferenceBaker::Impl::environment(const glm::vec3& dir) const {
    if (!options.environment) return options.sky;
    const io::ImageRgb& env = *options.environment;
    if (env.width <= 0 || env.height <= 0) return glm::vec3(0.0f);
    float u = 0.5f + std::atan2(dir.z, dir.x) / (2.0f * PI);
    float v = std::acos(std::clamp(dir.y, -1.0f, 1.0f)) / PI;
    float x = u * float(env.width) - 0.5f, y = std::clamp(v * float(env.height) - 0.5f, 0.0f, float(env.height - 1));
    float fx0 = std::floor(x), fy0 = std::floor(y);
    float fx = x - fx0, fy = y - fy0;
    auto wrap = [&](int64_t i) { return int((i % env.width + env.width) % env.width); };
    int x0 = wrap(int64_t(fx0)), x1 = wrap(int64_t(fx0) + 1);
    int y0 = int(fy0), y1 = std::min(y0 + 1, env.height - 1);
    return glm::mix(glm::mix(env.at(x0, y0), env.at(x1, y0), fx), glm::mix(env.at(x0, y1), env.at(x1, y1), fx), fy);
}

glm::vec3 ReferenceBaker::Impl::albedoAt(const Material& m, glm::vec2 uv0) const {
    glm::vec3 a = m.albedo;
    if (m.albedoTexture >= 0 && size_t(m.albedoTexture) < textures.size())
        a *= sampleTexture(textures[size_t(m.albedoTexture)], uv0);
    return glm::clamp(a, glm::vec3(0.0f), glm::vec3(1.0f));
}

glm::vec3 ReferenceBaker::Impl::emissionAt(const Material& m, glm::vec2 uv0) const {
    glm::vec3 e = m.emission;
    if (m.emissionTexture >= 0 && size_t(m.emissionTexture) < textures.size())
        e *= sampleTexture(textures[size_t(m.emissionTexture)], uv0);
    return e;
}

// Suns (exact) and one emitter sample (MIS-weighted against cosine sampling) at
// x, as L_lm contributions times beta.
glm::vec3 ReferenceBaker::Impl::directLight(const SurfacePoint& x, const glm::vec3& beta, float u1, float u2,
                                            Counters& counters) const {
    glm::vec3 sum(0.0f);
    const glm::vec3 origin = rayOrigin(x);
    const SkipContext self(x.triangle);
    for (const DirectionalLight& light : lights) {
        const glm::vec3 toSun = -light.direction;
        float c = glm::dot(x.ns, toSun);
        if (c <= 0.0f || glm::dot(x.ng, toSun) <= 0.0f) continue;
        ++counters.shadowRays;
        if (!occludedRay(rtcScene, origin, toSun, std::numeric_limits<float>::infinity(), self))
            sum += light.irradiance * (c * INV_PI);
    }
    sum += punctualLight(x, counters);
    if (options.emitterSampling && !emitters.empty()) {
        // pick by power with u1, then reuse u1 within the pick's interval: the 2D
        // point stays stratified over all emitters together
        size_t k = size_t(std::upper_bound(emitterCdf.begin(), emitterCdf.end(), u1) - emitterCdf.begin());
        k = std::min(k, emitters.size() - 1);
        const float lo = k > 0 ? emitterCdf[k - 1] : 0.0f, hi = emitterCdf[k];
        u1 = hi > lo ? std::clamp((u1 - lo) / (hi - lo), 0.0f, 0x1.fffffep-1f) : 0.5f;
        const uint32_t t = emitters[k];
        const BakeVertex* v = &mesh.vertices[3 * size_t(t)];
        float su = std::sqrt(u1);
        float b0 = 1.0f - su, b1 = u2 * su, b2 = 1.0f - b0 - b1;
        glm::vec3 y = b0 * glm::vec3(v[0].position) + b1 * glm::vec3(v[1].position) + b2 * glm::vec3(v[2].position);
        glm::vec3 d = y - x.p;
        float dist2 = glm::dot(d, d);
        if (dist2 > 0.0f) {
            float dist = std::sqrt(dist2);
            glm::vec3 wi = d / dist;
            float cx = glm::dot(x.ns, wi);
            const BakeTriangle& tri = mesh.triangles[t];
            float cl = -glm::dot(triNormal[t], wi);
            if ((tri.flags & TRIANGLE_DOUBLE_SIDED) != 0u) cl = std::fabs(cl);
            if (cx > 0.0f && glm::dot(x.ng, wi) > 0.0f && cl > 1e-7f) {
                float pl = lightPdfArea[t] * dist2 / cl;
                float pb = cx * INV_PI;
                float w = pl * pl / (pl * pl + pb * pb);
                const Material& m = materials[tri.material];
                glm::vec2 uv0 = b0 * v[0].uv0 + b1 * v[1].uv0 + b2 * v[2].uv0;
                glm::vec3 le = emissionAt(m, uv0);
                if (maxComponent(le) > 0.0f) {
                    ++counters.shadowRays;
                    // aimed from the ray's origin (a ray along wi from an offset
                    // origin would cross the emitter's plane short of y when it
                    // leaves x at a grazing angle close above the emitter: the
                    // shared Cornell box's ceiling, 0.9 mm over its light, read
                    // 1.4 % dark), skipping the emitter's triangle: y lies on it;
                    // it ends 1e-5 of the way short of y, which may lie on an edge
                    // the emitter's neighbour shares
                    const glm::vec3 toY = y - origin;
                    const float len = glm::length(toY);
                    const float tfar = x.triangle != kNoTriangle ? len * 0.99999f : len - 2.0f * eps;
                    if (tfar > 0.0f && !occludedRay(rtcScene, origin, toY / len, tfar, SkipContext(x.triangle, t)))
                        sum += le * (pb / pl * w);
                }
            }
        }
    }
    return beta * sum;
}

// Point and spot lights at x (exact: closed-form irradiance, one shadow ray
// each), as L_lm contributions.
glm::vec3 ReferenceBaker::Impl::punctualLight(const SurfacePoint& x, Counters& counters) const {
    glm::vec3 sum(0.0f);
    const glm::vec3 origin = rayOrigin(x);
    const SkipContext self(x.triangle);
    const float margin = x.triangle != kNoTriangle ? 0.0f : 2.0f * eps;
    for (const PunctualLight& light : punctualLights) {
        const glm::vec3 position(light.position - mesh.origin);  // local space
        const glm::vec3 e = punctualIrradiance(light, position, x.p, x.ns);
        if (maxComponent(e) <= 0.0f) continue;
        const glm::vec3 toLight = position - origin;
        const float dist = glm::length(toLight);
        if (!(dist > margin) || glm::dot(x.ng, toLight) <= 0.0f) continue;
        ++counters.shadowRays;
        if (!occludedRay(rtcScene, origin, toLight / dist, dist - margin, self)) sum += e * INV_PI;
    }
    return sum;
}

// One path from `start`: an estimate of L_lm there (light arriving, not leaving).
glm::vec3 ReferenceBaker::Impl::sample(const SurfacePoint& start, uint32_t sampleIndex, uint64_t key,
                                       const Scrambles& s, Counters& counters) const {
    ++counters.paths;
    Pcg32 rng(hash(key, sampleIndex));
    glm::vec3 radiance(0.0f), beta(1.0f);
    SurfacePoint x = start;
    for (int depth = 0; depth < options.maxBounces; ++depth) {
        // light sources seen directly from x
        float ul1, ul2, ud1, ud2;
        if (depth == 0) {
            ul1 = unit(owenScramble(sobol0(sampleIndex), s.light0));
            ul2 = unit(owenScramble(sobol1(sampleIndex), s.light1));
            ud1 = unit(owenScramble(sobol0(sampleIndex), s.dir0));
            ud2 = unit(owenScramble(sobol1(sampleIndex), s.dir1));
        } else {
            ul1 = rng.uniform();
            ul2 = rng.uniform();
            ud1 = rng.uniform();
            ud2 = rng.uniform();
        }
        radiance += directLight(x, beta, ul1, ul2, counters);

        // continue along a cosine-weighted direction
        glm::vec3 t, b;
        basis(x.ns, t, b);
        const glm::vec3 local = cosineHemisphere(ud1, ud2);
        glm::vec3 w = glm::normalize(t * local.x + b * local.y + x.ns * local.z);
        const float cx = std::max(local.z, 0.0f);
        if (glm::dot(w, x.ng) <= 0.0f) break;  // below its own triangle: blocked
        RTCRayHit rh;
        ++counters.rays;
        if (!intersectRay(rtcScene, rayOrigin(x), w, rh, x.triangle)) {
            radiance += beta * environment(w);
            break;
        }
        const size_t tri = rh.hit.primID;
        const BakeTriangle& bt = mesh.triangles[tri];
        const glm::vec3 ng = triNormal[tri];
        const bool front = glm::dot(w, ng) < 0.0f;
        const bool doubleSided = (bt.flags & TRIANGLE_DOUBLE_SIDED) != 0u;
        if (!front && !doubleSided) break;  // the back of a single-sided surface: opaque black
        const BakeVertex* v = &mesh.vertices[3 * tri];
        const glm::vec3 bary = inset(glm::dvec3(1.0 - double(rh.hit.u) - double(rh.hit.v), rh.hit.u, rh.hit.v));
        const float hw = bary.x, hu = bary.y, hv = bary.z;
        const glm::vec3 p = hw * glm::vec3(v[0].position) + hu * glm::vec3(v[1].position) + hv * glm::vec3(v[2].position);
        const glm::vec2 uv0 = hw * v[0].uv0 + hu * v[1].uv0 + hv * v[2].uv0;
        const Material& m = materials[bt.material];

        // emission found by the cosine sample, MIS-weighted against the emitter sample
        if ((bt.flags & TRIANGLE_EMISSIVE) != 0u) {
            glm::vec3 le = emissionAt(m, uv0);
            float weight = 1.0f;
            if (options.emitterSampling && lightPdfArea[tri] > 0.0f) {
                glm::vec3 d = p - x.p;
                float cl = std::fabs(glm::dot(ng, w));
                float pl = cl > 0.0f ? lightPdfArea[tri] * glm::dot(d, d) / cl : std::numeric_limits<float>::infinity();
                float pb = cx * INV_PI;
                weight = std::isfinite(pl) ? pb * pb / (pb * pb + pl * pl) : 0.0f;
            }
            radiance += beta * le * weight;
        }

        beta *= albedoAt(m, uv0);
        if (maxComponent(beta) <= 0.0f) break;
        if (depth + 1 >= options.rouletteDepth) {
            float q = maxComponent(beta);
            if (q < 1.0f) {
                if (rng.uniform() >= q) break;
                beta /= q;
            }
        }

        // the next vertex: the side that was hit
        glm::vec3 ns = hw * glm::vec3(v[0].normal) + hu * glm::vec3(v[1].normal) + hv * glm::vec3(v[2].normal);
        float len = glm::length(ns);
        ns = len > 0.0f && std::isfinite(len) ? ns / len : ng;
        x.ng = front ? ng : -ng;
        x.ns = front ? ns : -ns;
        if (glm::dot(x.ns, x.ng) <= 0.0f) x.ns = x.ng;  // a shading normal bent past the face
        x.p = p;
        x.triangle = uint32_t(tri);
    }
    return radiance;
}

// Calls f(i, counters) for every texel i, on options.threads threads (chunks of
// 16 texels handed out in turn), and adds the threads' counters to the stats.
template <class F>
void ReferenceBaker::Impl::forEachTexel(F&& f) {
    const size_t chunk = 16;
    std::atomic<size_t> next{0};
    std::vector<Counters> counters(size_t(options.threads));
    auto work = [&](int thread) {
#ifdef BB_HAVE_SSE_FTZ
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
        Counters& c = counters[size_t(thread)];
        while (true) {
            size_t begin = next.fetch_add(chunk);
            if (begin >= texels.size()) break;
            size_t end = std::min(begin + chunk, texels.size());
            for (size_t i = begin; i < end; ++i) f(i, c);
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < options.threads; ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& t : pool) t.join();
    for (const Counters& c : counters) {
        stats.paths += c.paths;
        stats.rays += c.rays;
        stats.shadowRays += c.shadowRays;
    }
}

// Samples [first, first + count) of texel i's stream `seed`: their sum, and
// the sum of the squares of their channels' mean.
glm::dvec4 ReferenceBaker::Impl::texelSamples(size_t i, uint64_t seed, uint32_t first, uint32_t count,
                                              Counters& c) const {
    const Texel& texel = texels[i];
    const uint64_t key = hash(seed, texel.page, texel.index);
    const Scrambles s = makeScrambles(key);
    glm::dvec4 sum(0.0);
    for (uint32_t index = first; index < first + count; ++index) {
        const SurfacePoint start = footprintPoint(texel, unit(owenScramble(sobol(index, SOBOL2), s.pos0)),
                                                  unit(owenScramble(sobol(index, SOBOL3), s.pos1)));
        glm::vec3 value = sample(start, index, key, s, c);
        if (std::isfinite(value.x) && std::isfinite(value.y) && std::isfinite(value.z)) {
            const double mean = (double(value.x) + value.y + value.z) / 3.0;
            sum += glm::dvec4(glm::dvec3(value), mean * mean);
        }
    }
    return sum;
}

void ReferenceBaker::Impl::runPass(int first, int count) {
    forEachTexel([&](size_t i, Counters& c) {
        sums[i] += glm::dvec3(texelSamples(i, options.seed, uint32_t(first), uint32_t(count), c));
    });
}

ReferenceBaker::ReferenceBaker(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ReferenceBaker::~ReferenceBaker() = default;

Expected<std::unique_ptr<ReferenceBaker>> ReferenceBaker::create(const Scene& scene, const Layout& layout,
                                                                const ReferenceOptions& options) {
    auto impl = std::make_unique<Impl>();
    impl->options = options;
    impl->layout = layout;
    impl->mesh = buildBakeMesh(scene, layout);
    Status s = impl->init(scene);
    if (!s) return s;
    return std::unique_ptr<ReferenceBaker>(new ReferenceBaker(std::move(impl)));
}

ReferenceProgress ReferenceBaker::step(double seconds) {
    Impl& m = *impl_;
    auto t0 = Clock::now();
    while (m.stats.sppDone < m.options.spp) {
        int count = std::min(m.options.passSpp, m.options.spp - m.stats.sppDone);
        auto tp = Clock::now();
        m.runPass(m.stats.sppDone, count);
        m.stats.secondsTrace += secondsSince(tp);
        m.stats.sppDone += count;
        ++m.stats.passes;
        if (secondsSince(t0) >= seconds) break;
    }
    return progress();
}

ReferenceProgress ReferenceBaker::progress() const { return {impl_->stats.sppDone, impl_->options.spp}; }

LightmapPages ReferenceBaker::readLightmaps() const {
    const Impl& m = *impl_;
    const int res = m.layout.resolution;
    const size_t perPage = size_t(res) * res;
    LightmapPages out;
    out.resolution = res;
    std::vector<std::vector<glm::vec4>> maps(size_t(m.layout.pageCount), std::vector<glm::vec4>(perPage, glm::vec4(0.0f)));
    const double scale = m.stats.sppDone > 0 ? 1.0 / m.stats.sppDone : 0.0;
    for (size_t i = 0; i < m.texels.size(); ++i)
        maps[m.texels[i].page][m.texels[i].index] = glm::vec4(glm::vec3(m.sums[i] * scale), 1.0f);
    // dilation: an empty texel takes the mean of its filled 8-neighbours, padding + 1 times
    for (auto& map : maps) {
        std::vector<uint8_t> cov(perPage);
        for (size_t i = 0; i < perPage; ++i) cov[i] = map[i].w > 0.0f;
        out.pages.push_back(dilatedImage(std::move(map), res, m.layout.padding + 1));
        out.covered.push_back(std::move(cov));
    }
    return out;
}

std::vector<TexelId> ReferenceBaker::coveredTexels() const {
    std::vector<TexelId> out;
    out.reserve(impl_->texels.size());
    for (const Texel& t : impl_->texels) out.push_back({t.page, t.index});
    return out;
}

std::vector<glm::dvec4> ReferenceBaker::sampleTexels(uint64_t seed, const std::vector<uint32_t>& spp) {
    Impl& m = *impl_;
    CHECK_EQ(spp.size(), m.texels.size());
    std::vector<glm::dvec4> out(m.texels.size());
    m.forEachTexel([&](size_t i, Counters& c) { out[i] = m.texelSamples(i, seed, 0, spp[i], c); });
    return out;
}

glm::vec3 ReferenceBaker::estimate(const glm::vec3& point, const glm::vec3& normal, int spp, uint64_t stream) const {
    const Impl& m = *impl_;
    SurfacePoint x;
    x.p = point;
    x.ns = x.ng = glm::normalize(normal);
    const uint64_t key = hash(m.options.seed, 0xE57157A7Eull, stream);
    const Scrambles s = makeScrambles(key);
    Counters counters;
    glm::dvec3 sum(0.0);
    for (int i = 0; i < spp; ++i) sum += glm::dvec3(m.sample(x, uint32_t(i), key, s, counters));
    return spp > 0 ? glm::vec3(sum / double(spp)) : glm::vec3(0.0f);
}

const ReferenceStats& ReferenceBaker::stats() const { return impl_->stats; }
const BakeMesh& ReferenceBaker::mesh() const { return impl_->mesh; }

}  // namespace bb
