#!/usr/bin/env python3
"""Generates a large, seeded glTF city: the benchmark scene for adaptive ray-bundle tiling.

usage: generate_city.py -o OUT.gltf [--preset tiny|small|city|paper] [--seed S] [knobs...]

Writes OUT.gltf and OUT.bin (external buffer, relative uri), each atomically.
Standard library only; the same arguments give the same bytes.

The scene (glTF: metres, +Y up):
- Terrain: a --size-m square centred at the origin, cut into --terrain-tiles^2
  tiles (one mesh and node each) of --terrain-quads^2 quads: a rolling height
  field (five seeded sines, amplitude 1.5 % of the size, slopes up to ~20
  degrees), flattened under each district to a plane tilted by < 3 degrees.
  TEXCOORD_1: the tile's grid mapped to [0,1]^2 with a margin.
  Node extras.texelDensity = --terrain-density.
- Buildings: --buildings instances in --districts seeded districts, each turned
  about Y: blocks of two back-to-back rows of buildings between narrow streets
  (6-15 m), cut by cross streets, so that looking down a street the depth
  complexity is high. Footprints --footprint-m (8-40 m), heights --height-m
  (6-80 m, skewed low, taller downtown), bases 1.5 m below the lowest ground
  under them. 16 shared meshes (4 slenderness classes x 2 footprint aspects x
  {parapet, setback}) with --building-detail recessed window bands per tier;
  each node takes the variant closest in shape and scales it (mildly
  non-uniformly: texel density inside one instance varies by up to ~1.4x).
  Every planar face is a TEXCOORD_1 chart, all at one UV scale per mesh,
  shelf-packed with a gutter. Node extras.texelDensity = --building-density.
- Flat (per-face) normals, uint32 indices, TEXCOORD_0 = TEXCOORD_1 (one shared
  accessor), a terrain and two grey building materials (diffuse), no lights
  (bake with --sky 1,1,1), one perspective camera over district 0's streets.

Presets (explicit flags override them). Figures for --seed 1 on a 2-core VM;
texels = sum(world area x density^2), which `--uv-layout pack` covers (the
baker's covered_texels came out 2-6 % higher on tiny and city):
  tiny   200 m, 4^2 tiles x 8^2 quads, 100 buildings (8-16 m, 6-30 m), 1 district,
         detail 1: 9 960 triangles, 116 instances, 37 k texels, 0.36 MB, 0.1 s
  small  2 km, 8^2 x 12^2, 1 000 buildings, 2 districts, detail 1:
         100 k triangles, 1 064 instances, 2.0 M texels, 2.3 MB, 0.2 s
  city   5 km, 16^2 x 16^2, 10 000 buildings, 5 districts, detail 1 (the defaults):
         947 k triangles, 10 256 instances, 16.0 M texels, 16 MB, 1.2 s
  paper  5 km, 16^2 x 32^2, 13 200 buildings, 7 districts, detail 5, densities 1.0
         (terrain) and 0.8 (buildings); cf. Tokuyoshi et al. 2013's 4.9 km scene:
         3.73 M triangles, 13 456 instances, 48.8 M texels, 59 MB, 3.1 s
"""
import argparse
import array
import json
import math
import os
import random
import sys
import time

GENERATOR = "bundlebake scripts/generate_city.py"
DEFAULTS = dict(size_m=5000.0, terrain_tiles=16, terrain_quads=16, buildings=10000, building_detail=1,
                districts=5, footprint_m=(8.0, 40.0), height_m=(6.0, 80.0),
                terrain_density=0.5, building_density=0.6)
