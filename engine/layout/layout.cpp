// Light map layout: asset (one shared atlas) or pack (one rectangle per
// instance, sized by world area x texel density, shelf-packed into pages).
//
// Based on: DESIGN.md "Data flow" step 2. Shelf packing with heights sorted
// in decreasing order is the classic "next-fit decreasing height" (NFDH)
// strip-packing heuristic (Coffman, Garey, Johnson, Tarjan 1980).
#include "layout/layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "core/check.h"
#include "core/log.h"

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

InstanceUv measureInstance(const Scene& scene, size_t instance) {
    const Instance& inst = scene.instances[instance];
    const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
    const glm::dmat4 worldFromObject(inst.worldFromObject);
    InstanceUv m;
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

// Texel centres of the page inside more than one TEXCOORD_1 triangle (strictly:
// a centre on a shared edge belongs to neither), and where the first one is.
struct Overlap {
    size_t texels = 0;
    int x = 0, y = 0;
    std::string first, second;  // instance names
};

Overlap findOverlaps(const Scene& scene, int res) {
    std::vector<int32_t> owner(size_t(res) * res, -1);
    std::vector<uint8_t> meshSeen(scene.meshes.size(), 0);
    Overlap o;
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        if (meshSeen[size_t(inst.mesh)]++) continue;  // a mesh's other instances: warned about as such
        for (const Primitive& prim : scene.meshes[size_t(inst.mesh)].primitives) {
            if (prim.uv1.size() != prim.positions.size()) continue;
            for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(prim.uv1[prim.indices[t + size_t(k)]]) * double(res);
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
                            inside = sign * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)) > 0.0;
                        }
                        if (!inside) continue;
                        int32_t& slot = owner[size_t(y) * res + x];
                        if (slot >= 0) {
                            if (o.texels++ == 0) {
                                o.x = x;
                                o.y = y;
                                o.first = scene.instances[size_t(slot)].name;
                                o.second = inst.name;
                            }
                        } else {
                            slot = int32_t(i);
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
Status checkOverlaps(const Scene& scene, const LayoutOptions& options, Layout& layout) {
    const Overlap o = findOverlaps(scene, options.resolution);
    layout.overlappingTexels = o.texels;
    if (o.texels == 0) return Status::ok();
    const std::string what = std::to_string(o.texels) + " light map texel(s) lie in two TEXCOORD_1 triangles at once, e.g. texel (" +
                             std::to_string(o.x) + ", " + std::to_string(o.y) + ") of " + o.first + " and " + o.second;
    if (options.failOnOverlap) return Status::error(what + " (overlapping charts; --uv-overlap fail)");
    logWarning(what + ": those texels mix two surfaces. Fix the charts, or use --uv-layout pack if they are instances "
               "of one mesh, or --uv-overlap fail to refuse such scenes");
    return Status::ok();
}

}  // namespace

Expected<Layout> computeLayout(const Scene& scene, const LayoutOptions& options) {
    if (Status s = validate(scene, options); !s) return s;
    const int res = options.resolution, pad = options.padding;

    if (options.mode == UvLayout::Asset) {
        if (Status s = requireUv1(scene, "--uv-layout asset uses TEXCOORD_1 as the atlas; add a second UV set "
                                         "in the exporting tool");
            !s)
            return s;
        Layout layout = assetLayout(scene, options);
        if (Status s = checkOverlaps(scene, options, layout); !s) return s;
        return layout;
    }

    if (Status s = requireUv1(scene, "light map UV generation is not implemented yet; add a second UV set "
                                     "(TEXCOORD_1) in the exporting tool");
        !s)
        return s;

    // measure: UV bounding box, UV area, world area of every instance
    const size_t n = scene.instances.size();
    std::vector<InstanceUv> measures(n);
    size_t emptyCount = 0;
    for (size_t i = 0; i < n; ++i) {
        measures[i] = measureInstance(scene, i);
        const InstanceUv& m = measures[i];
        if (!std::isfinite(m.worldArea) || !std::isfinite(m.uvArea) || !std::isfinite(m.uvMin.x) ||
            !std::isfinite(m.uvMin.y) || !std::isfinite(m.uvMax.x) || !std::isfinite(m.uvMax.y))
            return Status::error("instance " + instanceName(scene, i) + " of mesh " +
                                 meshName(scene, scene.instances[i].mesh) +
                                 " has non-finite positions, TEXCOORD_1 or transform");
        if (m.empty()) ++emptyCount;
    }
    auto overrideOf = [&](size_t i) { return double(scene.instances[i].texelDensity); };

    // sizes of every rectangle at global density `density`
    std::vector<RectSize> sizes(n);
    auto sizeAll = [&](double density) {
        double total = 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double d = overrideOf(i) > 0.0 ? overrideOf(i) : density;
            sizes[i] = rectSize(measures[i], d, res, pad);
            total += paddedArea(sizes[i], pad);
        }
        return total;
    };

    Layout layout;
    layout.mode = UvLayout::Pack;
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
        layout.pageCount = place();
    } else {
        // auto: density = m * base, with base the density at which the
        // unpadded, un-rounded bounding boxes cover AUTO_FILL of a page. The
        // search runs on the dimensionless m, so every decision (and hence
        // every rectangle) is the same whatever the scene's unit.
        const double page = double(res) * double(res);
        double boxArea = 0.0;  // sum of A_w * bbox / A_uv: texel area at density 1
        for (size_t i = 0; i < n; ++i) {
            if (overrideOf(i) > 0.0 || measures[i].empty()) continue;
            const glm::dvec2 s = measures[i].uvSize();
            boxArea += measures[i].worldArea * (s.x * s.y) / measures[i].uvArea;
        }
        const double base = boxArea > 0.0 ? std::sqrt(AUTO_FILL * page / boxArea) : 0.0;
        double target = AUTO_FILL * page;
        const double minimum = sizeAll(0.0);  // every auto-density instance 1x1
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

}  // namespace bb
