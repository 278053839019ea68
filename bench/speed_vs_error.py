#!/usr/bin/python3
"""Speed against error: bundlebake (GPU ray bundles) against the CPU path-traced
reference baker, both measured against a converged reference.

For each scene:
  1. a converged reference: `bundlebake reference` at many spp with its own seed,
     cached under bench/cache/ by a hash of the scene's files, the flags and the
     reference baker's source (or, for the furnace, the analytic answer L_lm = 2);
  2. `bundlebake bake` at increasing --directions, and `bundlebake reference` at
     increasing --spp (seed 1, independent of the converged one);
  3. for each point: time and error (`bundlebake compare --json` against the
     converged reference, over texels covered in both).

Outputs, in bench/results/<scene>/: results.csv, speed_vs_error.png (error
against time, log-log) and table.md; bench/results/summary.md collects the
tables with the machine, the date and the settings.

Time is each baker's own figure from stats.json, seconds.total: from the scene in
memory to the light maps (GPU: programs, meta pass, emitters, sun, bundles,
updates, resolves; CPU: BVH, coverage, tracing). Scene loading, GL context
creation and file writing are outside it; the process wall time is in the CSV.
Error is rel_rmse = RMSE / mean of the reference over covered texels and the 3
channels (scale-free; rmse, rel_mse and mean_ratio are in the CSV too).

Usage: bench/speed_vs_error.py [--bundlebake PATH] [--scenes a,b] [--quick]
Run from anywhere; needs /usr/bin/python3 with python3-matplotlib.
"""
import argparse
import csv
import datetime
import hashlib
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "bench")
CACHE = os.path.join(BENCH, "cache")
RESULTS = os.path.join(BENCH, "results")