PRESETS = {
    "tiny": dict(size_m=200.0, terrain_tiles=4, terrain_quads=8, buildings=100, districts=1,
                 footprint_m=(8.0, 16.0), height_m=(6.0, 30.0)),
    "small": dict(size_m=2000.0, terrain_tiles=8, terrain_quads=12, buildings=1000, districts=2),
    "city": dict(),
    "paper": dict(terrain_quads=32, buildings=13200, building_detail=5, districts=7,
                  terrain_density=1.0, building_density=0.8),
}
RELIEF = 0.015          # terrain amplitude (sum of the sines' amplitudes) over its size
DISTRICT_SLOPE = 0.3    # a district's ground keeps this fraction of the natural slope at its centre
BLEND = 0.08            # distance (over the size) over which a district's flattening fades out
SINK = 1.5              # metres a building base reaches below the lowest ground under it
UV_GUTTER = 1.0 / 256   # UV gap between building charts (half of it to the [0,1] border)
TERRAIN_MARGIN = 1.0 / 128
INSET = 0.35            # window band recess depth (nominal metres)
# Variant shapes: nominal footprints W x D (equal areas) and heights, in metres.
ASPECTS = ((20.0, 20.0), (28.0, 14.0))
HEIGHT_CLASSES = (7.0, 16.0, 36.0, 80.0)
MAX_ASPECT = 2.5        # footprints stay within 1:2.5 and heights within 5 sqrt(w d),
MAX_SLENDER = 5.0       # so the scale of the closest variant stays near uniform


# ---------------------------------------------------------------- building meshes
# A mesh is built as a list of planar quads (p0..p3, counter-clockwise seen from
# the front); each quad gets its own 4 vertices (flat normal) and UV chart.
def sides(outer, inner):
    """(outward normal (x, z), half length on the outer rect, on the inner rect) of 4 sides."""
    return [((1, 0), outer[1], inner[1]), ((-1, 0), outer[1], inner[1]),
            ((0, 1), outer[0], inner[0]), ((0, -1), outer[0], inner[0])]


def wall(quads, n, rect, half, y0, y1):
    """Vertical quad facing n on the side of half-size rect, from y0 to y1."""
    cx, cz, rx, rz = n[0] * rect[0], n[1] * rect[1], n[1], -n[0]  # right = up x n
    quads.append(((cx - rx * half, y0, cz - rz * half), (cx + rx * half, y0, cz + rz * half),
                  (cx + rx * half, y1, cz + rz * half), (cx - rx * half, y1, cz - rz * half)))


def ring(quads, y, outer, inner, up):
    """Horizontal ring between half-sizes outer and inner: 4 trapezoids facing up or down."""
    for n, ho, hi in sides(outer, inner):
        rx, rz = n[1], -n[0]
        co, ci = (n[0] * outer[0], n[1] * outer[1]), (n[0] * inner[0], n[1] * inner[1])
        q = ((co[0] - rx * ho, y, co[1] - rz * ho), (co[0] + rx * ho, y, co[1] + rz * ho),
             (ci[0] + rx * hi, y, ci[1] + rz * hi), (ci[0] - rx * hi, y, ci[1] - rz * hi))
        quads.append(q if up else q[::-1])


def tier(quads, rect, ya, yb, bands, top_extra):
    """Walls of one tier from ya to yb (+top_extra of parapet), with recessed window bands."""
    lo, slot = ya + 0.15 * (yb - ya), 0.77 * (yb - ya) / max(bands, 1)
    levels = [(lo + (i + 0.25) * slot, lo + (i + 0.75) * slot) for i in range(bands)]
    inner = (rect[0] - INSET, rect[1] - INSET)
    for n, h, hin in sides(rect, inner):
        y = ya
        for b0, b1 in levels:
            wall(quads, n, rect, h, y, b0)
            wall(quads, n, inner, hin, b0, b1)
            y = b1
        wall(quads, n, rect, h, y, yb + top_extra)
    for b0, b1 in levels:
        ring(quads, b0, rect, inner, True)   # sill
        ring(quads, b1, rect, inner, False)  # lintel


def roof_with_parapet(quads, rect, y, height=1.0, thickness=0.3):
    inner = (rect[0] - thickness, rect[1] - thickness)
    ring(quads, y + height, rect, inner, True)
    for n, h, _ in sides(inner, inner):
        wall(quads, (-n[0], -n[1]), (-inner[0], -inner[1]), h, y, y + height)
    quads.append(((-inner[0], y, inner[1]), (inner[0], y, inner[1]), (inner[0], y, -inner[1]),
                  (-inner[0], y, -inner[1])))


