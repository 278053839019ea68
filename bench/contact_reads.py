#!/usr/bin/python3
"""The Cornell box's block feet: how well the bundle pass's radiance reads
(append.frag radianceAt, read_modes.comp) give the floor's light that a block
face's bottom texels see, in a CPU model of the reads.

    bundlebake reference assets/cornell_box/cornell_box.gltf --uv-layout asset \\
        --resolution 512 --spp 1024 -o out/ref512
    bench/contact_reads.py out/ref512

The 512² reference is the floor's true light; its 4 × 4, 8 × 8 blocks are the
texel means a bake at supersample 2 / 1 (64 × s texels) holds (4 × 4: 2 × 2 of
supersample 4). For points on each face of the tall block 2-14 mm above the
floor, the floor's light they gather (cosine-weighted over the floor in front
of the face) is integrated once with the true light and once with each read:
  mean     the texel's mean
  bake     the bake's reads: a step or a limited slope per axis from the
           neighbours, kept within their range (no in-texel slopes: the floor
           texels here have all four neighbours on their chart)
  visible  the mean over the texel's part outside the block (its share known
           here from the geometry), the neighbours wholly under the block
           left out as a chart's edge is, then the same steps and slopes
Prints the relative error of each per face (A, B: the faces the light stands
over; C, D: their floor in the block's shadow). The model's own offset (the
512² texels' means against the light at a point) is about +1 %: the bake's
reads at supersample 4 read +0.8-1.3 % in it.
"""
import sys

import numpy as np

from texel_classes import load

# the floor's chart in the 64² asset layout: texel u = 22.77 + 34.72 z, v = 1.12 + 34.70 (0.553 - x), metres
def floor_point(u_texels, v_texels):
    """The floor point (x, z) at light-map position (u, v) in texels."""
    return 0.553 - (v_texels - 1.12) / 34.70, (u_texels - 22.77) / 34.72


TALL_BLOCK = np.array([(0.423, 0.247), (0.265, 0.296), (0.314, 0.456), (0.472, 0.406)])
FACES = {"A": (1, 2), "B": (0, 1), "C": (2, 3), "D": (3, 0)}


def limited_slope(a, b):
    return np.where(a * b > 0, np.sign(a) * np.minimum(np.abs(a + b) / 2, 2 * np.minimum(np.abs(a), np.abs(b))), 0)


def axis_offset(mode, l, m, r, x):
    a, b = m - l, r - m
    inside = a * b > 0
    share = np.clip(a / np.where(inside, r - l, 1), 0, 1)
    step = np.where(inside, np.where(x > 0.5 - share, r, l) - m, 0)
    return np.where(mode == 2, step, np.where(mode == 1, limited_slope(a, b) * x, 0))


def read_modes(means, gone, flatness=0.2):
    """READ_NONE 0 / SLOPE 1 / STEP 2 per texel and axis (read_modes.comp); a
    neighbour that is gone ends the chart there"""
    modes = np.zeros(means.shape + (2,), int)
    for axis in range(2):
        def at(a, d):
            return np.roll(a, -d, axis=1 - axis)
        l, r, l2, r2 = at(means, -1), at(means, 1), at(means, -2), at(means, 2)
        l2, r2 = np.where(at(gone, -2), l, l2), np.where(at(gone, 2), r, r2)
        step = ((means - l) * (r - means) > 0) & (np.maximum(np.abs(l - l2), np.abs(r2 - r)) <= flatness * np.abs(r - l))
        modes[..., axis] = np.where(at(gone, -1) | at(gone, 1), 0, np.where(step, 2, 1))
    return modes


def reads(means, gone, u, v, steps=True):
    n = means.shape[0]
    t = np.stack([u * n - 0.5, v * n - 0.5], -1)
    c = np.floor(t + 0.5).astype(int)
    f = t - c
    cx, cy = c[..., 0], c[..., 1]
    m = means[cy, cx]
    if not steps:
        return m
    modes = read_modes(means, gone)
    mx, my = modes[cy, cx, 0], modes[cy, cx, 1]
    sides = [(means[cy, cx - 1], gone[cy, cx - 1]), (means[cy, cx + 1], gone[cy, cx + 1]),
             (means[cy - 1, cx], gone[cy - 1, cx]), (means[cy + 1, cx], gone[cy + 1, cx])]
    lo, hi = m.copy(), m.copy()
    for value, g in sides:
        lo, hi = np.where(g, lo, np.minimum(lo, value)), np.where(g, hi, np.maximum(hi, value))
    (l, _), (r, _), (d, _), (up, _) = sides
    return np.clip(m + axis_offset(mx, l, m, r, f[..., 0]) + axis_offset(my, d, m, up, f[..., 1]), lo, hi)


def main():
    light = load(sys.argv[1] + "/lightmap_0.exr")[..., :3].sum(-1)
    fine = light.shape[0]
    ys, xs = np.mgrid[0:fine, 0:fine]
    u, v = (xs + 0.5) / fine, (ys + 0.5) / fine
    x, z = floor_point(u * 64, v * 64)
    centre = TALL_BLOCK.mean(axis=0)
    under = np.ones(light.shape, bool)
    for i in range(4):
        a, b = TALL_BLOCK[i], TALL_BLOCK[(i + 1) % 4]
        normal = np.array([b[1] - a[1], a[0] - b[0]])
        under &= ((x - a[0]) * normal[0] + (z - a[1]) * normal[1]) * ((centre - a) @ normal) > 0
    floor = (z > 0.01) & (z < 0.55) & (x > 0.01) & (x < 0.545) & ~under
    for supersample in (1, 2, 4):
        n = 64 * supersample
        k = fine // n
        means = light.reshape(n, k, n, k).mean(axis=(1, 3))
        visible_share = (~under).astype(float).reshape(n, k, n, k).mean(axis=(1, 3))
        gone = visible_share <= 0.02
        models = {"mean": reads(means, np.zeros_like(gone), u[floor], v[floor], steps=False),
                  "bake": reads(means, np.zeros_like(gone), u[floor], v[floor]),
                  "visible": reads(np.where(gone, 0, means / np.maximum(visible_share, 1e-9)), gone, u[floor], v[floor])}
        for name, read in models.items():
            seen = np.zeros_like(light)
            seen[floor] = read
            errors = []
            for face, (i, j) in FACES.items():
                a, b = TALL_BLOCK[i], TALL_BLOCK[j]
                normal = np.array([b[1] - a[1], a[0] - b[0]]) / np.linalg.norm(b - a)
                if (centre - a) @ normal > 0:
                    normal = -normal
                e = []
                for t in np.linspace(0.2, 0.8, 7):
                    q = a + t * (b - a)
                    for h in (0.002, 0.006, 0.010, 0.014):
                        dx, dz = x - q[0], z - q[1]
                        r2 = dx * dx + dz * dz + h * h
                        cos_face = (dx * normal[0] + dz * normal[1]) / np.sqrt(r2)
                        w = np.where(floor & (cos_face > 0), cos_face * h / np.sqrt(r2) / r2, 0)
                        e.append((w * seen).sum() / (w * light).sum() - 1)
                errors.append("%s %+.2f %%" % (face, 100 * np.mean(e)))
            print("supersample %d %-8s %s" % (supersample, name, "  ".join(errors)))


if __name__ == "__main__":
    main()
