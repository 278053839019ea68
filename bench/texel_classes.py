#!/usr/bin/env python3
"""Where a bake's error sits, by texel class: the texels of a bake directory
against a reference directory, classed by which of their four neighbours are
not covered in both ("-": all covered; "DU": a chart one texel across, no
neighbour up or down; "LDU": the end of such a strip; ...).

    bench/texel_classes.py BAKE REFERENCE [BAKE2]

Per class: texels, share of the squared error, rel_rmse and the mean error
relative to the class's reference mean (both over the whole map's reference
mean, as `bundlebake compare`). With a second bake of the same setting and
another seed, the mean of the product of the two errors is the squared bias
(noise cancels): per class the bias's rms instead, and the texels whose error
has the same sign in both and is largest. Reads the EXRs and coverage PNGs
through `oiiotool --dumpdata` (Debian openimageio-tools).
"""
import collections
import os
import re
import subprocess
import sys

import numpy as np


def load(path):
    out = subprocess.run(["oiiotool", "--dumpdata", path], capture_output=True, text=True, check=True).stdout.splitlines()
    m = re.search(r"(\d+) x\s+(\d+), (\d+) channel", out[0])
    w, h, c = int(m[1]), int(m[2]), int(m[3])
    a = np.zeros((h, w, c), np.float64)
    for line in out[1:]:
        mm = re.match(r"\s*Pixel \((\d+), (\d+)\): (.*)", line)
        if mm:
            a[int(mm[2]), int(mm[1])] = [float(v) for v in mm[3].split("(")[0].split()[:c]]
    return a


def pages(directory):
    p = 0
    while os.path.exists(f"{directory}/lightmap_{p}.exr"):
        p += 1
    return p


def texels(bakes, reference):
    """(page, x, y, class, [bake values], reference value) for texels covered in all."""
    rows = []
    for p in range(pages(reference)):
        ref = load(f"{reference}/lightmap_{p}.exr").mean(-1)
        values = [load(f"{b}/lightmap_{p}.exr").mean(-1) for b in bakes]
        cov = load(f"{reference}/coverage_{p}.png")[..., 0] > 0
        for b in bakes:
            cov &= load(f"{b}/coverage_{p}.png")[..., 0] > 0
        pad = np.pad(cov, 1)
        missing = {"L": ~pad[1:-1, :-2], "R": ~pad[1:-1, 2:], "D": ~pad[:-2, 1:-1], "U": ~pad[2:, 1:-1]}
        for y, x in zip(*np.nonzero(cov)):
            k = "".join(s for s in "LRDU" if missing[s][y, x]) or "-"
            rows.append((p, x, y, k, [v[y, x] for v in values], ref[y, x]))
    return rows


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    bakes = [sys.argv[1]] + sys.argv[3:]
    rows = texels(bakes, sys.argv[2])
    mean = np.mean([r[5] for r in rows])
    err = np.array([[v - r[5] for v in r[4]] for r in rows])
    square = err[:, 0] * err[:, 1] if len(bakes) == 2 else err[:, 0] ** 2
    print(f"{len(rows)} texels, rel_rmse {np.sqrt(np.mean(err[:, 0] ** 2)) / mean:.4f}", end="")
    if len(bakes) == 2:
        noise = np.sqrt(np.mean((err[:, 0] - err[:, 1]) ** 2) / 2) / mean
        print(f" (second bake {np.sqrt(np.mean(err[:, 1] ** 2)) / mean:.4f}); "
              f"bias {np.sqrt(max(np.mean(square), 0)) / mean:.4f}, noise {noise:.4f}", end="")
    print()
    classes = collections.defaultdict(list)
    for i, r in enumerate(rows):
        classes[r[3]].append(i)
    total = square.sum()
    what = "bias rms" if len(bakes) == 2 else "rel_rmse"
    for k, idx in sorted(classes.items(), key=lambda kv: -square[kv[1]].sum()):
        ref = sum(rows[i][5] for i in idx)
        print(f"{k:5s} {len(idx):6d} texels  share {square[idx].sum() / total:6.3f}  "
              f"{what} {np.sqrt(max(np.mean(square[idx]), 0)) / mean:.4f}  "
              f"mean error {err[idx, 0].sum() / ref:+.4f}  class mean {ref / len(idx) / mean:.3f}")
    if len(bakes) == 2:
        same = np.sign(err[:, 0]) == np.sign(err[:, 1])
        order = np.argsort(-np.minimum(np.abs(err[:, 0]), np.abs(err[:, 1])) * same)
        print("largest errors of one sign in both bakes: page x y class bake bake2 reference")
        for i in order[:20]:
            p, x, y, k, v, ref = rows[i]
            print(p, x, y, k, " ".join(f"{a:.4f}" for a in v), f"{ref:.4f}")


if __name__ == "__main__":
    main()
