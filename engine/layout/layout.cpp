// Light map layout: asset (one shared atlas) or pack (one rectangle per
// instance, sized by world area x texel density, shelf-packed into pages),
// with TEXCOORD_1 generated (uv_generate.h) where a mesh has none or with
// --uv-layout generate.
//
// Based on: DESIGN.md "Data flow" step 2. Shelf packing with heights sorted
// in decreasing order is the classic "next-fit decreasing height" (NFDH)
// strip-packing heuristic (Coffman, Garey, Johnson, Tarjan 1980).
#include "layout/layout.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/log.h"
#include "core/parallel.h"

namespace bb {
namespace {

constexpr int MIN_RESOLUTION = 16;
constexpr int MAX_RESOLUTION = 16384;
// Auto density aims the padded rectangles at this fraction of one page: the
// rest is what shelf packing typically wastes, so the scene fits one page.
constexpr double AUTO_FILL = 0.7;

// What the pack layout needs to know about one instance, in doubles.
struct InstanceUv {
    glm::dvec2 uvMin{0.0};
    glm::dvec2 uvMax{0.0};
    double uvArea = 0.0;      // sum of |triangle areas| in TEXCOORD_1 space
    double worldArea = 0.0;   // sum of triangle areas after worldFromObject
    glm::ivec2 grid{0};       // generated TEXCOORD_1: the rectangle is exactly this grid (uv1 spans [0,1]^2)
    bool empty() const { return !(uvArea > 0.0) || !(worldArea > 0.0); }
    glm::dvec2 uvSize() const { return uvMax - uvMin; }
};

// Size of one rectangle at a given texel density, after clamping to the page.
struct RectSize {
    int width = 1;
    int height = 1;
    double density = 0.0;     // texels per scene unit actually used
    bool clamped = false;
};

std::string meshName(const Scene& scene, int mesh) {
    const std::string& name = scene.meshes[size_t(mesh)].name;
    return name.empty() ? "mesh " + std::to_string(mesh) : "'" + name + "'";
}

std::string instanceName(const Scene& scene, size_t instance) {
    const std::string& name = scene.instances[instance].name;
    return name.empty() ? "instance " + std::to_string(instance) : "'" + name + "'";
}

std::string formatNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%g", v);
    return buf;
}

Status validate(const Scene& scene, const LayoutOptions& options) {
    if (options.resolution < MIN_RESOLUTION || options.resolution > MAX_RESOLUTION)
        return Status::error("light map resolution " + std::to_string(options.resolution) + " is outside [" +
                             std::to_string(MIN_RESOLUTION) + ", " + std::to_string(MAX_RESOLUTION) +
                             "] (--resolution)");
    if (!std::isfinite(options.texelDensity) || options.texelDensity < 0.0f)
        return Status::error("texel density " + formatNumber(options.texelDensity) +
                             " must be a finite number >= 0 (0 = auto; --texel-density)");
    if (options.padding < 0 || options.padding * 2 >= options.resolution)
        return Status::error("light map padding " + std::to_string(options.padding) +
                             " must be >= 0 and less than half the resolution " +
                             std::to_string(options.resolution));
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size())
            return Status::error("instance " + instanceName(scene, i) + " references mesh " +
                                 std::to_string(inst.mesh) + ", but the scene has " +
                                 std::to_string(scene.meshes.size()) + " meshes");
        if (!std::isfinite(inst.texelDensity) || inst.texelDensity < 0.0f)
            return Status::error("instance " + instanceName(scene, i) + " has texel density " +
                                 formatNumber(inst.texelDensity) +
                                 " in its extras; it must be a finite number >= 0 (0 = use the global density)");
    }
    return Status::ok();
}

// Every instanced primitive must carry TEXCOORD_1 (one per vertex).
Status requireUv1(const Scene& scene, const char* why) {
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Mesh& mesh = scene.meshes[size_t(scene.instances[i].mesh)];
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const Primitive& prim = mesh.primitives[p];
            if (prim.triangleCount() == 0) continue;
            if (prim.uv1.size() != prim.positions.size())
                return Status::error("mesh " + meshName(scene, scene.instances[i].mesh) + " (primitive " +
                                     std::to_string(p) + ", instance " + instanceName(scene, i) +
                                     ") has no TEXCOORD_1 light map UVs; " + why);
        }
    }
    return Status::ok();
}