def building_variant(height, footprint, setback, detail):
    quads, rect = [], (footprint[0] / 2, footprint[1] / 2)
    if not setback:
        tier(quads, rect, 0.0, height, detail, 1.0)
        roof_with_parapet(quads, rect, height)
    else:  # a second, narrower tier on the upper third
        y1, inset = 0.65 * height, 0.18 * min(footprint)
        rect2 = (rect[0] - inset, rect[1] - inset)
        tier(quads, rect, 0.0, y1, detail, 0.0)
        ring(quads, y1, rect, rect2, True)
        tier(quads, rect2, y1, height, (detail + 1) // 2, 1.0)
        roof_with_parapet(quads, rect2, height)
    return quads


def pack_charts(charts):
    """Packs charts [(w, h)] (metres) into [0,1]^2 at the largest common scale
    (first-fit decreasing-height shelves); returns (scale, [(u, v)] offsets)."""
    order = sorted(range(len(charts)), key=lambda i: (-charts[i][1], -charts[i][0], i))
    edge = 1 - UV_GUTTER / 2

    def place(s):
        shelves, out = [], [None] * len(charts)  # shelf: [y, x used, height]
        for i in order:
            w, h = charts[i][0] * s, charts[i][1] * s
            shelf = next((sh for sh in shelves if sh[1] + w <= edge), None)
            if shelf is None:
                y = shelves[-1][0] + shelves[-1][2] + UV_GUTTER if shelves else UV_GUTTER / 2
                if y + h > edge or UV_GUTTER / 2 + w > edge:
                    return None
                shelf = [y, UV_GUTTER / 2, h]
                shelves.append(shelf)
            out[i] = (shelf[1], shelf[0])
            shelf[1] += w + UV_GUTTER
        return out

    lo, hi = 0.0, 1.0 / math.sqrt(sum(w * h for w, h in charts))
    for _ in range(40):  # bisection in fixed steps: deterministic
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if place(mid) else (lo, mid)
    return lo, place(lo)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b, normalize=False):
    c = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    return tuple(x / math.sqrt(dot(c, c)) for x in c) if normalize else c


def mesh_from_quads(quads):
    """Vertex arrays (TEXCOORD_1: one chart per quad) and face areas by normal axis."""
    charts, frames = [], []
    for q in quads:
        n = cross(sub(q[1], q[0]), sub(q[2], q[0]), True)
        u = cross((0.0, 1.0, 0.0) if abs(n[1]) < 0.5 else (0.0, 0.0, 1.0), n, True)  # an edge: quads are axis-aligned
        v = cross(n, u)
        pts = [(dot(sub(p, q[0]), u), dot(sub(p, q[0]), v)) for p in q]
        x0, y0 = min(p[0] for p in pts), min(p[1] for p in pts)
        pts = [(p[0] - x0, p[1] - y0) for p in pts]
        w, h = max(p[0] for p in pts), max(p[1] for p in pts)
        if h > w:  # long side along the shelves
            pts, w, h = [(p[1], p[0]) for p in pts], h, w
        charts.append((w, h))
        frames.append((n, pts))
    scale, offsets = pack_charts(charts)
    pos, nrm, uv, idx = array.array("f"), array.array("f"), array.array("f"), array.array("I")
    axis_area = [0.0, 0.0, 0.0]
    for k, q in enumerate(quads):
        n, pts = frames[k]
        for p, c in zip(q, pts):
            pos.extend(p)
            nrm.extend(n)
            uv.extend((offsets[k][0] + c[0] * scale, offsets[k][1] + c[1] * scale))
        idx.extend((4 * k, 4 * k + 1, 4 * k + 2, 4 * k, 4 * k + 2, 4 * k + 3))
        diag = cross(sub(q[2], q[0]), sub(q[3], q[1]))  # planar quad: area = |d1 x d2| / 2
        axis_area[max(range(3), key=lambda i: abs(n[i]))] += 0.5 * math.sqrt(dot(diag, diag))
    return dict(pos=pos, nrm=nrm, uv=uv, idx=idx, axis_area=axis_area)


