#!/usr/bin/python3
"""GL memory of a bake by category, on named scenes.

Bakes each scene for a few directions (memory does not depend on their
number) and prints, from stats.json: page and covered texels, the light-map
state per page texel and per covered texel, the peak of every memory category
(MemoryCategory in engine/core/memory.h: light maps, mesh, materials, bundles,
direct light, importance, read-back), the peak GL memory and the peak resident
set of the process. GL sizes are GL's own component sizes of the objects.

Scenes: the shared Cornell box and mixed_lighting (default `pack` layout), the
generated cities (scripts/generate_city.py, seed 1; tiny, small, city at the
resolutions of bench/tiling_bench.py; --paper adds the 3.7 M-triangle preset).

Usage: bench/memory_bench.py [--bundlebake PATH] [--paper]
Outputs: bench/results/memory/results.json and table.md (printed too).
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tiling_bench import CACHE, RESOLUTION, ROOT, city  # noqa: E402

OUT = os.path.join(ROOT, "bench", "results", "memory")
CATEGORIES = ["light maps", "mesh", "materials", "bundles", "direct light", "importance", "read-back"]


def bake(exe, name, scene, extra):
    out = os.path.join(CACHE, "memory_" + name)
    cmd = [exe, "-q", "bake", scene, "-o", out, "--directions", "4", "--no-preview", "--no-progress", *extra]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return {"error": p.stderr.strip().splitlines()[-1]}
    with open(os.path.join(out, "stats.json")) as f:
        s = json.load(f)
    m = s["memory"]
    return {
        "triangles": s["culling"]["triangles"],
        "page_texels": s["lightmap"]["texels"],
        "covered_texels": s["lightmap"]["covered_texels"],
        "lightmap_bytes_per_page_texel": m["lightmap_bytes_per_page_texel"],
        "lightmap_bytes_per_covered_texel": m["lightmap_bytes_per_covered_texel"],
        "categories": {k: v["peak_bytes"] for k, v in m["by_category"].items()},
        "peak_gpu_bytes": m["peak_gpu_bytes"],
        "peak_gpu_bytes_per_page_texel": m["peak_gpu_bytes_per_page_texel"],
        "peak_resident_bytes": m["peak_resident_bytes"],
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bundlebake", default=os.path.join(ROOT, "build", "bundlebake"))
    ap.add_argument("--paper", action="store_true")
    a = ap.parse_args()
    shared = os.path.join(ROOT, "assets", "shared")
    scenes = [("cornell_box", os.path.join(shared, "cornell_box", "CornellBox.glb"), []),
              ("mixed_lighting", os.path.join(shared, "mixed_lighting", "MixedLightingExample.gltf"), [])]
    for preset in ["tiny", "small", "city"] + (["paper"] if a.paper else []):
        scenes.append(("city_" + preset, city(preset), ["--resolution", str(RESOLUTION[preset]), "--sky", "1,1,1"]))
    results = {name: bake(a.bundlebake, name, path, extra) for name, path, extra in scenes}
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    mib = lambda b: "%.1f" % (b / 2**20)
    lines = ["Measured %s on %s (%s, %d cores), Mesa llvmpipe through EGL; 4 directions, seed 1, default --memory-budget (4G)."
             % (datetime.date.today(), platform.node(), platform.machine(), os.cpu_count()), "",
             "| scene | triangles | page / covered texels (M) | light maps B / page texel | B / covered texel | "
             + " | ".join(c + " MiB" for c in CATEGORIES) + " | peak GL MiB | peak GL B / page texel | peak resident MiB |",
             "|---|---:|---|---:|---:|" + "---:|" * len(CATEGORIES) + "---:|---:|---:|"]
    for name, r in results.items():
        if "error" in r:
            lines.append("| %s | %s |" % (name, r["error"]))
            continue
        cats = " | ".join(mib(r["categories"].get(c, 0)) for c in CATEGORIES)
        lines.append("| %s | %d | %.2f / %.2f | %.1f | %.1f | %s | %s | %.1f | %s |" % (
            name, r["triangles"], r["page_texels"] / 1e6, r["covered_texels"] / 1e6,
            r["lightmap_bytes_per_page_texel"], r["lightmap_bytes_per_covered_texel"], cats,
            mib(r["peak_gpu_bytes"]), r["peak_gpu_bytes_per_page_texel"], mib(r["peak_resident_bytes"])))
    table = "\n".join(lines) + "\n"
    with open(os.path.join(OUT, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()