// `generated`: TEXCOORD_1 is (or is about to be) generated on a grid: only
// the world area is measured, the UV box is [0,1]^2.
InstanceUv measureInstance(const Scene& scene, size_t instance, bool generated) {
    const Instance& inst = scene.instances[instance];
    const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
    const glm::dmat4 worldFromObject(inst.worldFromObject);
    InstanceUv m;
    if (generated) {
        m.worldArea = scene.instanceArea(instance);
        m.uvMin = glm::dvec2(0.0);
        m.uvMax = glm::dvec2(1.0);
        m.uvArea = 1.0;
        m.grid = mesh.uv1Grid;
        return m;
    }
    m.uvMin = glm::dvec2(1e300);
    m.uvMax = glm::dvec2(-1e300);
    bool any = false;
    for (const Primitive& prim : mesh.primitives) {
        for (size_t t = 0; t < prim.triangleCount(); ++t) {
            glm::dvec3 p[3];
            glm::dvec2 uv[3];
            for (int k = 0; k < 3; ++k) {
                const uint32_t index = prim.indices[3 * t + size_t(k)];
                CHECK_LT(size_t(index), prim.positions.size());
                p[k] = glm::dvec3(worldFromObject * glm::dvec4(glm::dvec3(prim.positions[index]), 1.0));
                uv[k] = glm::dvec2(prim.uv1[index]);
                m.uvMin = glm::min(m.uvMin, uv[k]);
                m.uvMax = glm::max(m.uvMax, uv[k]);
            }
            any = true;
            m.worldArea += 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
            const glm::dvec2 e1 = uv[1] - uv[0], e2 = uv[2] - uv[0];
            m.uvArea += 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x);
        }
    }
    if (!any) m.uvMin = m.uvMax = glm::dvec2(0.0);
    return m;
}

// Rectangle size for UV->texel scale `density * sqrt(A_w / A_uv)`, clamped so
// the padded rectangle fits a page.
RectSize rectSize(const InstanceUv& m, double density, int resolution, int padding) {
    RectSize r;
    r.density = density;
    if (m.empty() || !(density > 0.0)) return r;  // 1x1
    const int maxSide = resolution - 2 * padding;
    const glm::dvec2 size = m.uvSize();
    double texelsPerUv = density * std::sqrt(m.worldArea / m.uvArea);
    const double longest = std::max(size.x, size.y);
    if (longest * texelsPerUv > double(maxSide)) {
        // shrink this instance's density so its longer side is exactly the
        // page minus padding (computed directly, so it does not ceil past it)
        const double clampedTexelsPerUv = double(maxSide) / longest;
        r.density = density * (clampedTexelsPerUv / texelsPerUv);
        texelsPerUv = clampedTexelsPerUv;
        r.clamped = true;
    }
    auto side = [&](double extent) {
        const double texels = std::ceil(extent * texelsPerUv);
        return std::clamp(int(std::min(texels, double(maxSide))), 1, maxSide);
    };
    r.width = side(size.x);
    r.height = side(size.y);
    return r;
}

// Shelf packing (next-fit decreasing height) of the padded rectangles.
// Fills page/x/y of `rects` (whose width/height are set); returns pages used.
int shelfPack(std::vector<InstanceRect>& rects, int resolution, int padding) {
    std::vector<size_t> order(rects.size());
    std::iota(order.begin(), order.end(), size_t(0));
    // tallest first; ties by index so the layout is deterministic
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (rects[a].height != rects[b].height) return rects[a].height > rects[b].height;
        return a < b;
    });
    int page = 0, shelfY = 0, shelfHeight = 0, cursorX = 0;
    bool pageUsed = false;
    for (size_t i : order) {
        InstanceRect& r = rects[i];
        const int w = r.width + 2 * padding, h = r.height + 2 * padding;
        DCHECK(w <= resolution && h <= resolution);
        if (cursorX + w > resolution) {  // next shelf
            shelfY += shelfHeight;
            shelfHeight = 0;
            cursorX = 0;
        }
        if (shelfY + h > resolution) {  // next page
            ++page;
            shelfY = 0;
            shelfHeight = 0;
            cursorX = 0;
        }
        r.page = page;
        r.x = cursorX + padding;
        r.y = shelfY + padding;
        cursorX += w;
        shelfHeight = std::max(shelfHeight, h);
        pageUsed = true;
    }
    return pageUsed ? page + 1 : 0;
}