# ---------------------------------------------------------------- districts and terrain
def plan_district(rng, quota, a):
    """quota buildings in district coordinates (x along the streets): a list of
    [centre x, centre z, w, d, height fraction], and the extent (L, Z)."""
    fmin, fmax = a.footprint_m
    mean_f = 0.5 * (fmin + fmax)
    L = math.sqrt(quota * (mean_f + 1.5) * (0.85 * mean_f + 5.25) * 1.07 * rng.uniform(1.0, 1.6))
    segments, x = [], 0.0  # along-street segments between cross streets
    while x < L:
        seg = rng.uniform(80.0, 220.0) if fmax > 20 else rng.uniform(50.0, 110.0)
        segments.append((x, min(x + seg, L)))
        x += seg + rng.uniform(6.0, 15.0)
    out, z = [], 0.0
    while len(out) < quota:
        z += rng.uniform(6.0, 15.0)  # the street in front of the block
        for row in range(2):  # two rows back to back, each facing its street
            depth = rng.uniform(fmin, fmax)
            for s0, s1 in segments:
                x = s0
                while len(out) < quota:
                    w = fmin + (fmax - fmin) * rng.random() ** 1.5
                    if x + w > s1:
                        w = s1 - x
                        if w < fmin:
                            break
                    d = rng.uniform(max(fmin, 0.7 * depth), depth)
                    w, d = min(w, MAX_ASPECT * d), min(d, MAX_ASPECT * w)
                    out.append([x + w / 2, z + d / 2 if row == 0 else z + depth - d / 2, w, d, rng.random()])
                    x += w + rng.uniform(0.5, 2.5)
            z += depth + (rng.uniform(0.5, 2.5) if row == 0 else 0.0)  # a back alley between the rows
    for b in out:  # taller towards the district centre
        r = 2 * math.hypot(b[0] / L - 0.5, b[1] / z - 0.5)
        b[4] = b[4] ** 1.3 * (0.5 + 0.5 * max(0.0, 1.0 - r))
    return out, L, z


def place_districts(rng, extents, half):
    """(centre x, centre z, angle) per district, inside the square with disjoint bounding
    boxes: largest first, random tries, all restarted when one gets stuck."""
    order = sorted(range(len(extents)), key=lambda i: (-extents[i][0] * extents[i][1], i))
    margin, gap = 0.03 * half, 2 * BLEND * half  # the flattening of one district never reaches another
    for restart in range(200):
        placed = {}
        for i in order:
            L, Z = extents[i]
            for _ in range(1000):
                th = rng.uniform(-math.pi / 6, math.pi / 6) if restart < 100 else 0.0
                bx = 0.5 * (L * math.cos(th) + Z * abs(math.sin(th)))
                bz = 0.5 * (L * abs(math.sin(th)) + Z * math.cos(th))
                if max(bx, bz) > half - margin:
                    continue
                cx = rng.uniform(-half + margin + bx, half - margin - bx)
                cz = rng.uniform(-half + margin + bz, half - margin - bz)
                if all(abs(cx - p[0]) > bx + p[3] + gap or abs(cz - p[1]) > bz + p[4] + gap
                       for p in placed.values()):
                    placed[i] = (cx, cz, th, bx, bz)
                    break
            else:
                break
        if len(placed) == len(extents):
            return [placed[i][:3] for i in range(len(extents))]
    sys.exit("generate_city.py: error: the districts do not fit the terrain; raise --size-m or --districts")