# Per scene: the shared flags (layout, lighting) and each baker's points. The
# reference's flags are its best on this machine (2 threads; emitter sampling
# on, except the furnace, where every surface emits and cosine sampling alone
# has zero variance for direct emission).
SCENES = {
    "cornell_box": {
        "path": "assets/cornell_box/cornell_box.gltf",
        "flags": ["--uv-layout", "asset", "--resolution", "64"],
        "directions": [16, 32, 64, 128, 256, 512, 1024, 2048],
        "spp": [4, 16, 64, 256, 1024, 4096],
        "reference_flags": [],
        "converged_spp": 32768,
    },
    "furnace": {
        "path": "assets/furnace/furnace.gltf",
        "flags": ["--uv-layout", "asset", "--resolution", "64"],
        "directions": [16, 32, 64, 128, 256, 512, 1024],
        "spp": [4, 16, 64, 256, 1024, 4096],
        "reference_flags": ["--emitter-sampling", "off"],
        "analytic": 2.0,  # Le / (1 - rho) at every texel
    },
    "two_rooms_doorway": {
        "path": "assets/two_rooms/two_rooms_doorway.gltf",
        "flags": ["--uv-layout", "asset", "--resolution", "64"],
        "directions": [16, 32, 64, 128, 256, 512, 1024, 2048],
        "spp": [4, 16, 64, 256, 1024, 4096],
        "reference_flags": [],
        "converged_spp": 32768,
    },
    "mixed_lighting": {
        "path": "assets/shared/mixed_lighting/MixedLightingExample.gltf",
        "flags": ["--uv-layout", "pack", "--resolution", "128"],
        "directions": [16, 32, 64, 128, 256, 512],
        "spp": [4, 16, 64, 256, 1024],
        "reference_flags": [],
        "converged_spp": 16384,
    },
}
CONVERGED_SEED = "7777"
SWEEP_SEED = "1"


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(cmd, quiet=True):
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    dt = time.monotonic() - t0
    if p.returncode != 0:
        raise RuntimeError("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr.strip()))
    return p.stdout, dt


def scene_hash(cfg, flags):
    h = hashlib.sha256()
    scene = os.path.join(ROOT, cfg["path"])
    folder = os.path.dirname(scene)
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if os.path.isfile(path) and not name.endswith(".md"):
            h.update(name.encode())
            with open(path, "rb") as f:
                h.update(hashlib.sha256(f.read()).digest())
    h.update(" ".join(flags).encode())
    for src in ("engine/reference/reference_baker.cpp", "engine/reference/reference_baker.h"):
        with open(os.path.join(ROOT, src), "rb") as f:
            h.update(f.read())
    return h.hexdigest()[:16]


def stats_of(outdir):
    with open(os.path.join(outdir, "stats.json")) as f:
        return json.load(f)


def compare(exe, a, b):
    out, _ = run([exe, "-q", "compare", a, b, "--json"])
    return json.loads(out)


def converged_reference(exe, name, cfg):
    """Path of the converged reference (a bake output dir or an EXR), and a note."""
    scene = os.path.join(ROOT, cfg["path"])
    if "analytic" in cfg:
        res = int(cfg["flags"][cfg["flags"].index("--resolution") + 1])
        path = os.path.join(CACHE, "%s-analytic-%d.exr" % (name, res))
        if not os.path.exists(path):
            os.makedirs(CACHE, exist_ok=True)
            v = cfg["analytic"]
            run(["oiiotool", "--pattern", "constant:color=%g,%g,%g" % (v, v, v), "%dx%d" % (res, res), "3",
                 "-d", "half", "-o", path])
        return path, "analytic L_lm = %g" % cfg["analytic"], 0.0
    flags = cfg["flags"] + cfg["reference_flags"] + ["--spp", str(cfg["converged_spp"]), "--seed", CONVERGED_SEED]
    key = scene_hash(cfg, flags)
    path = os.path.join(CACHE, "%s-%s" % (name, key))
    if not os.path.exists(os.path.join(path, "stats.json")):
        log("[%s] converged reference: %d spp (cached as %s)" % (name, cfg["converged_spp"], os.path.relpath(path, ROOT)))
        tmp = path + ".tmp"
        shutil.rmtree(tmp, ignore_errors=True)
        run([exe, "-q", "reference", scene, "-o", tmp, "--no-progress"] + flags)
        os.replace(tmp, path)
    else:
        log("[%s] converged reference from the cache: %s" % (name, os.path.relpath(path, ROOT)))
    s = stats_of(path)
    return path, "reference %d spp, seed %s" % (cfg["converged_spp"], CONVERGED_SEED), s["seconds"]["total"]


def sweep_point(exe, name, cfg, method, value, ref):
    scene = os.path.join(ROOT, cfg["path"])
    out = os.path.join(CACHE, "runs", name, "%s_%d" % (method, value))
    shutil.rmtree(out, ignore_errors=True)
    if method == "bundlebake":
        cmd = [exe, "-q", "bake", scene, "-o", out, "--directions", str(value), "--seed", SWEEP_SEED,
               "--no-preview", "--no-progress"] + cfg["flags"]
    else:
        cmd = [exe, "-q", "reference", scene, "-o", out, "--spp", str(value), "--seed", SWEEP_SEED,
               "--no-preview", "--no-progress"] + cfg["flags"] + cfg["reference_flags"]
    _, wall = run(cmd)
    s = stats_of(out)
    seconds = s["seconds"]["total"]
    c = compare(exe, out, ref)
    row = {"scene": name, "method": method, "param": "directions" if method == "bundlebake" else "spp",
           "value": value, "seconds": seconds, "process_seconds": wall, "rel_rmse": c["rel_rmse"],
           "rmse": c["rmse"], "rel_mse": c["rel_mse"], "mean_ratio": c["mean_ratio"], "max_abs": c["max_abs"],
           "texels": c["texels"]}
    log("[%s] %-10s %-10s %6d: %7.3f s (process %6.2f s) rel_rmse %.4f mean_ratio %.4f" %
        (name, method, row["param"], value, seconds, wall, c["rel_rmse"], c["mean_ratio"]))
    return row


def interp_loglog(points, t):
    """Error of a (seconds, error) curve at time t, log-log interpolated; None outside its range."""
    pts = sorted(points)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if t0 <= t <= t1 and t1 > t0:
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + a * (math.log(e1) - math.log(e0)))
    return None