// pageUv = uv1 * scale + offset maps the UV bounding box onto the texel
// rectangle; v grows with texel rows (row 0 at v = 0, as GL addresses textures).
void setScaleOffset(InstanceRect& r, const InstanceUv& m, int resolution) {
    const double res = double(resolution);
    const glm::dvec2 size = m.uvSize();
    const double origin[2] = {double(r.x), double(r.y)};
    const double extent[2] = {double(r.width), double(r.height)};
    for (int a = 0; a < 2; ++a) {
        if (size[a] > 0.0) {
            const double scale = extent[a] / (size[a] * res);
            r.scale[a] = float(scale);
            r.offset[a] = float(origin[a] / res - m.uvMin[a] * scale);
        } else {
            // degenerate extent: everything lands on the middle of the rectangle
            r.scale[a] = 0.0f;
            r.offset[a] = float((origin[a] + 0.5 * extent[a]) / res);
        }
    }
}

double paddedArea(const RectSize& s, int padding) {
    return double(s.width + 2 * padding) * double(s.height + 2 * padding);
}

// A texel centre closer than this to a triangle's edge (in texels) counts as
// on the edge: inside neither side. Rounding of nearly collinear vertices
// (T-junctions, slivers the loader keeps unless exactly degenerate) otherwise
// puts a centre inside two triangles that overlap by 1e-4 texel.
constexpr double EDGE_TOLERANCE = 1e-4;

// Texel centres of the pages inside the instances' TEXCOORD_1 triangles
// through their rectangles (strictly: a centre on a shared edge belongs to
// neither side), counting those inside two. Asset layouts visit each mesh
// once (a mesh's other instances are warned about as such).
TexelCoverage coverage(const Scene& scene, const Layout& layout) {
    const int res = layout.resolution;
    std::vector<std::vector<int32_t>> owner(size_t(std::max(layout.pageCount, 0)));
    std::vector<uint8_t> meshSeen(scene.meshes.size(), 0);
    TexelCoverage o;
    for (size_t i = 0; i < scene.instances.size() && i < layout.rects.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (layout.mode == UvLayout::Asset && meshSeen[size_t(inst.mesh)]++) continue;
        const InstanceRect& r = layout.rects[i];
        if (r.page < 0 || r.page >= layout.pageCount) continue;
        std::vector<int32_t>& page = owner[size_t(r.page)];
        if (page.empty()) page.assign(size_t(res) * size_t(res), -1);
        const glm::dvec2 scale(r.scale), offset(r.offset);
        for (const Primitive& prim : scene.meshes[size_t(inst.mesh)].primitives) {
            if (prim.uv1.size() != prim.positions.size()) continue;
            for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k)
                    p[k] = (glm::dvec2(prim.uv1[prim.indices[t + size_t(k)]]) * scale + offset) * double(res);
                const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
                if (area == 0.0 || !std::isfinite(area)) continue;
                const double sign = area > 0 ? 1.0 : -1.0;
                const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
                const int x1 = std::min(res - 1, int(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
                const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
                const int y1 = std::min(res - 1, int(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) {
                        const glm::dvec2 c(x + 0.5, y + 0.5);
                        bool inside = true;
                        for (int k = 0; k < 3 && inside; ++k) {
                            const glm::dvec2 a = p[k], b = p[(k + 1) % 3];
                            inside = sign * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)) >
                                     EDGE_TOLERANCE * glm::length(b - a);
                        }
                        if (!inside) continue;
                        int32_t& slot = page[size_t(y) * size_t(res) + size_t(x)];
                        if (slot >= 0) {
                            if (o.overlapping++ == 0) {
                                o.page = r.page;
                                o.x = x;
                                o.y = y;
                                o.first = scene.instances[size_t(slot)].name;
                                o.second = inst.name;
                            }
                        } else {
                            slot = int32_t(i);
                            ++o.covered;
                        }
                    }
            }
        }
    }
    return o;
}