def make_heightfield(rng, a, districts):
    """Heights at the (N+1)^2 terrain grid vertices (N = tiles x quads), rows along x."""
    size, n = a.size_m, a.terrain_tiles * a.terrain_quads
    waves = []  # (k_x, k_z, phase, amplitude): long waves, amplitudes proportional to wavelength
    for k in range(5):
        th, lam = rng.uniform(0, 2 * math.pi), size * rng.uniform(0.5, 1.5) / (1 + 0.5 * k)
        waves.append((math.cos(th) * 2 * math.pi / lam, math.sin(th) * 2 * math.pi / lam,
                      rng.uniform(0, 2 * math.pi), lam))
    waves = [(kx, kz, ph, RELIEF * size * lam / sum(w[3] for w in waves)) for kx, kz, ph, lam in waves]

    def natural(x, z, gradient=False):
        if gradient:
            return (sum(A * kx * math.cos(kx * x + kz * z + ph) for kx, kz, ph, A in waves),
                    sum(A * kz * math.cos(kx * x + kz * z + ph) for kx, kz, ph, A in waves))
        return sum(A * math.sin(kx * x + kz * z + ph) for kx, kz, ph, A in waves)

    # under a district: a plane through its centre with DISTRICT_SLOPE of the natural slope,
    # plus 10 % of the natural relief around that plane, faded out over BLEND x size around it
    blend = BLEND * size
    flat = [(cx, cz, math.cos(th), math.sin(th), L / 2, Z / 2, natural(cx, cz), natural(cx, cz, True))
            for cx, cz, th, L, Z in districts]
    heights = array.array("d")
    for j in range(n + 1):
        z = -size / 2 + size * j / n
        for i in range(n + 1):
            x = -size / 2 + size * i / n
            h = natural(x, z)
            for cx, cz, c, s, hl, hz, hc, (gx, gz) in flat:
                lx, lz = (x - cx) * c + (z - cz) * s, -(x - cx) * s + (z - cz) * c
                t = math.hypot(max(0.0, abs(lx) - hl), max(0.0, abs(lz) - hz)) / blend
                if t < 1:
                    plane = hc + DISTRICT_SLOPE * (gx * (x - cx) + gz * (z - cz))
                    h += (1 - t * t * (3 - 2 * t)) * 0.9 * (plane - h)
            heights.append(h)
    return heights


def ground(heights, a, x, z):
    """Height of the triangulated terrain at (x, z), exactly as drawn."""
    n = a.terrain_tiles * a.terrain_quads
    gx = min(max((x / a.size_m + 0.5) * n, 0.0), n - 1e-9)
    gz = min(max((z / a.size_m + 0.5) * n, 0.0), n - 1e-9)
    i, j = int(gx), int(gz)
    fx, fz, r0, r1 = gx - i, gz - j, j * (n + 1) + i, (j + 1) * (n + 1) + i
    if fx >= fz:  # triangle (00, 10, 11)
        return heights[r0] + fx * (heights[r0 + 1] - heights[r0]) + fz * (heights[r1 + 1] - heights[r0 + 1])
    return heights[r0] + fz * (heights[r1] - heights[r0]) + fx * (heights[r1 + 1] - heights[r1])


