#!/usr/bin/env python3
"""Generates bundlebake's small analytic test scenes under assets/.

usage: make_assets.py [ASSETS_DIR]        (default: <repo>/assets)

Standard library only. Writes, for each scene, a .gltf (glTF 2.0 JSON) with an
external .bin, then reads every file back and checks it (see verify()): accessor
bounds and alignment, POSITION min/max, winding against NORMAL, which side each
face faces, closed enclosures being watertight (no boundary edge, no
T-junction), and that no two TEXCOORD_1 charts overlap or come closer than
GAP. It also writes assets/probes.json (analytic answers at points, with their
TEXCOORD_1) and assets/README.md. It exits non-zero if any check fails.

Conventions (bundlebake DESIGN.md, "Units"): metres; the stored lightmap value
is L_lm = E/pi; emitted radiance Le = emissiveFactor * emissive_strength.

Lightmap UVs (TEXCOORD_1): every planar face is its own chart, one shared atlas
per scene (`--uv-layout asset`). A chart is the face projected onto its own
plane, scaled by one scene-wide density S (UV per metre, times an optional
per-face weight), packed with a skyline bottom-left packer; S is the largest
value for which everything fits. Charts keep GAP between each other and
BORDER from the atlas edge. A chart thinner than MIN_EXTENT along one axis is
stretched along that axis only, so that every chart covers whole texels at 64x64.
"""
import json
import math
import os
import struct
import sys

GAP = 0.035          # UV gap between charts: > 2 texels at 64x64 (2/64 = 0.03125)
BORDER = GAP / 2     # UV margin to the atlas edge (tiling the atlas keeps GAP)
MIN_EXTENT = 2.0 / 64.0  # smallest chart side in UV (2 texels at 64x64)
GENERATOR = "bundlebake scripts/make_assets.py"
EMISSIVE_STRENGTH = "KHR_materials_emissive_strength"

# ----------------------------------------------------------------------------
# small vector helpers (tuples of floats)


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def length(a):
    return math.sqrt(dot(a, a))