Layout assetLayout(const Scene& scene, const LayoutOptions& options) {
    Layout layout;
    layout.mode = UvLayout::Asset;
    layout.resolution = options.resolution;
    layout.padding = options.padding;
    layout.pageCount = 1;
    layout.texelDensity = 0.0f;  // not controlled by bundlebake in asset mode
    layout.rects.resize(scene.instances.size());
    for (InstanceRect& r : layout.rects) {
        r.page = 0;
        r.x = r.y = 0;
        r.width = r.height = options.resolution;
        r.scale = glm::vec2(1.0f);
        r.offset = glm::vec2(0.0f);
    }
    // a mesh instanced twice puts two surfaces on the same texels
    std::vector<int> uses(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances) ++uses[size_t(inst.mesh)];
    size_t shared = 0;
    std::string example;
    for (size_t m = 0; m < uses.size(); ++m) {
        if (uses[m] > 1) {
            if (shared++ == 0) example = meshName(scene, int(m)) + " (" + std::to_string(uses[m]) + " instances)";
        }
    }
    if (shared > 0)
        logWarning(std::to_string(shared) + " mesh(es) are instanced more than once, e.g. " + example +
                   "; with --uv-layout asset their instances share light map texels and overlap. "
                   "Use --uv-layout pack to give each instance its own rectangle");
    return layout;
}

// Asset charts must not overlap: their texels would hold two surfaces.
// Asset charts must not overlap: their texels would hold two surfaces.
Status checkOverlaps(const Scene& scene, const LayoutOptions& options, Layout& layout) {
    const TexelCoverage o = coverage(scene, layout);
    layout.overlappingTexels = o.overlapping;
    if (o.overlapping == 0) return Status::ok();
    const std::string what = std::to_string(o.overlapping) + " light map texel(s) lie in two TEXCOORD_1 triangles at once, e.g. texel (" +
                             std::to_string(o.x) + ", " + std::to_string(o.y) + ") of " + o.first + " and " + o.second;
    if (options.failOnOverlap) return Status::error(what + " (overlapping charts; --uv-overlap fail)");
    logWarning(what + ": those texels mix two surfaces. Fix the charts, or use --uv-layout pack if they are instances "
               "of one mesh, or --uv-overlap fail to refuse such scenes");
    return Status::ok();
}

// Meshes whose TEXCOORD_1 is generated by this computeLayout call: their
// charts, and the packing of the last sizing (the final one once the density
// is chosen).
struct GeneratedMeshes {
    std::vector<const MeshCharts*> charts;  // per scene mesh; null if not generated now
    std::vector<ChartPacking> packing;      // per scene mesh
};

