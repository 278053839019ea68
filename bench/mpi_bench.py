#!/usr/bin/env python3
"""1 MPI rank against 2 (and more with --ranks): wall time, communication
share and error against a converged reference, per scene.

    python3 bench/mpi_bench.py [--exe build/bundlebake] [--ranks 2] [--runs 3]

Scenes: the Cornell box (asset 64^2, 1024 directions; reference: the cached
32768 spp `bundlebake reference` of bench/speed_vs_error.py) and the tiny
sparse city (scripts/generate_city.py --preset tiny --terrain-density 0.1
--building-density 2, 512^2 pages, 256 directions, sky 1; reference: the cached
4096 spp one of bench/tiling_bench.py --error). A reference missing from
bench/cache is made first (minutes). Wall time is the CLI's own total for the
bake (setup included), the median of --runs. Results: bench/results/mpi/.
"""
import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CACHE = os.path.join(ROOT, "bench", "cache")
RESULTS = os.path.join(ROOT, "bench", "results", "mpi")

SCENES = {
    "cornell_box": {
        "scene": "assets/cornell_box/cornell_box.gltf",
        "flags": ["--uv-layout", "asset", "--resolution", "64", "--directions", "1024"],
        "reference": "cornell_box-*",
        "reference_cmd": ["--uv-layout", "asset", "--resolution", "64", "--spp", "32768", "--seed", "7777"],
    },
    "tiny_sparse_city": {
        "scene": "bench/cache/city_tiny_terraindensity_0.1_buildingdensity_2.gltf",
        "make_scene": ["scripts/generate_city.py", "--preset", "tiny", "--terrain-density", "0.1",
                       "--building-density", "2", "-o", "bench/cache/city_tiny_terraindensity_0.1_buildingdensity_2.gltf"],
        "flags": ["--resolution", "512", "--directions", "256", "--sky", "1,1,1"],
        "reference": "tiny_sparse_reference_4096",
        "reference_cmd": ["--resolution", "512", "--sky", "1,1,1", "--spp", "4096"],
    },
}


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(cmd):
    p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr.strip()))
    return p.stdout


def reference(exe, name, cfg):
    found = sorted(glob.glob(os.path.join(CACHE, cfg["reference"])))
    if found:
        return found[0]
    path = os.path.join(CACHE, cfg["reference"].replace("*", "mpi-bench"))
    log("[%s] making the converged reference (%s)" % (name, path))
    run([exe, "-q", "reference", cfg["scene"], "-o", path, "--no-progress"] + cfg["reference_cmd"])
    return path


def bake(exe, ranks, cfg, out):
    cmd = [exe, "-q", "bake", cfg["scene"], "-o", out, "--no-progress", "--no-preview"] + cfg["flags"]
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "--bind-to", "none", "-np", str(ranks)] + cmd
    run(cmd)
    with open(os.path.join(out, "stats.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "bundlebake"))
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    os.makedirs(RESULTS, exist_ok=True)
    rows = []
    for name in args.scenes.split(","):
        cfg = SCENES[name]
        if not os.path.exists(os.path.join(ROOT, cfg["scene"])):
            run([sys.executable] + cfg["make_scene"])
        ref = reference(args.exe, name, cfg)
        for ranks in (1, args.ranks):
            walls, comm, combine, errors, combines, sent = [], [], [], [], 0, 0
            waiting, transferring = [], []
            for r in range(args.runs):
                with tempfile.TemporaryDirectory(prefix="mpi-bench-") as out:
                    s = bake(args.exe, ranks, cfg, out)
                    walls.append(s["seconds"]["total"])
                    combine.append(s["seconds"].get("combine", 0.0))
                    mpi = s.get("mpi")
                    if mpi:
                        comm.append(mpi["communication_share"])
                        waiting.append(max(r["seconds"]["waiting"] for r in mpi["per_rank"]))
                        transferring.append(max(r["seconds"]["transferring"] for r in mpi["per_rank"]))
                        combines = mpi["per_rank"][0]["combines"]
                        sent = mpi["per_rank"][0]["bytes_sent"]
                    if r == 0:
                        m = json.loads(run([args.exe, "-q", "compare", out, ref, "--json"]))
                        errors.append(m["rel_rmse"])
            row = {"scene": name, "ranks": ranks, "seconds_total_median": statistics.median(walls),
                   "seconds_runs": walls, "seconds_combine_median": statistics.median(combine),
                   "communication_share_median": statistics.median(comm) if comm else 0.0,
                   "seconds_waiting_median": statistics.median(waiting) if waiting else 0.0,
                   "seconds_transferring_median": statistics.median(transferring) if transferring else 0.0,
                   "combines": combines, "bytes_sent_per_rank": sent, "rel_rmse_vs_reference": errors[0],
                   "reference": os.path.relpath(ref, ROOT), "flags": cfg["flags"]}
            log("[%s] %d rank(s): %.2f s (runs %s), combine %.3f s, communication %.1f %%, rel. RMSE %.4f" % (
                name, ranks, row["seconds_total_median"], " ".join("%.2f" % w for w in walls),
                row["seconds_combine_median"], 100 * row["communication_share_median"], errors[0]))
            rows.append(row)
    with open(os.path.join(RESULTS, "results.json"), "w") as f:
        json.dump(rows, f, indent=1)
    with open(os.path.join(RESULTS, "table.md"), "w") as f:
        f.write("| scene | ranks | bake s (median) | combine s (rank 0) | waiting s / transferring s (slowest rank) "
                "| communication share | combines | MB sent per rank | rel. RMSE vs reference |\n")
        f.write("|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %d | %.2f | %.3f | %.3f / %.3f | %.1f %% | %d | %.1f | %.4f |\n" % (
                r["scene"], r["ranks"], r["seconds_total_median"], r["seconds_combine_median"],
                r["seconds_waiting_median"], r["seconds_transferring_median"],
                100 * r["communication_share_median"], r["combines"], r["bytes_sent_per_rank"] / 1e6,
                r["rel_rmse_vs_reference"]))
    print(open(os.path.join(RESULTS, "table.md")).read())


if __name__ == "__main__":
    main()