def normalize(a):
    n = length(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def centroid(pts):
    n = float(len(pts))
    return (sum(p[0] for p in pts) / n, sum(p[1] for p in pts) / n, sum(p[2] for p in pts) / n)


def newell_normal(pts):
    nx = ny = nz = 0.0
    for i, p in enumerate(pts):
        q = pts[(i + 1) % len(pts)]
        nx += (p[1] - q[1]) * (p[2] + q[2])
        ny += (p[2] - q[2]) * (p[0] + q[0])
        nz += (p[0] - q[0]) * (p[1] + q[1])
    return normalize((nx, ny, nz))


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


# ----------------------------------------------------------------------------
# analytic form factors (ANALYTIC_REFERENCES.md sections 2 and 3a)


def lambert_form_factor(x, n, poly):
    """Point-to-polygon form factor (Lambert). poly must be unoccluded and in front of x."""
    s = 0.0
    for i in range(len(poly)):
        a = normalize(sub(poly[i], x))
        b = normalize(sub(poly[(i + 1) % len(poly)], x))
        theta = math.acos(max(-1.0, min(1.0, dot(a, b))))
        s += theta * dot(n, normalize(cross(a, b)))
    return abs(s) / (2.0 * math.pi)


def corner_form_factor(a, b, c):
    """Point under one corner of a parallel a x b rectangle at distance c (3a)."""
    X, Y = a / c, b / c
    return (X / math.sqrt(1 + X * X) * math.atan(Y / math.sqrt(1 + X * X))
            + Y / math.sqrt(1 + Y * Y) * math.atan(X / math.sqrt(1 + Y * Y))) / (2 * math.pi)


# ----------------------------------------------------------------------------
# faces: planar polygons (or explicit triangle sets) with an intended normal


class Face:
    """One chart. pts: 3D points; tris: index triples or None (ear-clip pts)."""

    def __init__(self, name, pts, normal, tris=None, weight=1.0):
        self.name = name
        self.pts = [tuple(float(c) for c in p) for p in pts]
        self.intended = normalize(normal)
        self.tris_in = tris
        self.weight = weight
        self.build()

    def build(self):
        n = newell_normal(self.pts) if self.tris_in is None else self.intended
        if dot(n, self.intended) < 0:
            n = mul(n, -1.0)
        if dot(n, self.intended) < 0.99:
            raise ValueError("%s: polygon normal %r far from intended %r" % (self.name, n, self.intended))
        self.n = n
        # chart basis: the polygon edge direction that gives the smallest bounding box
        best = None
        for i in range(len(self.pts)):
            e = sub(self.pts[(i + 1) % len(self.pts)], self.pts[i])
            e = sub(e, mul(n, dot(e, n)))
            if length(e) < 1e-9:
                continue
            t = normalize(e)
            b = cross(n, t)
            us = [dot(p, t) for p in self.pts]
            vs = [dot(p, b) for p in self.pts]
            area = (max(us) - min(us)) * (max(vs) - min(vs))
            if best is None or area < best[0] - 1e-12:
                best = (area, t, b, min(us), min(vs), max(us) - min(us), max(vs) - min(vs))
        _, self.t, self.b, u0, v0, self.w, self.h = best
        self.local = [(dot(p, self.t) - u0, dot(p, self.b) - v0) for p in self.pts]
        if self.tris_in is None:
            self.tris = ear_clip(self.local, self.name)
        else:
            self.tris = []
            for (i, j, k) in self.tris_in:
                g = cross(sub(self.pts[j], self.pts[i]), sub(self.pts[k], self.pts[i]))
                self.tris.append((i, j, k) if dot(g, n) > 0 else (i, k, j))

    def area(self):
        return sum(0.5 * length(cross(sub(self.pts[j], self.pts[i]), sub(self.pts[k], self.pts[i])))
                   for (i, j, k) in self.tris)


def ear_clip(poly, name):
    """Triangulates a simple 2D polygon; returns CCW index triples.

    A vertex lying on a candidate ear's boundary blocks that ear, so collinear
    vertices (kept on purpose to avoid T-junctions) are never skipped over.
    """
    def area2(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    signed = sum(area2((0.0, 0.0), poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))
    idx = list(range(len(poly)))
    if signed < 0:
        idx.reverse()
    eps = 1e-12
    tris = []
    while len(idx) > 3:
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = poly[i0], poly[i1], poly[i2]
            if area2(a, b, c) <= eps:
                continue
            blocked = False
            for j in idx:
                p = poly[j]
                if j in (i0, i1, i2) or p in (a, b, c):
                    continue
                if area2(a, b, p) >= -eps and area2(b, c, p) >= -eps and area2(c, a, p) >= -eps:
                    blocked = True
                    break
            if not blocked:
                tris.append((i0, i1, i2))
                idx.pop(k)
                break
        else:
            raise ValueError("%s: ear clipping found no ear" % name)
    if area2(poly[idx[0]], poly[idx[1]], poly[idx[2]]) <= eps:
        raise ValueError("%s: degenerate last triangle" % name)
    tris.append(tuple(idx))
    return tris


def quad_frame(name, outer, inner, normal):
    """A planar ring between two corresponding 4-point loops (a ceiling with a hole)."""
    pts = list(outer) + list(inner)
    tris = []
    for k in range(4):
        o0, o1, i0, i1 = k, (k + 1) % 4, 4 + k, 4 + (k + 1) % 4
        tris += [(o0, o1, i1), (o0, i1, i0)]
    return Face(name, pts, normal, tris=tris)


def box_faces(prefix, lo, hi, inward, skip=()):
    """Axis-aligned box faces, as quads; inward=True makes them face the inside."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    s = -1.0 if inward else 1.0
    faces = {
        "floor" if inward else "bottom": ([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (0, -s, 0)),
        "ceiling" if inward else "top": ([(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)], (0, s, 0)),
        "wall_xmin": ([(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)], (-s, 0, 0)),
        "wall_xmax": ([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)], (s, 0, 0)),
        "wall_zmin": ([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)], (0, 0, -s)),
        "wall_zmax": ([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (0, 0, s)),
    }
    return [Face(prefix + k, p, n) for k, (p, n) in faces.items() if k not in skip]


# ----------------------------------------------------------------------------
# chart packing (skyline bottom-left)


def skyline_pack(sizes, W, H):
    """sizes: (w, h) padded rectangles. Returns lower-left corners or None."""
    sky = [[0.0, 0.0, W]]  # segments [x, y, width], left to right
    order = sorted(range(len(sizes)), key=lambda i: (-sizes[i][1], -sizes[i][0], i))
    pos = [None] * len(sizes)
    for i in order:
        w, h = sizes[i]
        best = None
        for j in range(len(sky)):
            x = sky[j][0]
            if x + w > W + 1e-12:
                break
            y, k, rem = 0.0, j, w
            while rem > 1e-12:
                y = max(y, sky[k][1])
                rem -= sky[k][2]
                k += 1
                if k >= len(sky) and rem > 1e-12:
                    y = float("inf")
                    break
            if y + h <= H + 1e-12 and (best is None or (y + h, x) < (best[0] + h, best[1])):
                best = (y, x)
        if best is None:
            return None
        y, x = best
        pos[i] = (x, y)
        # raise the skyline over [x, x + w)
        new = []
        for sx, sy, sw in sky:
            if sx + sw <= x + 1e-12 or sx >= x + w - 1e-12:
                new.append([sx, sy, sw])
                continue
            if sx < x:
                new.append([sx, sy, x - sx])
            if sx + sw > x + w:
                new.append([x + w, sy, sx + sw - (x + w)])
        new.append([x, y + h, w])
        new.sort()
        merged = []
        for seg in new:
            if merged and abs(merged[-1][1] - seg[1]) < 1e-12:
                merged[-1][2] = seg[0] + seg[2] - merged[-1][0]
            else:
                merged.append(seg)
        sky = merged
    return pos


def chart_extent(f, s):
    """UV extent (w, h) of face f at density s, landscape, with the thin-axis minimum."""
    w, h = f.w * s * f.weight, f.h * s * f.weight
    return max(w, MIN_EXTENT), max(h, MIN_EXTENT)


def pack_charts(faces):
    """Finds the largest density s that fits, and sets each face's UV mapping."""
    side = 1.0 - 2 * BORDER + GAP

    def attempt(s):
        sizes = []
        for f in faces:
            w, h = chart_extent(f, s)
            f.rot = h > w + 1e-12  # store landscape: long side along U
            if f.rot:
                w, h = h, w
            sizes.append((w + GAP, h + GAP))
        return skyline_pack(sizes, side, side)

    lo, hi = 0.0, 1.0 / min(max(f.w, f.h) * f.weight for f in faces)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if attempt(mid) is not None:
            lo = mid
        else:
            hi = mid
    s = lo
    pos = attempt(s)
    assert pos is not None
    for f, (px, py) in zip(faces, pos):
        w, h = chart_extent(f, s)
        ku = w / f.w   # UV per metre along the chart's own axes (anisotropic if stretched)
        kv = h / f.h
        ox, oy = BORDER + px, BORDER + py
        if f.rot:
            f.uv = [(ox + v * kv, oy + u * ku) for (u, v) in f.local]
        else:
            f.uv = [(ox + u * ku, oy + v * kv) for (u, v) in f.local]
        f.density = (ku, kv)
    return s


# ----------------------------------------------------------------------------
# scenes


def material(name, albedo, emission=None, double_sided=False):
    m = {
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [float(albedo[0]), float(albedo[1]), float(albedo[2]), 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "doubleSided": double_sided,
    }
    if emission is not None and max(emission) > 0:
        peak = max(emission)
        if peak > 1.0:
            m["emissiveFactor"] = [e / peak for e in emission]
            m["extensions"] = {EMISSIVE_STRENGTH: {"emissiveStrength": float(peak)}}
        else:
            m["emissiveFactor"] = [float(e) for e in emission]
    return m


def look_at_rotation(eye, target, up=(0.0, 1.0, 0.0)):
    """Quaternion (x, y, z, w) that turns a glTF camera (looking down -Z) toward target."""
    fwd = normalize(sub(target, eye))
    right = normalize(cross(fwd, up))
    upv = cross(right, fwd)
    back = mul(fwd, -1.0)
    # rotation matrix columns: right, up, back
    m00, m01, m02 = right[0], upv[0], back[0]
    m10, m11, m12 = right[1], upv[1], back[1]
    m20, m21, m22 = right[2], upv[2], back[2]
    tr = m00 + m11 + m22
    if tr > 0:
        S = math.sqrt(tr + 1.0) * 2
        q = ((m21 - m12) / S, (m02 - m20) / S, (m10 - m01) / S, 0.25 * S)
    elif m00 > m11 and m00 > m22:
        S = math.sqrt(1.0 + m00 - m11 - m22) * 2
        q = (0.25 * S, (m01 + m10) / S, (m02 + m20) / S, (m21 - m12) / S)
    elif m11 > m22:
        S = math.sqrt(1.0 + m11 - m00 - m22) * 2
        q = ((m01 + m10) / S, 0.25 * S, (m12 + m21) / S, (m02 - m20) / S)
    else:
        S = math.sqrt(1.0 + m22 - m00 - m11) * 2
        q = ((m02 + m20) / S, (m12 + m21) / S, 0.25 * S, (m10 - m01) / S)
    return [round(c, 9) for c in normalize4(q)]


def normalize4(q):
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


class Scene:
    """meshes: list of (mesh name, material name, [faces]); one node per mesh."""

    def __init__(self, name, materials, meshes, camera=None, copyright_=None, extras=None):
        self.name = name
        self.materials = materials
        self.meshes = meshes
        self.camera = camera
        self.copyright = copyright_
        self.extras = extras or {}
        self.faces = [f for (_, _, fs) in meshes for f in fs]
        self.density = pack_charts(self.faces)


def mm(p):
    return tuple(c / 1000.0 for c in p)


def cornell_box():
    white, red, green = (0.725, 0.71, 0.68), (0.63, 0.065, 0.05), (0.14, 0.45, 0.091)
    mats = [material("white", white), material("red", red), material("green", green),
            material("light", (0.78, 0.78, 0.78), emission=(17.0, 12.0, 4.0))]
    F = lambda name, pts, n: Face(name, [mm(p) for p in pts], n)  # noqa: E731
    floor = F("floor", [(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)], (0, 1, 0))
    ceiling = F("ceiling", [(556, 548.8, 0), (556, 548.8, 559.2), (0, 548.8, 559.2), (0, 548.8, 0)], (0, -1, 0))
    back = F("back_wall", [(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)], (0, 0, -1))
    green_w = F("green_wall", [(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)], (1, 0, 0))
    red_w = F("red_wall", [(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)], (-1, 0, 0))
    light = F("light", [(343, 547.9, 227), (343, 547.9, 332), (213, 547.9, 332), (213, 547.9, 227)], (0, -1, 0))

    def block(prefix, top, corners):
        c = centroid([(x, 0.0, z) for (x, z) in corners])
        faces = [F(prefix + "top", [(x, top, z) for (x, z) in corners], (0, 1, 0))]
        for i in range(4):
            (xa, za), (xb, zb) = corners[i], corners[(i + 1) % 4]
            side = [(xa, 0, za), (xa, top, za), (xb, top, zb), (xb, 0, zb)]
            out = sub(centroid([(xa, 0, za), (xb, 0, zb)]), c)
            faces.append(F(prefix + "side%d" % i, side, out))
        return faces

    short = block("short_block_", 165.0, [(130, 65), (82, 225), (240, 272), (290, 114)])
    tall = block("tall_block_", 330.0, [(423, 247), (265, 296), (314, 456), (472, 406)])
    meshes = [("floor", "white", [floor]), ("ceiling", "white", [ceiling]), ("back_wall", "white", [back]),
              ("red_wall", "red", [red_w]), ("green_wall", "green", [green_w]),
              ("short_block", "white", short), ("tall_block", "white", tall), ("light", "light", [light])]
    cam = {"name": "cornell_camera", "translation": [0.278, 0.273, -0.8], "rotation": [0.0, 1.0, 0.0, 0.0],
           "yfov": 2 * math.atan(0.0125 / 0.035), "aspectRatio": 1.0, "znear": 0.01, "zfar": 10.0}
    return Scene("cornell_box", mats, meshes, cam,
                 "Geometry: Cornell Box Data, Cornell University Program of Computer Graphics "
                 "(https://www.graphics.cornell.edu/online/box/data.html); mm converted to m. "
                 "File generated by " + GENERATOR + ".")


def furnace(rho):
    mats = [material("furnace_rho%g" % rho, (rho, rho, rho), emission=(1.0, 1.0, 1.0))]
    outer = box_faces("outer_", (-0.5, 0.0, -0.5), (0.5, 1.0, 0.5), inward=True)
    inner = box_faces("inner_", (-0.15, 0.35, -0.15), (0.15, 0.65, 0.15), inward=False)
    meshes = [("outer_box", mats[0]["name"], outer), ("inner_box", mats[0]["name"], inner)]
    eye = (0.42, 0.85, 0.42)
    cam = {"name": "furnace_camera", "translation": list(eye), "rotation": look_at_rotation(eye, (0, 0.45, 0)),
           "yfov": 1.3, "aspectRatio": 1.0, "znear": 0.01, "zfar": 10.0}
    return Scene("furnace", mats, meshes, cam)


def sky_plane():
    mats = [material("grey", (0.5, 0.5, 0.5))]
    plane = Face("plane", [(-5, 0, -5), (5, 0, -5), (5, 0, 5), (-5, 0, 5)], (0, 1, 0))
    eye = (0.0, 6.0, 12.0)
    cam = {"name": "sky_camera", "translation": list(eye), "rotation": look_at_rotation(eye, (0, 0, 0)),
           "yfov": 0.9, "aspectRatio": 1.0, "znear": 0.05, "zfar": 100.0}
    return Scene("sky_plane", mats, [("plane", "grey", [plane])], cam)


def open_box():
    mats = [material("black", (0.0, 0.0, 0.0))]
    faces = box_faces("", (-0.5, 0.0, -0.5), (0.5, 1.0, 0.5), inward=True, skip=("ceiling",))
    floor = [f for f in faces if f.name == "floor"]
    floor[0].weight = 2.0  # twice the linear texel density on the surface tests read
    walls = [f for f in faces if f.name != "floor"]
    eye = (0.0, 2.4, 1.5)
    cam = {"name": "open_box_camera", "translation": list(eye), "rotation": look_at_rotation(eye, (0, 0.3, 0)),
           "yfov": 0.8, "aspectRatio": 1.0, "znear": 0.01, "zfar": 20.0}
    return Scene("open_box", mats, [("floor", "black", floor), ("walls", "black", walls)], cam)


# two rooms: interiors x in [-2.01,-0.01] (A) and [0.01, 2.01] (B), y in [0,2], z in [-1,1]
TR = {"ax0": -2.01, "ax1": -0.01, "bx0": 0.01, "bx1": 2.01, "y1": 2.0, "z": 1.0,
      "panel": (-1.26, -0.76, -0.25, 0.25), "door_z": 0.2, "door_h": 1.0}


def street_canyon():
    """A street canyon with recessed window bands: two walls 10 m high, 6 m apart and 12 m long (albedo 0.6) over
    a black street, each with a band from 4 to 5.5 m recessed 35 cm (sill, recessed wall, lintel), under a sky.
    The sills and lintels, 35 cm deep, are strips under half a texel across at 32x32 (the generated city's
    ledges and sills are a fifth of a texel): issue 11's bench scene and the noise estimate's sliver test."""
    def wall(side):
        s = -1.0 if side == "A" else 1.0
        x0, xr, n, L = 3.0 * s, 3.35 * s, (-s, 0.0, 0.0), 6.0
        quads = [("lower", [(x0, 0, -L), (x0, 0, L), (x0, 4, L), (x0, 4, -L)], n),
                 ("sill", [(x0, 4, -L), (x0, 4, L), (xr, 4, L), (xr, 4, -L)], (0, 1, 0)),
                 ("recess", [(xr, 4, -L), (xr, 4, L), (xr, 5.5, L), (xr, 5.5, -L)], n),
                 ("lintel", [(x0, 5.5, -L), (x0, 5.5, L), (xr, 5.5, L), (xr, 5.5, -L)], (0, -1, 0)),
                 ("upper", [(x0, 5.5, -L), (x0, 5.5, L), (x0, 10, L), (x0, 10, -L)], n)]
        return [("%s_%s" % (side, name), "wall", [Face("%s_%s" % (side, name), pts, normal)])
                for name, pts, normal in quads]

    street = Face("street", [(-3, 0, -6), (3, 0, -6), (3, 0, 6), (-3, 0, 6)], (0, 1, 0))
    eye = (0.0, 8.0, 14.0)
    camera = {"name": "canyon_camera", "translation": list(eye), "rotation": look_at_rotation(eye, (0, 4, 0)),
              "yfov": 1.0, "aspectRatio": 1.0, "znear": 0.05, "zfar": 100.0}
    return Scene("street_canyon", [material("wall", (0.6, 0.6, 0.6)), material("black", (0.0, 0.0, 0.0))],
                 wall("A") + wall("B") + [("street", "black", [street])], camera)


def two_rooms(doorway):
    ax0, ax1, bx0, bx1, y1, Z = TR["ax0"], TR["ax1"], TR["bx0"], TR["bx1"], TR["y1"], TR["z"]
    dz, dh = TR["door_z"], TR["door_h"]
    mats = [material("grey", (0.5, 0.5, 0.5)), material("panel", (0.5, 0.5, 0.5), emission=(10.0, 10.0, 10.0))]

    def room(prefix, x0, x1, div_x, div_n):
        # walls and floor; the dividing-wall face is built separately below
        skip = ("wall_xmax" if div_x == x1 else "wall_xmin", "ceiling")
        if doorway:
            skip += ("floor",)
        faces = box_faces(prefix, (x0, 0.0, -Z), (x1, y1, Z), inward=True, skip=skip)
        if doorway:  # floor keeps vertices at the doorway edges: no T-junction
            xo = x0 if div_x == x1 else x1
            faces.append(Face(prefix + "floor", [(xo, 0, -Z), (div_x, 0, -Z), (div_x, 0, -dz), (div_x, 0, dz),
                                                 (div_x, 0, Z), (xo, 0, Z)], (0, 1, 0)))
            faces.append(Face(prefix + "divider", [(div_x, 0, -Z), (div_x, 0, -dz), (div_x, dh, -dz),
                                                   (div_x, dh, dz), (div_x, 0, dz), (div_x, 0, Z),
                                                   (div_x, y1, Z), (div_x, y1, -Z)], div_n))
        else:
            faces.append(Face(prefix + "divider", [(div_x, 0, -Z), (div_x, 0, Z), (div_x, y1, Z),
                                                   (div_x, y1, -Z)], div_n))
        return faces

    a = room("a_", ax0, ax1, ax1, (-1, 0, 0))
    px0, px1, pz0, pz1 = TR["panel"]
    inner = [(px0, y1, pz0), (px1, y1, pz0), (px1, y1, pz1), (px0, y1, pz1)]
    a.append(quad_frame("a_ceiling", [(ax0, y1, -Z), (ax1, y1, -Z), (ax1, y1, Z), (ax0, y1, Z)], inner, (0, -1, 0)))
    panel = Face("a_panel", inner, (0, -1, 0))
    b = room("b_", bx0, bx1, bx0, (1, 0, 0))
    b += box_faces("b_", (bx0, 0.0, -Z), (bx1, y1, Z), inward=True,
                   skip=("floor", "wall_xmin", "wall_xmax", "wall_zmin", "wall_zmax"))
    meshes = [("room_a", "grey", a), ("room_a_panel", "panel", [panel]), ("room_b", "grey", b)]
    if doorway:
        door = [
            Face("jamb_zmin", [(ax1, 0, -dz), (bx0, 0, -dz), (bx0, dh, -dz), (ax1, dh, -dz)], (0, 0, 1)),
            Face("jamb_zmax", [(ax1, 0, dz), (bx0, 0, dz), (bx0, dh, dz), (ax1, dh, dz)], (0, 0, -1)),
            Face("lintel", [(ax1, dh, -dz), (bx0, dh, -dz), (bx0, dh, dz), (ax1, dh, dz)], (0, -1, 0)),
            Face("threshold", [(ax1, 0, -dz), (bx0, 0, -dz), (bx0, 0, dz), (ax1, 0, dz)], (0, 1, 0)),
        ]
        meshes.append(("doorway", "grey", door))
    eye = (-1.95, 1.5, 0.95)
    cam = {"name": "room_a_camera", "translation": list(eye), "rotation": look_at_rotation(eye, (0.0, 0.7, -0.3)),
           "yfov": 1.2, "aspectRatio": 1.0, "znear": 0.01, "zfar": 20.0}
    return Scene("two_rooms_doorway" if doorway else "two_rooms", mats, meshes, cam)


# ----------------------------------------------------------------------------
# glTF writer


def build_gltf(scene, bin_uri):
    buf = bytearray()
    views, accessors = [], []

    def add_view(data, target):
        while len(buf) % 4:
            buf.append(0)
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "target": target})
        buf.extend(data)
        return len(views) - 1

    def add_accessor(values, ncomp, ctype, target, minmax=False):
        if ctype == 5126:
            flat = [c for v in values for c in v]
            data = struct.pack("<%df" % len(flat), *flat)
        elif ctype == 5123:
            data = struct.pack("<%dH" % len(values), *values)
        else:
            data = struct.pack("<%dI" % len(values), *values)
        acc = {"bufferView": add_view(data, target), "componentType": ctype, "count": len(values),
               "type": {1: "SCALAR", 2: "VEC2", 3: "VEC3"}[ncomp]}
        if minmax:
            acc["min"] = [min(f32(v[i]) for v in values) for i in range(ncomp)]
            acc["max"] = [max(f32(v[i]) for v in values) for i in range(ncomp)]
        accessors.append(acc)
        return len(accessors) - 1

    mat_index = {m["name"]: i for i, m in enumerate(scene.materials)}
    meshes, nodes = [], []
    for mesh_name, mat_name, faces in scene.meshes:
        pos, nrm, uv, uv0, idx = [], [], [], [], []
        for f in faces:
            tri_normals = [normalize(cross(sub(f.pts[j], f.pts[i]), sub(f.pts[k], f.pts[i]))) for (i, j, k) in f.tris]
            planar = all(dot(tn, tri_normals[0]) > 1 - 1e-12 for tn in tri_normals)
            if planar:  # shared vertices, one flat normal
                base = len(pos)
                for p, t, l in zip(f.pts, f.uv, f.local):
                    pos.append(p)
                    nrm.append(tri_normals[0])
                    uv.append(t)
                    uv0.append(l)
                for (i, j, k) in f.tris:
                    idx += [base + i, base + j, base + k]
            else:  # non-planar quad (Cornell walls): each triangle gets its own flat normal
                for (i, j, k), tn in zip(f.tris, tri_normals):
                    for v in (i, j, k):
                        idx.append(len(pos))
                        pos.append(f.pts[v])
                        nrm.append(tn)
                        uv.append(f.uv[v])
                        uv0.append(f.local[v])
        ctype = 5123 if len(pos) < 65536 else 5125
        attrs = {"POSITION": add_accessor(pos, 3, 5126, 34962, minmax=True),
                 "NORMAL": add_accessor(nrm, 3, 5126, 34962),
                 # the spec wants TEXCOORD_0 before TEXCOORD_1: planar, 1 unit per metre
                 "TEXCOORD_0": add_accessor(uv0, 2, 5126, 34962),
                 "TEXCOORD_1": add_accessor(uv, 2, 5126, 34962)}
        prim = {"attributes": attrs, "indices": add_accessor(idx, 1, ctype, 34963),
                "material": mat_index[mat_name], "mode": 4}
        meshes.append({"name": mesh_name, "primitives": [prim]})
        nodes.append({"name": mesh_name, "mesh": len(meshes) - 1})
    while len(buf) % 4:
        buf.append(0)
    gl = {"asset": {"version": "2.0", "generator": GENERATOR}}
    if scene.copyright:
        gl["asset"]["copyright"] = scene.copyright
    used = sorted({e for m in scene.materials for e in m.get("extensions", {})})
    if used:
        gl["extensionsUsed"] = used
    cameras = []
    if scene.camera:
        c = scene.camera
        cameras.append({"name": c["name"], "type": "perspective",
                        "perspective": {"yfov": c["yfov"], "aspectRatio": c["aspectRatio"],
                                        "znear": c["znear"], "zfar": c["zfar"]}})
        nodes.append({"name": c["name"], "camera": 0, "translation": c["translation"], "rotation": c["rotation"]})
    gl["scene"] = 0
    gl["scenes"] = [{"name": scene.name, "nodes": list(range(len(nodes)))}]
    gl["nodes"] = nodes
    if cameras:
        gl["cameras"] = cameras
    gl["meshes"] = meshes
    gl["materials"] = scene.materials
    gl["accessors"] = accessors
    gl["bufferViews"] = views
    gl["buffers"] = [{"uri": bin_uri, "byteLength": len(buf)}]
    if scene.extras:
        gl["extras"] = scene.extras
    return gl, bytes(buf)


def write_scene(scene, folder, stem, bin_stem=None):
    os.makedirs(folder, exist_ok=True)
    bin_name = (bin_stem or stem) + ".bin"
    gl, data = build_gltf(scene, bin_name)
    bin_path = os.path.join(folder, bin_name)
    if bin_stem and bin_stem != stem:  # a variant sharing another file's geometry
        with open(bin_path, "rb") as fh:
            if fh.read() != data:
                raise SystemExit("%s: shared .bin differs" % bin_path)
    else:
        with open(bin_path, "wb") as fh:
            fh.write(data)
    path = os.path.join(folder, stem + ".gltf")
    with open(path, "w") as fh:
        json.dump(gl, fh, indent=1)
        fh.write("\n")
    return path


# ----------------------------------------------------------------------------
# read-back and verification


class Loaded:
    def __init__(self, path):
        self.path = path
        with open(path) as fh:
            self.gl = json.load(fh)
        with open(os.path.join(os.path.dirname(path), self.gl["buffers"][0]["uri"]), "rb") as fh:
            self.bin = fh.read()
        # (mesh name, material index, p0, p1, p2, n0.., uv0..)
        self.tris = []
        for mesh in self.gl["meshes"]:
            for prim in mesh["primitives"]:
                P = self.read(prim["attributes"]["POSITION"])
                N = self.read(prim["attributes"]["NORMAL"])
                U = self.read(prim["attributes"]["TEXCOORD_1"])
                I = self.read(prim["indices"])
                for t in range(0, len(I), 3):
                    i, j, k = I[t], I[t + 1], I[t + 2]
                    self.tris.append({"mesh": mesh["name"], "material": prim["material"],
                                      "p": (P[i], P[j], P[k]), "n": (N[i], N[j], N[k]), "uv": (U[i], U[j], U[k])})

    def read(self, ai):
        a = self.gl["accessors"][ai]
        v = self.gl["bufferViews"][a["bufferView"]]
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        fmt = {5126: "f", 5123: "H", 5125: "I"}[a["componentType"]]
        off = v["byteOffset"] + a.get("byteOffset", 0)
        vals = struct.unpack_from("<%d%s" % (a["count"] * ncomp, fmt), self.bin, off)
        if ncomp == 1:
            return list(vals)
        return [tuple(vals[i:i + ncomp]) for i in range(0, len(vals), ncomp)]


class Checker:
    def __init__(self):
        self.failures = []
        self.count = 0

    def check(self, ok, what):
        self.count += 1
        if not ok:
            self.failures.append(what)
            print("FAIL: " + what, file=sys.stderr)


def check_structure(L, C):
    gl, name = L.gl, os.path.basename(L.path)
    C.check(gl["asset"]["version"] == "2.0", name + ": asset.version")
    C.check(len(L.bin) == gl["buffers"][0]["byteLength"] and len(L.bin) % 4 == 0, name + ": buffer byteLength")
    for i, v in enumerate(gl["bufferViews"]):
        C.check(v["byteOffset"] % 4 == 0 and v["byteOffset"] + v["byteLength"] <= len(L.bin),
                "%s: bufferView %d bounds/alignment" % (name, i))
    sizes = {5126: 4, 5123: 2, 5125: 4}
    for i, a in enumerate(gl["accessors"]):
        v = gl["bufferViews"][a["bufferView"]]
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        C.check(a["count"] * ncomp * sizes[a["componentType"]] <= v["byteLength"], "%s: accessor %d fits" % (name, i))
    for mesh in gl["meshes"]:
        for prim in mesh["primitives"]:
            at = prim["attributes"]
            C.check(all(k in at for k in ("POSITION", "NORMAL", "TEXCOORD_0", "TEXCOORD_1")) and "indices" in prim
                    and "material" in prim, "%s/%s: attributes" % (name, mesh["name"]))
            pa = gl["accessors"][at["POSITION"]]
            P = L.read(at["POSITION"])
            C.check("min" in pa and "max" in pa and pa["min"] == [min(p[c] for p in P) for c in range(3)]
                    and pa["max"] == [max(p[c] for p in P) for c in range(3)], "%s/%s: POSITION min/max"
                    % (name, mesh["name"]))
            I = L.read(prim["indices"])
            C.check(len(I) % 3 == 0 and max(I) < len(P), "%s/%s: indices" % (name, mesh["name"]))
            for n in L.read(at["NORMAL"]):
                if abs(length(n) - 1) > 1e-6:
                    C.check(False, "%s/%s: NORMAL not unit" % (name, mesh["name"]))
                    break
    uses_strength = False
    for m in gl["materials"]:
        pbr = m["pbrMetallicRoughness"]
        C.check(pbr["metallicFactor"] == 0 and len(pbr["baseColorFactor"]) == 4, "%s: material %s" % (name, m["name"]))
        if EMISSIVE_STRENGTH in m.get("extensions", {}):
            uses_strength = True
            C.check(max(m["emissiveFactor"]) == 1.0, "%s: %s emissiveFactor normalised" % (name, m["name"]))
    C.check(uses_strength == (EMISSIVE_STRENGTH in gl.get("extensionsUsed", [])), name + ": extensionsUsed")


def tri_geo_normal(t):
    p0, p1, p2 = t["p"]
    return normalize(cross(sub(p1, p0), sub(p2, p0)))


def check_orientation(L, C, refs):
    """refs: mesh name -> (point, sense); sense +1 = face toward point (inward), -1 = away."""
    name = os.path.basename(L.path)
    for t in L.tris:
        g = tri_geo_normal(t)
        C.check(all(dot(g, n) > 0.9999 for n in t["n"]), "%s/%s: winding agrees with NORMAL" % (name, t["mesh"]))
        ref, sense = refs[t["mesh"]]
        c = centroid(t["p"])
        C.check(sense * dot(g, sub(ref, c)) > 0, "%s/%s: faces %s" % (name, t["mesh"], "in" if sense > 0 else "out"))


def edge_key(p):
    return tuple(round(c, 6) for c in p)


def check_closed(L, C, meshes, boundary_ok=lambda a, b: False, label="closed"):
    """Every directed edge must be matched by its reverse (watertight, consistent, no T-junction)."""
    name = os.path.basename(L.path)
    directed = {}
    for t in L.tris:
        if t["mesh"] not in meshes:
            continue
        ks = [edge_key(p) for p in t["p"]]
        for i in range(3):
            e = (ks[i], ks[(i + 1) % 3])
            directed[e] = directed.get(e, 0) + 1
    bad = [e for e, c in directed.items() if c != 1 or directed.get((e[1], e[0]), 0) != 1]
    unexpected = [e for e in bad if not (directed[e] == 1 and (e[1], e[0]) not in directed and boundary_ok(*e))]
    C.check(not unexpected, "%s: %s %s (%d bad edges, e.g. %s)" % (name, "+".join(sorted(meshes)), label,
                                                                 len(unexpected), unexpected[:2]))
    return len(bad) - len(unexpected)


def uv_charts(L):
    """Groups triangles into charts: connected through shared TEXCOORD_1 values."""
    parent = list(range(len(L.tris)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    owner = {}
    for ti, t in enumerate(L.tris):
        for u in t["uv"]:
            key = (t["mesh"], u)
            if key in owner:
                parent[find(ti)] = find(owner[key])
            else:
                owner[key] = ti
    groups = {}
    for ti in range(len(L.tris)):
        groups.setdefault(find(ti), []).append(ti)
    return list(groups.values())


def uv_area(t):
    (a, b, c) = t["uv"]
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def world_area(t):
    p0, p1, p2 = t["p"]
    return 0.5 * length(cross(sub(p1, p0), sub(p2, p0)))


def check_uv(L, C, expected_charts):
    name = os.path.basename(L.path)
    charts = uv_charts(L)
    C.check(len(charts) == expected_charts, "%s: %d UV charts, expected %d" % (name, len(charts), expected_charts))
    boxes = []
    for ch in charts:
        us = [u for ti in ch for u in L.tris[ti]["uv"]]
        lo = (min(u[0] for u in us), min(u[1] for u in us))
        hi = (max(u[0] for u in us), max(u[1] for u in us))
        boxes.append((lo, hi))
        C.check(min(lo) >= BORDER - 1e-6 and max(hi) <= 1 - BORDER + 1e-6, "%s: chart inside atlas border" % name)
        signs = {uv_area(L.tris[ti]) > 0 for ti in ch}
        C.check(len(signs) == 1 and all(abs(uv_area(L.tris[ti])) > 1e-9 for ti in ch),
                "%s: chart has one UV winding and no degenerate triangle" % name)
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            (al, ah), (bl, bh) = boxes[i], boxes[j]
            sep = max(bl[0] - ah[0], al[0] - bh[0], bl[1] - ah[1], al[1] - bh[1])
            C.check(sep >= GAP - 1e-6, "%s: charts %d and %d are %.4f apart (< GAP)" % (name, i, j, sep))
    # independent raster test: no sample point is covered twice
    R = 512
    jitter = 0.5 + 1.0 / 7919.0
    cover = bytearray(R * R)
    double = 0
    for t in L.tris:
        (a, b, c) = t["uv"]
        if uv_area(t) < 0:
            b, c = c, b
        x0 = max(0, int(math.floor(min(a[0], b[0], c[0]) * R)))
        x1 = min(R - 1, int(math.ceil(max(a[0], b[0], c[0]) * R)))
        y0 = max(0, int(math.floor(min(a[1], b[1], c[1]) * R)))
        y1 = min(R - 1, int(math.ceil(max(a[1], b[1], c[1]) * R)))
        for y in range(y0, y1 + 1):
            py = (y + jitter) / R
            for x in range(x0, x1 + 1):
                px = (x + jitter) / R
                e0 = (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])
                e1 = (c[0] - b[0]) * (py - b[1]) - (c[1] - b[1]) * (px - b[0])
                e2 = (a[0] - c[0]) * (py - c[1]) - (a[1] - c[1]) * (px - c[0])
                if e0 > 0 and e1 > 0 and e2 > 0:
                    if cover[y * R + x]:
                        double += 1
                    cover[y * R + x] = 1
    C.check(double == 0, "%s: %d doubly covered UV samples" % (name, double))
    used = sum(abs(uv_area(t)) for t in L.tris)
    return charts, boxes, used


def chart_boundary_distance(L, uv):
    """UV distance from uv to the boundary of the chart that contains it."""
    best = None
    for ch in uv_charts(L):
        edges = {}
        for ti in ch:
            u = L.tris[ti]["uv"]
            for i in range(3):
                a, b = u[i], u[(i + 1) % 3]
                edges[(min(a, b), max(a, b))] = edges.get((min(a, b), max(a, b)), 0) + 1
        inside = False
        for ti in ch:
            t = L.tris[ti]
            a, b, c = t["uv"]
            if uv_area(t) < 0:
                b, c = c, b
            if all((q[0] - p[0]) * (uv[1] - p[1]) - (q[1] - p[1]) * (uv[0] - p[0]) >= -1e-12
                   for p, q in ((a, b), (b, c), (c, a))):
                inside = True
        if not inside:
            continue
        for (a, b), k in edges.items():
            if k != 1:
                continue
            d = (b[0] - a[0], b[1] - a[1])
            s = max(0.0, min(1.0, ((uv[0] - a[0]) * d[0] + (uv[1] - a[1]) * d[1]) / (d[0] ** 2 + d[1] ** 2)))
            dist = math.hypot(uv[0] - a[0] - s * d[0], uv[1] - a[1] - s * d[1])
            best = dist if best is None else min(best, dist)
    return best


def probe_uv(L, mesh, point, normal):
    """TEXCOORD_1 at a world point on a mesh (barycentric interpolation of the stored data)."""
    for t in L.tris:
        if t["mesh"] != mesh or dot(tri_geo_normal(t), normal) < 0.999:
            continue
        p0, p1, p2 = t["p"]
        n = cross(sub(p1, p0), sub(p2, p0))
        if abs(dot(normalize(n), sub(point, p0))) > 1e-5:
            continue
        nn = dot(n, n)
        w0 = dot(cross(sub(p2, p1), sub(point, p1)), n) / nn
        w1 = dot(cross(sub(p0, p2), sub(point, p2)), n) / nn
        w2 = 1 - w0 - w1
        if min(w0, w1, w2) >= -1e-9:
            uv = tuple(w0 * t["uv"][0][i] + w1 * t["uv"][1][i] + w2 * t["uv"][2][i] for i in range(2))
            return [round(uv[0], 6), round(uv[1], 6)]
    raise SystemExit("probe %r not on mesh %s" % (point, mesh))


def segment_hits_triangle(o, d, tri):
    """Möller-Trumbore: does o + s*d, s in (1e-6, 1-1e-6), hit triangle tri?"""
    p0, p1, p2 = tri
    e1, e2 = sub(p1, p0), sub(p2, p0)
    h = cross(d, e2)
    a = dot(e1, h)
    if abs(a) < 1e-15:
        return False
    f = 1.0 / a
    s = sub(o, p0)
    u = f * dot(s, h)
    if u < 0 or u > 1:
        return False
    q = cross(s, e1)
    v = f * dot(d, q)
    if v < 0 or u + v > 1:
        return False
    tt = f * dot(e2, q)
    return 1e-6 < tt < 1 - 1e-6  # float32 vertices: start and end points lie on surfaces


def assert_unoccluded(L, x, poly, skip_meshes, C, what, n=24):
    blockers = [t["p"] for t in L.tris if t["mesh"] not in skip_meshes]
    a, b, c, d = poly
    hit = 0
    for i in range(n):
        for j in range(n):
            s, t = (i + 0.5) / n, (j + 0.5) / n
            p = add(mul(add(mul(a, 1 - s), mul(b, s)), 1 - t), mul(add(mul(d, 1 - s), mul(c, s)), t))
            if any(segment_hits_triangle(x, sub(p, x), tri) for tri in blockers):
                hit += 1
    C.check(hit == 0, "%s: %d of %d sight lines to the emitter blocked" % (what, hit, n * n))


# ----------------------------------------------------------------------------
# assets/README.md


def write_readme(assets, report, probes):
    P = probes["scenes"]

    def layout(stem):
        r = report[stem]
        return ("%d triangles, %d TEXCOORD_1 chart%s; density %.4f UV/m (%.1f texels/m at 64x64, %.1f at 256x256), "
                "%.0f%% of the atlas covered" % (r["triangles"], r["charts"], "s" if r["charts"] > 1 else "", r["density"], 64 * r["density"],
                                                 256 * r["density"], 100 * r["uv_used"]))

    def uv(stem, name):
        return "uv1 (%.6f, %.6f)" % tuple(next(q for q in P[stem]["probes"] if q["name"] == name)["uv1"])

    cb = P["cornell_box"]["probes"][0]
    ob = {q["name"]: q for q in P["open_box"]["probes"]}
    tr = P["two_rooms"]
    trd = P["two_rooms_doorway"]
    lines = []
    w = lines.append
    w("# assets")
    w("")
    w("Small scenes for bundlebake's tests and benchmarks. This file, the generated scenes and `probes.json` "
      "are written by `python3 scripts/make_assets.py` (standard library only; the \"Shared scenes\" section "
      "is fixed text in it): edit the script, not the output. The script re-reads every file it writes and checks it: "
      "glTF structure (accessor bounds, 4-byte alignment, POSITION min/max), winding against NORMAL, that every "
      "face faces the room it belongs to (enclosures inward, blocks outward), that enclosures are watertight "
      "(every edge shared by exactly two triangles in opposite directions: no hole, no T-junction), that no two "
      "TEXCOORD_1 charts overlap or come closer than the gap, and the analytic numbers below. All files also pass "
      "the Khronos glTF validator (2.0.0-dev.3.10) with 0 errors and 0 warnings (its only infos: TEXCOORD_0/1 "
      "unused by any texture).")
    w("")
    w("## Conventions of the generated scenes")
    w("- Units: metres, Y up, glTF 2.0 `.gltf` + external `.bin`. Emitted radiance Le = `emissiveFactor` x "
      "`KHR_materials_emissive_strength` (declared in `extensionsUsed` where an emission exceeds 1). Every "
      "material has `metallicFactor` 0, `roughnessFactor` 1 and `doubleSided` false: faces are single-sided and "
      "their normals face the inside of each room.")
    w("- Lightmap values are L_lm = E/pi (DESIGN.md, Units): a Lambertian surface of albedo rho leaves radiance "
      "Le + rho * L_lm. \"k iterations\" below means the baker's k-th light-map iteration (k = 1: direct light "
      "only). In a closed enclosure of uniform albedo the area mean of L_lm after k iterations is "
      "L_inf * (1 - rho^k), exactly (flux balance); in the furnace this holds at every texel.")
    w("- TEXCOORD_1 is one shared atlas per scene (`--uv-layout asset`): every planar face is its own chart, "
      "projected onto its plane at one scene-wide density (a per-face weight only for the open box floor), "
      "packed by a skyline packer at the largest density that fits. Charts are at least %.3f UV apart (%.2f "
      "texels at 64x64) and %.4f UV from the atlas edge. A chart thinner than 2 texels at 64x64 (the "
      "2 cm doorway faces) is stretched along its thin axis only. Each mesh's TEXCOORD_1 therefore covers only "
      "its own charts of the atlas: a `pack` layout that rescales a mesh's [0,1] UV square into a page rectangle "
      "wastes the rest of that square." % (GAP, GAP * 64, BORDER))
    w("- TEXCOORD_0 (required by the glTF spec when TEXCOORD_1 is present) is planar, 1 unit per metre.")
    w("- `probes.json` gives, per scene, world points with their normal, their TEXCOORD_1 (`uv1`, glTF "
      "convention, no flip), and the expected L_lm; every probe lies at least 1.5 texels (at 64x64) inside its "
      "chart. Area means are over world area: weight each texel by the world area it covers.")
    w("- Licence of the generated files: that of the bundlebake repository (they are made from scratch by the "
      "script), except for the third-party data named in the Cornell box entry.")
    w("")
    w("## Generated scenes")
    w("")
    w("**`cornell_box/cornell_box.gltf`**: the Cornell box built from the published Cornell Box Data "
      "(ANALYTIC_REFERENCES.md section 6), millimetres divided by 1000: floor, ceiling, back wall, red wall "
      "(x = 0.550 to 0.556), green wall (x = 0), the short and the tall block (4 sides and a top each, no bottom) and a "
      "0.130 x 0.105 m light quad at y = 0.5479, 0.9 mm below the whole ceiling, facing -Y; front open at z = 0. "
      "The published red wall is not quite planar, so its two triangles carry their own flat normals. "
      "Materials: white (0.725, 0.71, 0.68) for floor, ceiling, back wall and blocks; red (0.63, 0.065, 0.05); "
      "green (0.14, 0.45, 0.091); light albedo 0.78 with Le = (17, 12, 4) (`emissiveFactor` (1, 12/17, 4/17) x "
      "strength 17). Camera node from the published data: at (0.278, 0.273, -0.8) looking +Z (node rotated "
      "180 deg about Y), yfov = 2 atan(0.0125/0.035) = %.6f rad, aspect 1. %s. Analytic answer: none for the full "
      "solution (use it for relative checks: colour bleeding, shadow shapes); direct light only (1 iteration, "
      "no sky: the front is open) at the back-wall centre (0.278, 0.2744, 0.5592), normal -Z, %s, which sees the whole light (checked by ray "
      "casting): form factor %.9f by Lambert's formula, so L_lm = (%.6f, %.6f, %.6f). Ceiling texels above the "
      "light see its back at 0.9 mm and are dark. Source: Cornell University Program of Computer Graphics, "
      "\"Cornell Box Data\", https://www.graphics.cornell.edu/online/box/data.html (published data; no licence is "
      "attached to it here: cite the page). The RGB albedos and the radiance (17, 12, 4) are the values widely used in renderer "
      "test scenes, not the measured spectra (see `shared/cornell_box/cornell_spectral_reflectance.csv`)."
      % (2 * math.atan(0.0125 / 0.035), layout("cornell_box"), uv("cornell_box", "back_wall_centre"),
         cb["form_factor_to_light"], cb["L_lm"][0], cb["L_lm"][1], cb["L_lm"][2]))
    w("")
    w("**`furnace/furnace.gltf`, `furnace/furnace_rho09.gltf`** (one shared `furnace.bin`): a closed 1 m cube "
      "(x, z in [-0.5, 0.5], y in [0, 1]), 6 inward walls of 2 triangles, with a 0.3 m cube floating at its centre "
      "(y in [0.35, 0.65], 6 outward faces). One material everywhere: Le = 1 (`emissiveFactor` (1, 1, 1)), albedo "
      "rho = 0.5 (`furnace.gltf`) or 0.9 (`furnace_rho09.gltf`). %s. Analytic answer (ANALYTIC_REFERENCES 1.1): "
      "L_lm = Le / (1 - rho) = 2 (rho 0.5) or 10 (rho 0.9) at every texel, occluded or not (the floor under the "
      "inner cube included); after k iterations Le (1 - rho^k) / (1 - rho), e.g. 1, 1.5, 1.75 for rho 0.5 and "
      "1, 1.9, 2.71 for rho 0.9. The box is closed, so any sky is irrelevant. Source: generated." % layout("furnace"))
    w("")
    w("**`sky_plane/sky_plane.gltf`**: one upward-facing 10 m x 10 m square at y = 0 (x, z in [-5, 5]), "
      "single-sided, albedo 0.5, no emission. %s. Analytic answer: under a uniform sky of radiance S, "
      "L_lm = S at every texel, for any number of iterations (outgoing radiance 0.5 S); probes at the centre "
      "%s and near a corner. Source: generated." % (layout("sky_plane"), uv("sky_plane", "centre")))
    w("")
    w("**`two_rooms/two_rooms.gltf`**: two sealed 2 m x 2 m x 2 m rooms side by side, A at x in [-2.01, -0.01] "
      "and B at x in [0.01, 2.01] (y in [0, 2], z in [-1, 1]), separated by a solid 0.02 m slab (x in "
      "[-0.01, 0.01]) that has one face in each room. Every face is inward; each room is watertight. A has a "
      "0.5 m x 0.5 m emitting panel flush in its ceiling (x in [-1.26, -0.76], z in [-0.25, 0.25], facing -Y, "
      "Le = 10: `emissiveFactor` (1, 1, 1) x strength 10; the rest of A's ceiling is a frame around it, without "
      "T-junctions); B has no emitter. Albedo 0.5 everywhere. %s. Analytic answers: room B is exactly 0 at every "
      "texel, for any iteration count and any sky (light leaking through the 2 cm slab is the failure this tests; "
      "probes on B's floor, B's ceiling and B's side of the slab). Room A: the area mean of L_lm over its %g m^2 "
      "(panel included) is Le A_panel / (A (1 - rho)) = %.9f after all bounces, times (1 - 0.5^k) after k "
      "iterations (exact: flux balance of a closed enclosure, ANALYTIC_REFERENCES 4); direct light at the floor "
      "point under the panel centre (-1.01, 0, 0), %s: form factor %.9f, L_lm = %.9f (1 iteration). "
      "Source: generated."
      % (layout("two_rooms"), tr["room_a_area_mean_L_lm"]["area_m2"], tr["room_a_area_mean_L_lm"]["all_bounces"],
         uv("two_rooms", "room_a_floor_under_panel"), tr["probes"][0]["form_factor_to_panel"],
         tr["probes"][0]["L_lm"][0]))
    w("")
    w("**`two_rooms/two_rooms_doorway.gltf`**: the same two rooms with a doorway 0.4 m wide and 1.0 m high "
      "(z in [-0.2, 0.2], y in [0, 1]) through the slab, with its two jambs, the lintel's underside and the "
      "threshold as faces; the floors keep vertices at the doorway edges, so the whole is one watertight "
      "enclosure. %s. Room B is lit only through the doorway: the slow, leak-prone case for benchmarks, with no "
      "pointwise closed form. Analytic answers: the area mean of L_lm over the whole enclosure (%.3f m^2) is "
      "%.9f after all bounces, times (1 - 0.5^k) after k iterations; the direct value under the panel is as in "
      "`two_rooms.gltf` (%s). Source: generated."
      % (layout("two_rooms_doorway"), trd["enclosure_area_mean_L_lm"]["area_m2"],
         trd["enclosure_area_mean_L_lm"]["all_bounces"], uv("two_rooms_doorway", "room_a_floor_under_panel")))
    w("")
    w("**`open_box/open_box.gltf`**: ANALYTIC_REFERENCES 1.3, an open-top unit cube: floor x, z in [-0.5, 0.5] at "
      "y = 0 and four walls 1 m high, all inward, no top; albedo 0 (black), no emission. The floor chart has twice "
      "the walls' linear texel density (it is the surface tests read). %s. Analytic answers under a uniform sky "
      "L_env (exact after one iteration; black surfaces reflect nothing): L_lm = L_env V with V the sky view "
      "factor through the opening (Lambert's formula): floor centre V = %.12f (%s), floor point (x, z) = "
      "(0.25, 0.1) V = %.12f (%s), and (derived here, not in ANALYTIC_REFERENCES) the centre of the x = -0.5 wall, "
      "(-0.5, 0.5, 0), V = %.12f (%s). Source: generated."
      % (layout("open_box"), ob["floor_centre"]["sky_view_factor"], uv("open_box", "floor_centre"),
         ob["floor_0.25_0.1"]["sky_view_factor"], uv("open_box", "floor_0.25_0.1"),
         ob["wall_xmin_centre"]["sky_view_factor"], uv("open_box", "wall_xmin_centre")))
    w("")
    w("**`street_canyon/street_canyon.gltf`**: a street 6 m wide (x in [-3, 3], z in [-6, 6], black) between two "
      "walls 10 m high (albedo 0.6, facing the street), each with a window band from y = 4 to 5.5 m recessed 0.35 m "
      "(sill facing +Y, recessed wall, lintel facing -Y); open above and at both ends. %s: at the `bench/"
      "speed_vs_error.py` street canyon's 32x32 (--uv-layout asset) the sills and lintels are strips under half a "
      "texel across, as the generated city's ledges and sills. No closed form: the bench measures it against a "
      "converged `bundlebake reference` under a uniform sky, the noise estimate tests against its seed-to-seed "
      "noise and against that reference, kept in `street_canyon/reference_asset32/` (written by `bundlebake "
      "reference --uv-layout asset --resolution 32 --sky 1,1,1 --spp 131072 --seed 7777`, not by this script; its "
      "own noise 0.10 %% of the map's mean). Source: generated." % layout("street_canyon"))
    w("")
    w(SHARED_SECTION)
    with open(os.path.join(assets, "README.md"), "w") as fh:
        fh.write("\n".join(lines))


SHARED_SECTION = """## Shared scenes (`shared/`, copied unchanged)

Third-party scenes copied byte for byte from the project's `shared/scenes/` (which took them unchanged from
their public repositories). Each folder keeps its own README.md with source, licence and attribution, and notes
for bakers; keep it with the files. Units: metres, except the Cornell box (millimetres).

| folder | files | triangles | TEXCOORD_1 | licence |
|---|---|---|---|---|
| `shared/cornell_box/` | `CornellBox.glb`, `cornell_spectral_reflectance.csv`, `README.md` | 36 | yes (one unwrap per mesh) | glb: MIT OR Apache-2.0 (Bevy contributors); CSV: measured data published by the Cornell University Program of Computer Graphics (cite the page) |
| `shared/mixed_lighting/` | `MixedLightingExample.gltf` + `.bin`, 8 `SheenChair*.jpg`, `README.md` | 40,898 | yes (one unwrap per mesh) | MIT OR Apache-2.0 (Bevy contributors); the SheenChair model CC0-1.0 (Wayfair, Khronos glTF sample) |
| `shared/living_room/` | `living_room.glb`, `README.md` | 5,088 (3,537 zero-area) | no | MIT (Godot Engine contributors, godot-demo-projects) |
| `shared/zdm2/` | `zdm2.glb`, `README.md` | 58,772 | no (and no materials) | **CC BY 4.0, attribution required** (see below) |

- `shared/cornell_box/`: the Bevy lightmaps (`lightmaps_bevy/`, 1.26 MB, qualitative only) are not copied;
  its README still describes them. The glb is in millimetres, rotated 180 deg about Y from the published
  coordinates, with albedos that are not Cornell's.
- `shared/zdm2/`: attribution to keep with any use or redistribution: "zdm2" map from Cube 2: Sauerbraten
  (credits: I.g(, Suicizer, Chaseter and the map author), OBJ export by Hugo Locurcio (game-maps-obj), glTF
  conversion by the Godot demo projects; CC BY 4.0 (https://creativecommons.org/licenses/by/4.0/). Changes:
  none (file copied unchanged).
- The living room and zdm2 have no TEXCOORD_1 (use `--uv-layout pack` with generated UVs); the Cornell box and
  mixed-lighting scenes have one unwrap per mesh that overlap each other in UV1, so they also need `pack`, not
  `asset`.
"""


# ----------------------------------------------------------------------------
# main


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    assets = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "assets"))
    C = Checker()
    report = {}
    probes = {"_about": ("Analytic answers at points of the generated scenes. L_lm = E/pi (DESIGN.md Units). "
                         "uv1 is TEXCOORD_1 in the scene's one atlas (--uv-layout asset), glTF convention "
                         "(origin at the image's top-left, v down). 'iterations' k: the baker's k-th light-map "
                         "iteration (k=1: direct light only). Generated by scripts/make_assets.py."),
              "scenes": {}}

    # reference values from ANALYTIC_REFERENCES.md, re-derived here
    C.check(abs(corner_form_factor(1, 1, 1) - 0.138531605995) < 1e-11, "form factor 3(a) worked value")
    sq = [(-0.5, 1.0, -0.5), (0.5, 1.0, -0.5), (0.5, 1.0, 0.5), (-0.5, 1.0, 0.5)]
    v_centre = lambert_form_factor((0, 0, 0), (0, 1, 0), sq)
    v_off = lambert_form_factor((0.25, 0, 0.1), (0, 1, 0), sq)
    v_wall = lambert_form_factor((-0.5, 0.5, 0.0), (1, 0, 0), sq)
    C.check(abs(v_centre - 0.239456470461) < 1e-11 and abs(4 * corner_form_factor(0.5, 0.5, 1) - v_centre) < 1e-12,
            "open box: floor centre sky view factor")
    C.check(abs(v_off - 0.220473362652) < 1e-11, "open box: floor (0.25, 0.1) sky view factor")

    def emit(scene, folder, stem, bin_stem=None):
        path = write_scene(scene, os.path.join(assets, folder), stem, bin_stem)
        L = Loaded(path)
        check_structure(L, C)
        charts, boxes, used = check_uv(L, C, len(scene.faces))
        report[stem] = {"path": os.path.relpath(path, assets), "triangles": len(L.tris), "charts": len(charts),
                        "density": scene.density, "uv_used": used,
                        "materials": [m["name"] for m in scene.materials], "scene": scene, "loaded": L}
        return L

    # 1. Cornell box -----------------------------------------------------------
    cb = cornell_box()
    L = emit(cb, "cornell_box", "cornell_box")
    room_c = mm((278.0, 274.4, 279.6))
    refs = {m: (room_c, 1) for m in ("floor", "ceiling", "back_wall", "red_wall", "green_wall", "light")}
    refs["short_block"] = (mm((185.5, 82.5, 169.0)), -1)
    refs["tall_block"] = (mm((368.5, 165.0, 351.25)), -1)
    check_orientation(L, C, refs)
    shell = {"floor", "ceiling", "back_wall", "red_wall", "green_wall"}
    n_open = check_closed(L, C, shell, lambda a, b: a[2] == 0 and b[2] == 0, "closed except the open front z=0")
    C.check(n_open == 4, "cornell shell: 4 boundary edges at the open front (got %d)" % n_open)
    for blk in ("short_block", "tall_block"):
        nb = check_closed(L, C, {blk}, lambda a, b: a[1] == 0 and b[1] == 0, "closed except the bottom y=0")
        C.check(nb == 4, "%s: 4 open bottom edges" % blk)
    x_back = mm((278.0, 274.4, 559.2))
    light_poly = [mm(p) for p in [(343, 547.9, 227), (343, 547.9, 332), (213, 547.9, 332), (213, 547.9, 227)]]
    assert_unoccluded(L, x_back, light_poly, {"light"}, C, "cornell back-wall centre")
    F_back = lambert_form_factor(x_back, (0, 0, -1), light_poly)
    probes["scenes"]["cornell_box"] = {
        "file": "cornell_box/cornell_box.gltf",
        "probes": [{"name": "back_wall_centre", "mesh": "back_wall", "point": list(x_back), "normal": [0, 0, -1],
                    "uv1": probe_uv(L, "back_wall", x_back, (0, 0, -1)), "form_factor_to_light": round(F_back, 9),
                    "iterations": 1, "sky": 0,
                    "L_lm": [round(17 * F_back, 9), round(12 * F_back, 9), round(4 * F_back, 9)],
                    "note": "direct light only (first iteration); unoccluded (checked by ray casting)"}]}
    report["cornell_box"]["F_back"] = F_back

    # 2. furnace ---------------------------------------------------------------
    for rho, stem in ((0.5, "furnace"), (0.9, "furnace_rho09")):
        sc = furnace(rho)
        L = emit(sc, "furnace", stem, bin_stem="furnace")
        check_orientation(L, C, {"outer_box": ((0, 0.5, 0), 1), "inner_box": ((0, 0.5, 0), -1)})
        check_closed(L, C, {"outer_box"})
        check_closed(L, C, {"inner_box"})
        answer = 1.0 / (1.0 - rho)
        pts = [("outer_floor_centre", "outer_box", (0, 0, 0), (0, 1, 0)),
               ("outer_floor_corner", "outer_box", (0.4, 0, -0.4), (0, 1, 0)),
               ("outer_wall_xmin_centre", "outer_box", (-0.5, 0.5, 0), (1, 0, 0)),
               ("inner_top_centre", "inner_box", (0, 0.65, 0), (0, 1, 0)),
               ("inner_bottom_centre", "inner_box", (0, 0.35, 0), (0, -1, 0))]
        probes["scenes"][stem] = {
            "file": "furnace/%s.gltf" % stem, "rho": rho, "Le": 1.0,
            "L_lm_all_bounces": round(answer, 9),
            "L_lm_after_k_iterations": "Le * (1 - rho^k) / (1 - rho)",
            "probes": [{"name": nm, "mesh": me, "point": list(p), "normal": list(n),
                        "uv1": probe_uv(L, me, p, n), "L_lm": [round(answer, 9)] * 3} for (nm, me, p, n) in pts],
            "note": "the answer holds at every texel, whatever the occlusion; closed, so any sky is irrelevant"}

    # 3. sky plane -------------------------------------------------------------
    L = emit(sky_plane(), "sky_plane", "sky_plane")
    check_orientation(L, C, {"plane": ((0, 1, 0), 1)})
    probes["scenes"]["sky_plane"] = {
        "file": "sky_plane/sky_plane.gltf",
        "probes": [{"name": nm, "mesh": "plane", "point": list(p), "normal": [0, 1, 0],
                    "uv1": probe_uv(L, "plane", p, (0, 1, 0)), "L_lm": "S (the sky radiance, per channel)"}
                   for nm, p in (("centre", (0, 0, 0)), ("near_corner", (4.5, 0, -4.5)))],
        "note": "L_lm = S at every texel, any iteration count; outgoing radiance 0.5 S"}

    # 4. two rooms --------------------------------------------------------------
    room_a = (-1.01, 1.0, 0.0)
    room_b = (1.01, 1.0, 0.0)
    px0, px1, pz0, pz1 = TR["panel"]
    panel_poly = [(px0, 2.0, pz0), (px1, 2.0, pz0), (px1, 2.0, pz1), (px0, 2.0, pz1)]
    x_under = (-1.01, 0.0, 0.0)
    F_under = lambert_form_factor(x_under, (0, 1, 0), panel_poly)
    C.check(abs(F_under - 4 * corner_form_factor(0.25, 0.25, 2.0)) < 1e-12, "two rooms: panel form factor")
    area_a = 6 * 4.0
    for doorway, stem in ((False, "two_rooms"), (True, "two_rooms_doorway")):
        L = emit(two_rooms(doorway), "two_rooms", stem)
        refs = {"room_a": (room_a, 1), "room_a_panel": (room_a, 1), "room_b": (room_b, 1),
                "doorway": ((0.0, 0.5, 0.0), 1)}
        check_orientation(L, C, refs)
        if doorway:
            check_closed(L, C, {"room_a", "room_a_panel", "room_b", "doorway"})
        else:
            check_closed(L, C, {"room_a", "room_a_panel"})
            check_closed(L, C, {"room_b"})
        assert_unoccluded(L, x_under, panel_poly, {"room_a_panel"}, C, stem + " floor under panel")
        area_total = sum(f.area() for f in report[stem]["scene"].faces)
        pr = [{"name": "room_a_floor_under_panel", "mesh": "room_a", "point": list(x_under), "normal": [0, 1, 0],
               "uv1": probe_uv(L, "room_a", x_under, (0, 1, 0)), "form_factor_to_panel": round(F_under, 9),
               "iterations": 1, "L_lm": [round(10 * F_under, 9)] * 3, "note": "direct light only"}]
        entry = {"file": "two_rooms/%s.gltf" % stem, "rho": 0.5, "panel_Le": 10.0, "panel_area": 0.25}
        if not doorway:
            for nm, p, n in (("room_b_floor_centre", (1.01, 0.0, 0.0), (0, 1, 0)),
                             ("room_b_divider_centre", (0.01, 1.0, 0.0), (1, 0, 0)),
                             ("room_b_divider_low", (0.01, 0.3, 0.5), (1, 0, 0)),
                             ("room_b_ceiling_centre", (1.01, 2.0, 0.0), (0, -1, 0))):
                pr.append({"name": nm, "mesh": "room_b", "point": list(p), "normal": list(n),
                           "uv1": probe_uv(L, "room_b", p, n), "L_lm": [0.0, 0.0, 0.0],
                           "note": "sealed room: exactly 0 for any iteration count and any sky"})
            C.check(abs(area_total - 48.0) < 1e-6, "two_rooms: total area 48")
            entry["room_a_area_mean_L_lm"] = {"all_bounces": round(10 * 0.25 / (area_a * 0.5), 12),
                                              "after_k_iterations": "all_bounces * (1 - rho^k)",
                                              "area_m2": area_a}
            entry["room_b_L_lm"] = 0.0
        else:
            entry["enclosure_area_mean_L_lm"] = {"all_bounces": round(10 * 0.25 / (area_total * 0.5), 12),
                                                 "after_k_iterations": "all_bounces * (1 - rho^k)",
                                                 "area_m2": round(area_total, 9)}
        entry["probes"] = pr
        entry["note"] = ("area means are over world area (weight each texel by the world area it covers), "
                         "emitter texels included; exact for a closed enclosure (ANALYTIC_REFERENCES 4)")
        probes["scenes"][stem] = entry
        report[stem]["area"] = area_total

    # 5. open box ---------------------------------------------------------------
    L = emit(open_box(), "open_box", "open_box")
    check_orientation(L, C, {"floor": ((0, 0.5, 0), 1), "walls": ((0, 0.5, 0), 1)})
    nb = check_closed(L, C, {"floor", "walls"}, lambda a, b: a[1] == 1 and b[1] == 1, "closed except the top rim")
    C.check(nb == 4, "open box: 4 rim edges open")
    pr = []
    for nm, me, p, n, v in (("floor_centre", "floor", (0, 0, 0), (0, 1, 0), v_centre),
                            ("floor_0.25_0.1", "floor", (0.25, 0, 0.1), (0, 1, 0), v_off),
                            ("wall_xmin_centre", "walls", (-0.5, 0.5, 0), (1, 0, 0), v_wall)):
        pr.append({"name": nm, "mesh": me, "point": list(p), "normal": list(n), "uv1": probe_uv(L, me, p, n),
                   "sky_view_factor": round(v, 12), "L_lm": "%.12f * L_env" % v})
    probes["scenes"]["open_box"] = {"file": "open_box/open_box.gltf", "rho": 0.0, "probes": pr,
                                    "note": "black surfaces: one iteration is already exact"}
    report["open_box"]["v"] = (v_centre, v_off, v_wall)

    # 6. street canyon ----------------------------------------------------------
    L = emit(street_canyon(), "street_canyon", "street_canyon")
    check_orientation(L, C, {m: ((0.0, 5.0, 0.0), 1) for m, _, _ in report["street_canyon"]["scene"].meshes})

    for sname, entry in probes["scenes"].items():
        Lp = report[sname]["loaded"]
        for pr in entry["probes"]:
            d = chart_boundary_distance(Lp, tuple(pr["uv1"]))
            C.check(d is not None and d * 64 >= 1.5, "%s probe %s: %s texels (at 64) from its chart's edge"
                    % (sname, pr["name"], None if d is None else round(d * 64, 2)))
    with open(os.path.join(assets, "probes.json"), "w") as fh:
        json.dump(probes, fh, indent=1)
        fh.write("\n")

    write_readme(assets, report, probes)

    # summary
    for stem, r in report.items():
        sc = r["scene"]
        dens = sorted({round(min(f.density), 4) for f in sc.faces})
        print("%-20s %3d triangles %2d charts  S=%.4f UV/m (%.1f texels/m at 64, %.1f at 256)  UV used %.1f%%  "
              "materials %s  chart densities %s" % (stem, r["triangles"], r["charts"], r["density"], r["density"] * 64,
                                                    r["density"] * 256, 100 * r["uv_used"], ",".join(r["materials"]),
                                                    dens))
    print("open box sky view factors: centre %.12f, (0.25,0.1) %.12f, wall centre %.12f" % report["open_box"]["v"])
    print("cornell back-wall centre form factor to light %.9f" % report["cornell_box"]["F_back"])
    print("two_rooms: F(floor under panel) = %.9f; doorway enclosure area %.6f" %
          (F_under, report["two_rooms_doorway"]["area"]))
    print("%d checks, %d failed" % (C.count, len(C.failures)))
    return 1 if C.failures else 0


if __name__ == "__main__":
    sys.exit(main())