// The pack layout (pack and generate modes). `gen` (may be null): meshes
// sized by packing their charts at the layout's density.
Expected<Layout> packLayout(const Scene& scene, const LayoutOptions& options, GeneratedMeshes* gen) {
    const int res = options.resolution, pad = options.padding;
    const int maxSide = res - 2 * pad;
    auto generatedNow = [&](int mesh) { return gen != nullptr && gen->charts[size_t(mesh)] != nullptr; };

    // every instance without generated TEXCOORD_1 must carry it
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const int mi = scene.instances[i].mesh;
        if (generatedNow(mi)) continue;
        const Mesh& mesh = scene.meshes[size_t(mi)];
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const Primitive& prim = mesh.primitives[p];
            if (prim.triangleCount() == 0 || prim.uv1.size() == prim.positions.size()) continue;
            return Status::error("mesh " + meshName(scene, mi) + " (primitive " + std::to_string(p) + ", instance " +
                                 instanceName(scene, i) +
                                 ") has no TEXCOORD_1 light map UVs; computeLayout(const Scene&) does not generate "
                                 "them (computeLayout(Scene&) does)");
        }
    }

    // measure: UV bounding box, UV area, world area of every instance
    const size_t n = scene.instances.size();
    std::vector<InstanceUv> measures(n);
    size_t emptyCount = 0;
    for (size_t i = 0; i < n; ++i) {
        const int mi = scene.instances[i].mesh;
        measures[i] = measureInstance(scene, i, generatedNow(mi) || scene.meshes[size_t(mi)].uv1Grid.x > 0);
        if (generatedNow(mi)) measures[i].grid = glm::ivec2(0);  // sized below
        const InstanceUv& m = measures[i];
        if (!std::isfinite(m.worldArea) || !std::isfinite(m.uvArea) || !std::isfinite(m.uvMin.x) ||
            !std::isfinite(m.uvMin.y) || !std::isfinite(m.uvMax.x) || !std::isfinite(m.uvMax.y))
            return Status::error("instance " + instanceName(scene, i) + " of mesh " +
                                 meshName(scene, scene.instances[i].mesh) +
                                 " has non-finite positions, TEXCOORD_1 or transform");
        if (m.empty()) ++emptyCount;
    }
    auto overrideOf = [&](size_t i) { return double(scene.instances[i].texelDensity); };
    // the density override of each generated mesh (its instances share one)
    std::vector<double> meshOverride(scene.meshes.size(), 0.0);
    for (size_t i = 0; i < n; ++i) meshOverride[size_t(scene.instances[i].mesh)] = overrideOf(i);

    // sizes of every rectangle at global density `density`
    std::vector<RectSize> sizes(n);
    std::vector<RectSize> meshSizes(scene.meshes.size());
    int unfitMesh = -1;  // a generated mesh whose charts do not fit a page at any density
    auto sizeGenerated = [&](int mi, double density) {
        const MeshCharts& charts = *gen->charts[size_t(mi)];
        ChartPacking& pk = gen->packing[size_t(mi)];
        RectSize& r = meshSizes[size_t(mi)];
        const double d = meshOverride[size_t(mi)] > 0.0 ? meshOverride[size_t(mi)] : density;
        auto fits = [&](const ChartPacking& p) { return p.width <= maxSide && p.height <= maxSide; };
        pk = packCharts(charts, d, pad);
        r.clamped = false;
        if (!fits(pk)) {
            // the largest density (bisection) at which the grid fits the page
            r.clamped = true;
            ChartPacking best = packCharts(charts, 0.0, pad);
            if (!fits(best)) {
                unfitMesh = mi;
            } else {
                double lo = 0.0, hi = d;
                for (int k = 0; k < 30; ++k) {
                    const double mid = 0.5 * (lo + hi);
                    ChartPacking p = packCharts(charts, mid, pad);
                    if (fits(p)) {
                        lo = mid;
                        best = std::move(p);
                    } else {
                        hi = mid;
                    }
                }
            }
            pk = std::move(best);
        }
        r.width = std::clamp(pk.width, 1, std::max(maxSide, 1));
        r.height = std::clamp(pk.height, 1, std::max(maxSide, 1));
        r.density = pk.texelsPerUnit;
    };
    auto sizeAll = [&](double density) {
        double total = 0.0;
        if (gen)
            for (size_t mi = 0; mi < scene.meshes.size(); ++mi)
                if (gen->charts[mi]) sizeGenerated(int(mi), density);
        for (size_t i = 0; i < n; ++i) {
            const int mi = scene.instances[i].mesh;
            if (generatedNow(mi)) {
                sizes[i] = meshSizes[size_t(mi)];
            } else if (measures[i].grid.x > 0) {
                // generated before: its grid, whatever the density (shrunk if it no longer fits)
                RectSize& r = sizes[i];
                r.width = std::min(measures[i].grid.x, maxSide);
                r.height = std::min(measures[i].grid.y, maxSide);
                r.clamped = r.width < measures[i].grid.x || r.height < measures[i].grid.y;
                r.density = 0.0;
            } else {
                const double d = overrideOf(i) > 0.0 ? overrideOf(i) : density;
                sizes[i] = rectSize(measures[i], d, res, pad);
            }
            total += paddedArea(sizes[i], pad);
        }
        return total;
    };
    auto unfitError = [&]() {
        const MeshCharts& charts = *gen->charts[size_t(unfitMesh)];
        const ChartPacking p = packCharts(charts, 0.0, pad);
        return Status::error("mesh " + meshName(scene, unfitMesh) + " has " + std::to_string(charts.chartCount()) +
                             " light map charts; even at one texel each with " + std::to_string(pad) +
                             " texels between them they take " + std::to_string(p.width) + "x" +
                             std::to_string(p.height) + " texels, more than a " + std::to_string(res) + "x" +
                             std::to_string(res) + " page holds. Raise --resolution");
    };

    Layout layout;
    layout.mode = options.mode;
    layout.resolution = res;
    layout.padding = pad;
    layout.rects.resize(n);
    auto place = [&]() {
        for (size_t i = 0; i < n; ++i) {
            layout.rects[i].width = sizes[i].width;
            layout.rects[i].height = sizes[i].height;
            layout.rects[i].texelDensity = float(sizes[i].density);
        }
        return shelfPack(layout.rects, res, pad);
    };

    double density = options.texelDensity;
    if (density > 0.0) {
        sizeAll(density);
        if (unfitMesh >= 0) return unfitError();
        layout.pageCount = place();
    } else {
        // auto: density = m * base, with base the density at which the
        // unpadded, un-rounded bounding boxes cover AUTO_FILL of a page. The
        // search runs on the dimensionless m, so every decision (and hence
        // every rectangle) is the same whatever the scene's unit.
        const double page = double(res) * double(res);
        double boxArea = 0.0;  // sum of A_w * bbox / A_uv: texel area at density 1
        for (size_t i = 0; i < n; ++i) {
            const int mi = scene.instances[i].mesh;
            if (overrideOf(i) > 0.0 || measures[i].empty() || measures[i].grid.x > 0) continue;
            if (generatedNow(mi)) {
                const MeshCharts& charts = *gen->charts[size_t(mi)];
                for (const glm::dvec2& e : charts.extent) boxArea += e.x * e.y;
                continue;
            }
            const glm::dvec2 s = measures[i].uvSize();
            boxArea += measures[i].worldArea * (s.x * s.y) / measures[i].uvArea;
        }
        const double base = boxArea > 0.0 ? std::sqrt(AUTO_FILL * page / boxArea) : 0.0;
        double target = AUTO_FILL * page;
        const double minimum = sizeAll(0.0);  // every auto-density instance 1x1 (generated: charts 1x1)
        if (unfitMesh >= 0) return unfitError();
        bool fitOnePage = true;
        if (minimum > target) {
            // more instances than one page holds: give each some texels and
            // let the packer open more pages
            logWarning(std::to_string(n) + " instances do not fit one " + std::to_string(res) + "x" +
                       std::to_string(res) + " page at automatic texel density; using several pages. "
                       "Raise --resolution or set --texel-density");
            target = 4.0 * minimum;
            fitOnePage = false;
        }
        double m = 0.0;
        if (base > 0.0) {
            // bracket [lo, hi] with area(lo) <= target < area(hi), then bisect
            double lo = 1.0, hi = 1.0;
            if (sizeAll(base) <= target) {
                for (int k = 0; k < 64 && sizeAll(base * hi) <= target; ++k) {
                    lo = hi;
                    hi *= 2.0;
                }
            } else {
                lo = 0.5;
                for (int k = 0; k < 64 && sizeAll(base * lo) > target; ++k) {
                    hi = lo;
                    lo *= 0.5;
                }
                if (sizeAll(base * lo) > target) lo = 0.0;
            }
            if (sizeAll(base * hi) <= target) {
                m = hi;  // everything clamped to the page already
            } else {
                for (int k = 0; k < 60; ++k) {
                    const double mid = 0.5 * (lo + hi);
                    if (sizeAll(base * mid) <= target) lo = mid;
                    else hi = mid;
                }
                m = lo;
            }
        }
        sizeAll(base * m);
        layout.pageCount = place();
        // area alone does not guarantee the shelves fit: shrink until they do
        for (int k = 0; fitOnePage && layout.pageCount > 1 && m > 0.0 && k < 400; ++k) {
            m *= 0.97;
            sizeAll(base * m);
            layout.pageCount = place();
        }
        density = base * m;
    }
    layout.texelDensity = float(density);

    for (size_t i = 0; i < n; ++i) setScaleOffset(layout.rects[i], measures[i], res);

    // warnings, once per kind
    size_t clampedCount = 0;
    for (const RectSize& s : sizes) clampedCount += s.clamped ? 1 : 0;
    if (clampedCount > 0)
        logWarning(std::to_string(clampedCount) + " instance(s) would be larger than a " + std::to_string(res) +
                   "x" + std::to_string(res) + " page at the requested texel density; their density was "
                   "reduced to fit. Raise --resolution or lower --texel-density");
    if (emptyCount > 0)
        logWarning(std::to_string(emptyCount) + " instance(s) have zero world or TEXCOORD_1 area; each gets "
                   "a 1x1 light map rectangle");
    return layout;
}