def terrain_tile(heights, a, ti, tj):
    """One tile in tile-local XZ (its node translates it), one vertex triple per triangle."""
    q, n = a.terrain_quads, a.terrain_tiles * a.terrain_quads
    step = a.size_m / n
    centre = (-a.size_m / 2 + (ti + 0.5) * q * step, -a.size_m / 2 + (tj + 0.5) * q * step)
    xs = [(k - q / 2) * step for k in range(q + 1)]
    us = [TERRAIN_MARGIN + (1 - 2 * TERRAIN_MARGIN) * k / q for k in range(q + 1)]
    pos, nrm, uv, area = array.array("f"), array.array("f"), array.array("f"), 0.0
    for j in range(q):
        r0, r1 = (tj * q + j) * (n + 1) + ti * q, (tj * q + j + 1) * (n + 1) + ti * q
        z0, z1, v0, v1 = xs[j], xs[j + 1], us[j], us[j + 1]
        for i in range(q):
            h00, h10, h01, h11 = heights[r0 + i], heights[r0 + i + 1], heights[r1 + i], heights[r1 + i + 1]
            x0, x1, u0, u1 = xs[i], xs[i + 1], us[i], us[i + 1]
            for tri, tuv in (((x0, h00, z0, x1, h11, z1, x1, h10, z0), (u0, v0, u1, v1, u1, v0)),
                             ((x0, h00, z0, x0, h01, z1, x1, h11, z1), (u0, v0, u0, v1, u1, v1))):
                ax, ay, az = tri[3] - tri[0], tri[4] - tri[1], tri[5] - tri[2]
                bx, by, bz = tri[6] - tri[0], tri[7] - tri[1], tri[8] - tri[2]
                cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
                ln = math.sqrt(cx * cx + cy * cy + cz * cz)
                area += 0.5 * ln
                pos.extend(tri)
                nrm.extend((cx / ln, cy / ln, cz / ln) * 3)
                uv.extend(tuv)
    return dict(pos=pos, nrm=nrm, uv=uv, idx=array.array("I", range(len(pos) // 3)), area=area), centre


# ---------------------------------------------------------------- glTF output
class Gltf:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": GENERATOR}, "scene": 0, "scenes": [],
                    "nodes": [], "cameras": [], "meshes": [], "materials": [], "accessors": [],
                    "bufferViews": [], "buffers": []}

    def add(self, key, item):
        self.doc[key].append(item)
        return len(self.doc[key]) - 1

    def accessor(self, arr, kind, target, bounds=False):
        comps = {"VEC3": 3, "VEC2": 2, "SCALAR": 1}[kind]
        data = arr
        if sys.byteorder != "little":  # glTF buffers are little-endian
            data = array.array(arr.typecode, arr)
            data.byteswap()
        view = self.add("bufferViews", {"buffer": 0, "byteOffset": len(self.bin),
                                        "byteLength": 4 * len(arr), "target": target})
        self.bin += data.tobytes()  # 4-byte elements only: every offset stays 4-aligned
        acc = {"bufferView": view, "componentType": 5125 if arr.typecode == "I" else 5126,
               "count": len(arr) // comps, "type": kind}
        if bounds:
            acc["min"] = [min(arr[c::comps]) for c in range(comps)]
            acc["max"] = [max(arr[c::comps]) for c in range(comps)]
        return self.add("accessors", acc)

    def mesh(self, name, m, material):
        uv = self.accessor(m["uv"], "VEC2", 34962)
        attributes = {"POSITION": self.accessor(m["pos"], "VEC3", 34962, True),
                      "NORMAL": self.accessor(m["nrm"], "VEC3", 34962), "TEXCOORD_0": uv, "TEXCOORD_1": uv}
        return self.add("meshes", {"name": name, "primitives": [{
            "attributes": attributes, "indices": self.accessor(m["idx"], "SCALAR", 34963),
            "material": material, "mode": 4}]})


def write_atomic(path, data):
    tmp = "%s.tmp%d" % (path, os.getpid())
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def material(name, rgb):
    return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1.0],
                                                   "metallicFactor": 0.0, "roughnessFactor": 1.0}}


class Totals:
    """What the summary line reports, summed over instances."""
    triangles, area, texels = 0, 0.0, 0.0

    def add(self, triangles, area, density):
        self.triangles, self.area, self.texels = (self.triangles + triangles, self.area + area,
                                                  self.texels + area * density ** 2)