def write_outputs(name, cfg, rows, ref_note, ref_seconds):
    outdir = os.path.join(RESULTS, name)
    os.makedirs(outdir, exist_ok=True)
    fields = ["scene", "method", "param", "value", "seconds", "process_seconds", "rel_rmse", "rmse", "rel_mse",
              "mean_ratio", "max_abs", "texels"]
    with open(os.path.join(outdir, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow(r)

    gpu = [r for r in rows if r["method"] == "bundlebake"]
    cpu = [r for r in rows if r["method"] == "reference"]
    cpu_curve = [(r["seconds"], r["rel_rmse"]) for r in cpu]

    # the converged reference's own noise, from the sweep's largest spp: err^2 = s^2 (1/S + 1/Sc)
    noise = None
    if cpu and "converged_spp" in cfg:
        last = max(cpu, key=lambda r: r["value"])
        sc = cfg["converged_spp"]
        noise = last["rel_rmse"] * math.sqrt(last["value"] / sc / (1.0 + last["value"] / sc))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    ax.loglog([r["seconds"] for r in gpu], [r["rel_rmse"] for r in gpu], "o-", label="bundlebake (directions)")
    ax.loglog([r["seconds"] for r in cpu], [r["rel_rmse"] for r in cpu], "s-", label="reference path tracer (spp)")
    for r in gpu:
        ax.annotate(str(r["value"]), (r["seconds"], r["rel_rmse"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    for r in cpu:
        ax.annotate(str(r["value"]), (r["seconds"], r["rel_rmse"]), fontsize=7, xytext=(3, -9), textcoords="offset points")
    if noise:
        ax.axhline(noise, color="grey", lw=0.8, ls=":", label="converged reference's noise (est.)")
    ax.set_xlabel("bake time, s (stats.json seconds.total)")
    ax.set_ylabel("relative RMSE vs converged reference")
    ax.set_title("%s  (%s)" % (name, " ".join(cfg["flags"])), fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "speed_vs_error.png"), dpi=110)
    plt.close(fig)

    lines = ["### %s" % name, "",
             "Scene `%s`, flags `%s`; converged reference: %s%s." %
             (cfg["path"], " ".join(cfg["flags"]), ref_note,
              (", %.1f s" % ref_seconds) if ref_seconds else ""),
             "bundlebake: defaults (bundle resolution from the texel density, 512M budget, stochastic rounding, "
             "automatic history power), seed %s. Reference sweep: 2 threads, seed %s, flags `%s`." %
             (SWEEP_SEED, SWEEP_SEED, " ".join(cfg["reference_flags"]) or "(defaults: emitter sampling on)"), ""]
    if noise is not None:
        lines.append("Estimated noise of the converged reference itself: rel_rmse %.4f (a floor under every error "
                     "below)." % noise)
        lines.append("")
    lines += ["| baker | setting | time s | process s | rel_rmse | mean_ratio | max_abs | reference's rel_rmse at equal time | ratio |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in gpu:
        at = interp_loglog(cpu_curve, r["seconds"])
        lines.append("| bundlebake | %d directions | %.3f | %.2f | %.4f | %.4f | %.4g | %s | %s |" %
                     (r["value"], r["seconds"], r["process_seconds"], r["rel_rmse"], r["mean_ratio"], r["max_abs"],
                      "%.4f" % at if at else "out of range", "%.2f" % (r["rel_rmse"] / at) if at else "-"))
    for r in cpu:
        lines.append("| reference | %d spp | %.3f | %.2f | %.4f | %.4f | %.4g | | |" %
                     (r["value"], r["seconds"], r["process_seconds"], r["rel_rmse"], r["mean_ratio"], r["max_abs"]))
    lines.append("")
    lines.append("ratio = bundlebake's error / the reference baker's error at the same time (log-log interpolated); "
                 "the goal is <= 0.5.")
    lines.append("")
    with open(os.path.join(outdir, "table.md"), "w") as f:
        f.write("\n".join(lines))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bundlebake", default=None, help="the CLI (default: build-ref/, build/ under the repository)")
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated: " + ", ".join(SCENES))
    ap.add_argument("--quick", action="store_true", help="first three points of each sweep, 1/8 of the converged spp")
    args = ap.parse_args()
    exe = args.bundlebake
    if not exe:
        for d in ("build-ref", "build"):
            if os.path.exists(os.path.join(ROOT, d, "bundlebake")):
                exe = os.path.join(ROOT, d, "bundlebake")
                break
    if not exe or not os.path.exists(exe):
        sys.exit("speed_vs_error: no bundlebake binary (build it, or pass --bundlebake)")
    t0 = time.monotonic()
    sections = []
    for name in args.scenes.split(","):
        cfg = dict(SCENES[name])
        if args.quick:
            cfg["directions"] = cfg["directions"][:3]
            cfg["spp"] = cfg["spp"][:3]
            if "converged_spp" in cfg:
                cfg["converged_spp"] //= 8
        ref, note, ref_seconds = converged_reference(exe, name, cfg)
        rows = [sweep_point(exe, name, cfg, "bundlebake", d, ref) for d in cfg["directions"]]
        rows += [sweep_point(exe, name, cfg, "reference", s, ref) for s in cfg["spp"]]
        sections.append(write_outputs(name, cfg, rows, note, ref_seconds))
    load = os.getloadavg()
    header = ["# Speed against error: bundlebake vs the CPU reference path tracer", "",
              "Generated by `bench/speed_vs_error.py` on %s, %s, %d cores (%s), load average at the end %.1f/%.1f/%.1f; "
              "GL: Mesa llvmpipe (CPU). Whole run: %.0f s." %
              (datetime.datetime.now().strftime("%Y-%m-%d %H:%M"), platform.node(), os.cpu_count(),
               platform.processor() or platform.machine(), load[0], load[1], load[2], time.monotonic() - t0), ""]
    os.makedirs(RESULTS, exist_ok=True)
    with open(os.path.join(RESULTS, "summary.md"), "w") as f:
        f.write("\n".join(header + sections))
    log("wrote %s" % os.path.relpath(os.path.join(RESULTS, "summary.md"), ROOT))


if __name__ == "__main__":
    main()