bool closeMetric(const glm::dmat3& a, const glm::dmat3& b) {
    double scale = 0.0, diff = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) {
            scale = std::max(scale, std::abs(a[c][r]));
            diff = std::max(diff, std::abs(a[c][r] - b[c][r]));
        }
    return diff <= 1e-6 * scale;
}

}  // namespace

Expected<Layout> computeLayout(const Scene& scene, const LayoutOptions& options) {
    if (Status s = validate(scene, options); !s) return s;

    if (options.mode == UvLayout::Asset) {
        if (Status s = requireUv1(scene, "--uv-layout asset uses TEXCOORD_1 as the atlas; add a second UV set "
                                         "in the exporting tool, or use --uv-layout pack or generate");
            !s)
            return s;
        Layout layout = assetLayout(scene, options);
        if (Status s = checkOverlaps(scene, options, layout); !s) return s;
        return layout;
    }
    return packLayout(scene, options, nullptr);
}

Expected<Layout> computeLayout(Scene& scene, const LayoutOptions& options) {
    if (options.mode == UvLayout::Asset) return computeLayout(std::as_const(scene), options);
    if (Status s = validate(scene, options); !s) return s;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();

    // which meshes get generated TEXCOORD_1, and their instances
    std::vector<std::vector<size_t>> instancesOf(scene.meshes.size());
    for (size_t i = 0; i < scene.instances.size(); ++i) instancesOf[size_t(scene.instances[i].mesh)].push_back(i);
    std::vector<int> need;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        if (instancesOf[m].empty()) continue;
        bool missing = options.mode == UvLayout::Generate;
        for (const Primitive& prim : scene.meshes[m].primitives)
            if (prim.triangleCount() > 0 && prim.uv1.size() != prim.positions.size()) missing = true;
        if (missing) need.push_back(int(m));
    }
    if (need.empty()) return computeLayout(std::as_const(scene), options);

    // one generated mesh per instance shape: instances whose linear parts
    // differ only by a rotation (same L^T L) and that share a density
    // override share the mesh and its TEXCOORD_1; the others get copies
    struct Group {
        int mesh;
        glm::dmat3 metricFromObject;
        glm::dmat3 metric;
        float texelDensity;
    };
    std::vector<Group> groups;
    size_t copies = 0;
    for (int m : need) {
        const size_t firstGroup = groups.size();
        for (size_t i : instancesOf[size_t(m)]) {
            Instance& inst = scene.instances[i];
            const glm::dmat3 linear(inst.exactWorldFromObject());
            const glm::dmat3 metric = glm::transpose(linear) * linear;
            size_t g = firstGroup;
            while (g < groups.size() && !(groups[g].texelDensity == inst.texelDensity && closeMetric(groups[g].metric, metric)))
                ++g;
            if (g == groups.size()) {
                int mesh = m;
                if (g > firstGroup) {
                    Mesh copy = scene.meshes[size_t(m)];
                    scene.meshes.push_back(std::move(copy));
                    mesh = int(scene.meshes.size()) - 1;
                    ++copies;
                }
                groups.push_back({mesh, linear, metric, inst.texelDensity});
            }
            inst.mesh = groups[g].mesh;
        }
    }

    // charts, one mesh per task on every core (each mesh is its own; same bytes in any order)
    std::vector<MeshCharts> charts(groups.size());
    parallelFor(groups.size(), [&](size_t g) {
        charts[g] = makeCharts(scene.meshes[size_t(groups[g].mesh)], groups[g].metricFromObject, options.charts);
    });
    const auto charted = Clock::now();

    GeneratedMeshes gen;
    gen.charts.assign(scene.meshes.size(), nullptr);
    gen.packing.resize(scene.meshes.size());
    for (size_t g = 0; g < groups.size(); ++g) gen.charts[size_t(groups[g].mesh)] = &charts[g];
    Expected<Layout> layout = packLayout(scene, options, &gen);
    if (!layout) return layout;
    for (const Group& g : groups) writeUv1(scene.meshes[size_t(g.mesh)], *gen.charts[size_t(g.mesh)], gen.packing[size_t(g.mesh)]);
    const auto packed = Clock::now();

    // figures
    UvGenerationStats& st = layout->uv;
    st.meshes = groups.size();
    st.copiedMeshes = copies;
    double stretchArea = 0.0, area = 0.0;
    std::vector<size_t> uses(scene.meshes.size(), 0);
    for (const Instance& inst : scene.instances) ++uses[size_t(inst.mesh)];
    for (size_t g = 0; g < groups.size(); ++g) {
        const MeshCharts& c = charts[g];
        const int mi = groups[g].mesh;
        const ChartPacking& pk = gen.packing[size_t(mi)];
        st.charts += c.chartCount();
        for (size_t k = 0; k < c.chartCount(); ++k) {
            st.lscmCharts += c.lscm[k];
            st.worstStretch = std::max(st.worstStretch, c.stretch[k]);
            stretchArea += c.stretch[k] * c.area[k];
            area += c.area[k];
            if (c.area[k] * pk.texelsPerUnit * pk.texelsPerUnit < 1.0) ++st.subTexelCharts;
        }
        const GridCoverage cov = gridCoverage(scene.meshes[size_t(mi)], pk.width, pk.height);
        st.gridTexels += size_t(pk.width) * size_t(pk.height) * uses[size_t(mi)];
        st.coveredTexels += cov.covered * uses[size_t(mi)];
        st.overlappingTexels += cov.overlapping * uses[size_t(mi)];
    }
    st.meanStretch = area > 0.0 ? stretchArea / area : 1.0;
    st.chartSeconds = std::chrono::duration<double>(charted - start).count();
    st.packSeconds = std::chrono::duration<double>(packed - charted).count();
    if (st.overlappingTexels > 0)
        logWarning(std::to_string(st.overlappingTexels) + " texel(s) of the generated light map UVs lie in two "
                   "triangles (overlapping charts)");
    if (st.charts > 0 && 2 * st.subTexelCharts > st.charts)
        logWarning(std::to_string(st.subTexelCharts) + " of the " + std::to_string(st.charts) +
                   " generated light map charts are smaller than a texel at " +
                   std::to_string(layout->texelDensity) +
                   " texels per scene unit; they share the light of their neighbours. Raise --resolution or "
                   "--texel-density");
    char line[256];
    std::snprintf(line, sizeof line,
                  "generated light map UVs for %zu mesh(es): %zu charts (%zu by LSCM), worst stretch %.3f, "
                  "%.1f %% of their texels covered, %.2f s",
                  st.meshes, st.charts, st.lscmCharts, st.worstStretch,
                  st.gridTexels ? 100.0 * double(st.coveredTexels) / double(st.gridTexels) : 0.0,
                  st.chartSeconds + st.packSeconds);
    logDebug(line);
    return layout;
}

TexelCoverage measureCoverage(const Scene& scene, const Layout& layout) { return coverage(scene, layout); }

}  // namespace bb