def add_terrain(g, a, heights, totals):
    children = []
    for tj in range(a.terrain_tiles):
        for ti in range(a.terrain_tiles):
            m, (cx, cz) = terrain_tile(heights, a, ti, tj)
            name = "terrain_%d_%d" % (ti, tj)
            children.append(g.add("nodes", {"name": name, "mesh": g.mesh(name, m, 0),
                                            "translation": [round(cx, 4), 0.0, round(cz, 4)],
                                            "extras": {"texelDensity": a.terrain_density}}))
            totals.add(len(m["idx"]) // 3, m["area"], a.terrain_density)
    return g.add("nodes", {"name": "terrain", "children": children})


def add_buildings(g, rng, a, plans, placed, heights, totals):
    variants = {}  # (height class, aspect index, setback) -> (mesh, triangles, face areas by normal axis)
    for hc in HEIGHT_CLASSES:
        for ai, fp in enumerate(ASPECTS):
            for setback in (False, True):
                m = mesh_from_quads(building_variant(hc, fp, setback, a.building_detail))
                name = "building_h%d_%dx%d_%s" % (hc, fp[0], fp[1], "setback" if setback else "parapet")
                variants[hc, ai, setback] = (g.mesh(name, m, 1 + len(variants) % 2), len(m["idx"]) // 3,
                                             m["axis_area"])
    hmin, hmax = a.height_m
    roots = []
    for k, ((buildings, L, Z), (dcx, dcz, th)) in enumerate(zip(plans, placed)):
        c, s = math.cos(th), math.sin(th)
        children = []
        for bi, (lx, lz, w, dep, hf) in enumerate(buildings):
            lx, lz = lx - L / 2, lz - Z / 2
            x, z = dcx + lx * c - lz * s, dcz + lx * s + lz * c
            h = min(hmin + (hmax - hmin) * hf, MAX_SLENDER * math.sqrt(w * dep))
            turn = dep > 1.4 * w  # deep lots take the oblong variant turned by 90 degrees
            vw, vd = (dep, w) if turn else (w, dep)
            ai = 1 if vw > 1.4 * vd else 0
            slender = (h + SINK) / math.sqrt(w * dep)
            hc = min(HEIGHT_CLASSES, key=lambda v: abs(math.log(v / 20.0 / slender)))
            mesh, ntri, axis_area = variants[hc, ai, rng.random() < 0.5]
            base = min(ground(heights, a, x + (u * w * c - v * dep * s) / 2, z + (u * w * s + v * dep * c) / 2)
                       for u in (-1, 0, 1) for v in (-1, 0, 1)) - SINK
            # the mesh's +X along the street: a turn by -th about Y (+90, +180 degrees)
            yaw = -th + (math.pi / 2 if turn else 0.0) + (math.pi if rng.random() < 0.5 else 0.0)
            sx, sy, sz = round(vw / ASPECTS[ai][0], 4), round((h + SINK) / hc, 4), round(vd / ASPECTS[ai][1], 4)
            children.append(g.add("nodes", {
                "name": "b%d_%d" % (k, bi), "mesh": mesh,
                "translation": [round(x, 3), round(base, 3), round(z, 3)],
                "rotation": [0.0, round(math.sin(yaw / 2), 7), 0.0, round(math.cos(yaw / 2), 7)],
                "scale": [sx, sy, sz], "extras": {"texelDensity": a.building_density}}))
            totals.add(ntri, axis_area[0] * sy * sz + axis_area[1] * sx * sz + axis_area[2] * sx * sy,
                       a.building_density)
        roots.append(g.add("nodes", {"name": "district_%d" % k, "children": children}))
    return roots


def add_camera(g, a, plan, place, heights):
    """Past the near end of the district's streets, above the roofs, aimed at its centre."""
    (dcx, dcz, th), L = place, plan[1]
    ex, ez = dcx - 0.6 * L * math.cos(th), dcz - 0.6 * L * math.sin(th)
    ey = ground(heights, a, ex, ez) + max(15.0, 0.6 * a.height_m[1])
    dx, dy, dz = dcx - ex, ground(heights, a, dcx, dcz) - ey, dcz - ez
    yaw, pitch = math.atan2(-dx, -dz), math.atan2(dy, math.hypot(dx, dz))  # q = q_yaw(Y) q_pitch(X)
    cy, sy, cp, sp = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(pitch / 2), math.sin(pitch / 2)
    g.add("cameras", {"type": "perspective", "name": "over_district_0", "perspective": {
        "yfov": 0.9, "aspectRatio": 1.7778, "znear": 0.5, "zfar": round(2.0 * a.size_m, 1)}})
    return g.add("nodes", {"name": "camera", "camera": 0, "translation": [round(ex, 3), round(ey, 3), round(ez, 3)],
                           "rotation": [round(cy * sp, 7), round(sy * cp, 7), round(-sy * sp, 7), round(cy * cp, 7)]})


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", required=True, help="OUT.gltf (OUT.bin is written next to it)")
    ap.add_argument("--preset", choices=sorted(PRESETS), default="city", help="size knobs (default city)")
    ap.add_argument("--seed", type=int, default=1)
    for flag, kind, nargs, text in (
            ("size-m", float, None, "terrain side (m)"), ("terrain-tiles", int, None, "tiles per side"),
            ("terrain-quads", int, None, "quads per tile side"), ("buildings", int, None, "building instances"),
            ("building-detail", int, None, "window bands per tier"), ("districts", int, None, "building districts"),
            ("terrain-density", float, None, "texels per metre"), ("building-density", float, None, "texels per metre"),
            ("footprint-m", float, 2, "building side range (m)"), ("height-m", float, 2, "building height range (m)")):
        ap.add_argument("--" + flag, type=kind, nargs=nargs, help=text, metavar=("MIN", "MAX") if nargs else None)
    a = ap.parse_args()
    for key, value in {**DEFAULTS, **PRESETS[a.preset]}.items():
        if getattr(a, key) is None:
            setattr(a, key, value)
    if (min(a.size_m, a.terrain_tiles, a.terrain_quads, a.buildings, a.districts, a.terrain_density,
            a.building_density) <= 0 or a.building_detail < 0 or not 4 <= a.footprint_m[0] <= a.footprint_m[1]
            or not 3 <= a.height_m[0] <= a.height_m[1]):
        ap.error("sizes, counts and densities must be positive, footprints >= 4 m, heights >= 3 m, MIN <= MAX")
    return a


def main():
    t_start = time.perf_counter()
    a = parse_args()
    rng = random.Random(a.seed)
    g, totals = Gltf(), Totals()
    g.doc["materials"] = [material("terrain", (0.28, 0.31, 0.25)), material("concrete", (0.62, 0.62, 0.6)),
                          material("stone", (0.52, 0.5, 0.48))]
    # districts: planned in their own coordinates, placed, then the terrain flattened under them
    weights = [rng.uniform(0.6, 1.4) for _ in range(a.districts)]
    quotas = [round(a.buildings * w / sum(weights)) for w in weights[:-1]]
    quotas.append(a.buildings - sum(quotas))
    plans = [plan_district(rng, quota, a) for quota in quotas]
    placed = place_districts(rng, [(L, Z) for _, L, Z in plans], a.size_m / 2)
    heights = make_heightfield(rng, a, [p + (L, Z) for p, (_, L, Z) in zip(placed, plans)])
    roots = [add_terrain(g, a, heights, totals)] + add_buildings(g, rng, a, plans, placed, heights, totals)
    roots.append(add_camera(g, a, plans[0], placed[0], heights))
    g.add("scenes", {"name": "city, seed %d" % a.seed, "nodes": roots})

    base_path = a.output[:-5] if a.output.endswith(".gltf") else a.output
    gltf_path, bin_path = base_path + ".gltf", base_path + ".bin"
    g.add("buffers", {"uri": os.path.basename(bin_path), "byteLength": len(g.bin)})
    text = json.dumps(g.doc, separators=(",", ":")).encode() + b"\n"
    write_atomic(bin_path, bytes(g.bin))
    write_atomic(gltf_path, text)
    print("%s: triangles=%d meshes=%d nodes=%d instances=%d area_m2=%.0f texels_est=%.0f bytes=%d seconds=%.1f" % (
        gltf_path, totals.triangles, len(g.doc["meshes"]), len(g.doc["nodes"]), a.terrain_tiles ** 2 + a.buildings,
        totals.area, totals.texels, len(text) + len(g.bin), time.perf_counter() - t_start))


if __name__ == "__main__":
    main()
