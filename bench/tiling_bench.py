#!/usr/bin/python3
"""Adaptive against uniform ray-bundle tiling on generated cities
(scripts/generate_city.py, seed 1).

For each city size, three bakes under a uniform sky (same directions, seed,
layout and memory budget):
  adaptive       --tiling adaptive (the default): each leaf's pixel from the
                 importance of what it covers (half its densest texel);
  uniform-dense  --tiling uniform at the pixel the densest texels need (the
                 adaptive bake's finest pixel): the Hermes et al. 2010 grid with
                 the same leak protection everywhere;
  uniform-mean   --tiling uniform at its default pixel (half the mean texel).
Figures per bake, from stats.json: seconds per direction (seconds.total minus
setup, over the directions), fragments per direction, peak bundle memory (node
buffer + head image as allocated), peak GL memory, tiles, predicted/actual
nodes per tile, overflows, culled fractions, pass throughputs.

--error: on a tiny city with sparse terrain (0.1 texels/m) and dense
buildings (2 texels/m), each mode at 256 directions against a converged
`bundlebake reference` (cached in bench/cache/), relative RMSE over covered texels.
The last row: a city too wide for one uniform grid (the viewport limit), which
the adaptive tiling bakes.

Usage: bench/tiling_bench.py [--bundlebake PATH] [--sizes tiny,small,city]
                             [--directions N] [--error] [--wide]
Outputs: bench/results/tiling/results.json and table.md (printed too).
"""
import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "bench", "cache")
OUT = os.path.join(ROOT, "bench", "results", "tiling")
RESOLUTION = {"tiny": 512, "small": 2048, "city": 4096, "paper": 8192}
SKY = ["--sky", "1,1,1"]


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "exit %d" % p.returncode
    return None


def city(preset, extra=()):
    os.makedirs(CACHE, exist_ok=True)
    name = preset + ("_" + "_".join(extra).replace("-", "") if extra else "")
    path = os.path.join(CACHE, "city_%s.gltf" % name)
    if not os.path.exists(path):
        subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "generate_city.py"), "--preset", preset,
                        "--seed", "1", *extra, "-o", path], check=True, capture_output=True)
    return path


def bake(exe, scene, out, resolution, directions, extra):
    cmd = [exe, "bake", scene, "-o", out, "--resolution", str(resolution), "--directions", str(directions),
           "--no-preview", "--no-progress", *SKY, *extra]
    err = run(cmd)
    if err:
        return {"error": err}
    with open(os.path.join(out, "stats.json")) as f:
        s = json.load(f)
    sec = s["seconds"]
    n = s["directions"]["done"]
    t = s["tiles"]
    return {
        "seconds_per_direction": (sec["total"] - sec["setup"]) / n,
        "seconds_setup": sec["setup"],
        "fragments_per_direction": s["throughput"]["fragments"] / n,
        "bundle_bytes": s["memory"]["node_buffer_bytes"] + s["memory"]["head_image_bytes"],
        "peak_gpu_bytes": s["memory"]["peak_gpu_bytes"],
        "tiles_per_direction": t["per_direction_mean"],
        "leaves_per_direction": t.get("leaves_per_direction_mean", 1),
        "pixel_min": t["pixel_size_scene_units"]["min"],
        "pixel_median": t["pixel_size_scene_units"]["median"],
        "pixel_max": t["pixel_size_scene_units"]["max"],
        "pred_p10": t["predicted_over_actual_nodes"]["p10"],
        "pred_median": t["predicted_over_actual_nodes"]["median"],
        "pred_p90": t["predicted_over_actual_nodes"]["p90"],
        "overflows": t["overflows_redrawn"],
        "tiles": t["drawn"],
        "culled_bundle": s["culling"]["bundle_pass_triangles_drawn_fraction"],
        "bundle_mfps": s["throughput"]["fragments_per_second_bundle_pass"] / 1e6,
        "update_mtps": s["throughput"]["texel_samples_per_second_update_pass"] / 1e6,
        "uniform_grid": s["bundle"]["resolution_pixels"] * s["bundle"]["pixel_size_scene_units"],
        "triangles": s["culling"]["triangles"],
        "covered_texels": s["lightmap"]["covered_texels"],
    }


def modes(exe, scene, tag, resolution, directions):
    rows = {}
    rows["adaptive"] = bake(exe, scene, os.path.join(CACHE, tag + "_adaptive"), resolution, directions, [])
    a = rows["adaptive"]
    if "error" not in a:
        dense = int(math.ceil(a["uniform_grid"] / a["pixel_min"]))
        rows["uniform-dense"] = bake(exe, scene, os.path.join(CACHE, tag + "_uniform_dense"), resolution, directions,
                                     ["--tiling", "uniform", "--bundle-res", str(dense)])
        rows["uniform-dense"]["bundle_res"] = dense
    rows["uniform-mean"] = bake(exe, scene, os.path.join(CACHE, tag + "_uniform_mean"), resolution, directions,
                                ["--tiling", "uniform"])
    return rows


