#!/usr/bin/env python3
"""End-to-end check of csgrt_bench --quick on a tiny mesh and the shipped CSG scenes.

Usage: quick_bench_check.py CSGRT_BENCH SOURCE_DIR WORK_DIR

A closed 12-triangle cube stands in for the armadillo (--data points at a folder holding it
and a link to the shipped scenes), so the run takes seconds. Checks: Google Benchmark's JSON
flag works; every variant traced the same rays and, on the camera rays, hit the same fraction
of them (the cube is closed and the rays are fixed, so the counts are exact); the peers and
the speedup table are there; every scene ran under brute force and the BVH with a frame time
and per-ray counts, and the hierarchy tests fewer objects per ray than brute force.
"""
import json
import pathlib
import subprocess
import sys

bench, source, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
data = work / "data"
(data / "meshes").mkdir(parents=True, exist_ok=True)
cube_vertices = [(x, y, z) for x in (0, 2) for y in (0, 1) for z in (0, 3)]
cube_faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
with open(data / "meshes" / "armadillo.off", "w") as off:
    off.write(f"OFF\n{len(cube_vertices)} {2 * len(cube_faces)} 0\n")
    for v in cube_vertices:
        off.write("%g %g %g\n" % v)
    for a, b, c, d in cube_faces:
        off.write(f"3 {a} {b} {c}\n3 {a} {c} {d}\n")
scenes = data / "scenes"
if not scenes.exists():
    scenes.symlink_to(source / "data" / "scenes")

run = subprocess.run(
    [bench, "--quick", "--data", str(data), "--benchmark_format=json",
     "--benchmark_min_time=0.01",
     "--benchmark_filter=trace/|csg/(part_objects|showcase)/"],
    capture_output=True, text=True, timeout=120)
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


check(run.returncode == 0, f"exit status {run.returncode}: {run.stderr[-2000:]}")
report = json.loads(run.stdout)
results = {b["name"]: b for b in report["benchmarks"]}
check(report["context"].get("csgrt_mode") == "quick", "the mode is in the JSON context")

for rays in ("camera", "incoherent"):
    traced = {name.split("/")[2]: b for name, b in results.items()
              if name.startswith("trace/armadillo/") and f"/{rays}/" in name}
    for required in ("brute", "brute-boxes", "bvh", "cgal"):
        check(required in traced, f"trace/armadillo/{required}/{rays} ran")
    counts = {variant: b["traced"] for variant, b in traced.items()}
    check(len(set(counts.values())) == 1, f"{rays}: every variant traced the same rays {counts}")
    fractions = {variant: b["hit_fraction"] for variant, b in traced.items()}
    check(len(set(fractions.values())) == 1, f"{rays}: the same hits everywhere {fractions}")
    if rays == "camera":
        check(0.05 < fractions.get("bvh", 0) < 1.0, "camera: some rays hit the cube, not all")
    else:
        # Aimed at points of the mesh's box, which is the cube: every ray hits it.
        check(fractions.get("bvh", 0) == 1.0, "incoherent: every ray hits the cube")
    for variant, b in traced.items():
        check(b.get("items_per_second", 0) > 0, f"{variant}/{rays} has a ray rate (items_per_second)")

for scene in ("part_objects", "showcase"):
    # Manual time adds "/manual_time" to the names.
    brute = results.get(f"csg/{scene}/brute/threads:1/manual_time")
    bvh = results.get(f"csg/{scene}/bvh/threads:1/manual_time")
    check(brute is not None and bvh is not None, f"{scene}: brute and bvh frames ran")
    if brute and bvh:
        check(bvh["time_unit"] == "ms" and bvh["real_time"] > 0, f"{scene}: a frame time")
        check(brute["objects_per_ray"] == brute["objects"],
              f"{scene}: brute force tests every object on every ray")
        check(bvh["objects_per_ray"] < brute["objects_per_ray"],
              f"{scene}: the hierarchy tests fewer objects per ray")
        check(bvh["rendered_width"] == 128, f"{scene}: the quick frame is 128 wide")

summary = run.stderr
for text in ("csgrt_bench summary: armadillo", "x CGAL", "x Embree", "CSG scenes of data/scenes",
             "ms/frame"):
    check(text in summary, f"the summary (on stderr with JSON output) has '{text}'")

for failure in failures:
    print("FAILED:", failure)
print(f"{len(results)} benchmarks checked, {len(failures)} failures")
sys.exit(1 if failures else 0)