def mib(b):
    return "%.1f" % (b / 2**20)


def table(results):
    lines = ["| city | mode | s / direction | M fragments / direction | bundle MiB | peak GL MiB | tiles / dir | pixel min / median / max (m) | pred/actual p10 / median / p90 | overflows | bundle M frag/s | update M texel/s | error |",
             "|---|---|---:|---:|---:|---:|---:|---|---|---:|---:|---:|---:|"]
    for size, rows in results.items():
        for mode, r in rows.items():
            if "error" in r:
                lines.append("| %s | %s | fails: %s |||||||||||" % (size, mode, r["error"]))
                continue
            err = "%.2f %%" % (100 * r["rel_rmse"]) if "rel_rmse" in r else ""
            lines.append("| %s (%s tris, %s texels) | %s | %.2f | %.2f | %s | %s | %.1f | %.2f / %.2f / %.2f | %.2f / %.2f / %.2f | %d | %.1f | %.1f | %s |" % (
                size, "{:,}".format(r["triangles"]), "{:,}".format(r["covered_texels"]), mode,
                r["seconds_per_direction"], r["fragments_per_direction"] / 1e6, mib(r["bundle_bytes"]),
                mib(r["peak_gpu_bytes"]), r["tiles_per_direction"], r["pixel_min"], r["pixel_median"], r["pixel_max"],
                r["pred_p10"], r["pred_median"], r["pred_p90"], r["overflows"], r["bundle_mfps"], r["update_mtps"], err))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bundlebake", default=os.path.join(ROOT, "build", "bundlebake"))
    ap.add_argument("--sizes", default="tiny,small,city,small-sparse,city-sparse",
                    help="presets; -sparse: terrain at 0.1 texels/m, buildings at 1 (a typical terrain / building ratio)")
    ap.add_argument("--directions", type=int, default=8)
    ap.add_argument("--error", action="store_true", help="tiny city at 256 directions against a converged reference")
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--wide", action="store_true", help="a city wider than one uniform grid can be")
    args = ap.parse_args()
    exe = os.path.abspath(args.bundlebake)
    results = {}
    for size in args.sizes.split(","):
        preset, _, variant = size.partition("-")
        extra = ("--terrain-density", "0.1", "--building-density", "1") if variant == "sparse" else ()
        results[size] = modes(exe, city(preset, extra), size, RESOLUTION[preset], args.directions)
        print(table({size: results[size]}), flush=True)
    if args.error:
        scene = city("tiny", ("--terrain-density", "0.1", "--building-density", "2"))
        ref = os.path.join(CACHE, "tiny_sparse_reference_%d" % args.reference_spp)
        if not os.path.exists(os.path.join(ref, "stats.json")):
            err = run([exe, "reference", scene, "-o", ref, "--resolution", "512", "--spp", str(args.reference_spp),
                       "--seed", "7", *SKY])
            if err:
                sys.exit("reference: " + err)
        rows = modes(exe, scene, "tiny_sparse256", 512, 256)
        for mode, r in rows.items():
            if "error" in r:
                continue
            out = os.path.join(CACHE, "tiny_sparse256_" + mode.replace("-", "_"))
            p = subprocess.run([exe, "compare", out, ref, "--json"], capture_output=True, text=True, check=True)
            r["rel_rmse"] = json.loads(p.stdout)["rel_rmse"]
        results["tiny-sparse, 256 directions"] = rows
        print(table({"tiny-sparse, 256 directions": rows}), flush=True)
    if args.wide:
        # 12 km of sparse terrain with two dense districts: the uniform grid at the densest pixel
        # would be ~28k pixels across, past GL_MAX_VIEWPORT_DIMS (16384 on llvmpipe)
        scene = city("small", ("--size-m", "12000"))
        rows = modes(exe, scene, "wide", 4096, 2)
        results["wide (12 km)"] = rows
        print(table({"wide (12 km)": rows}), flush=True)

    os.makedirs(OUT, exist_ok=True)
    header = "Measured %s on %s (%s, %d cores), Mesa llvmpipe through EGL; %d directions unless stated, --sky 1,1,1, seed 1, default --memory-budget.\n\n" % (
        datetime.date.today().isoformat(), platform.node(), platform.machine(), os.cpu_count(), args.directions)
    with open(os.path.join(OUT, "table.md"), "w") as f:
        f.write(header + table(results) + "\n")
    with open(os.path.join(OUT, "results.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
