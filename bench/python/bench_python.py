#!/usr/bin/env python3
"""Times the csgrt module's cast_rays on 10^6 camera rays over a mesh and, when a virtual
environment with them exists, the Python peers on the same rays in the same run: Open3D's
RaycastingScene, embreex (Embree 4) and trimesh (docs/benchmarks.md, issue 12).

    bench_python.py [--mesh data/meshes/armadillo.off] [--venv DIR] [--make-venv]
                    [--rays 1000000] [--repetitions 5] [--json out.json]

csgrt is imported from PYTHONPATH (build/release/python). --make-venv creates DIR with
`python3 -m venv --system-site-packages` and pip-installs open3d, embreex and trimesh there
(only the bench script does this; the tests never need them); the peers are then timed by
running this script again under the venv's interpreter with --peers-only.
Timings on a loaded machine are not results: the script prints the load average beside them.
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

PEERS = ["open3d", "embreex", "trimesh"]


def read_off(path):
    """Vertices (N, 3) float64 and triangles (M, 3) of an OFF file of triangles."""
    words = pathlib.Path(path).read_text().split()
    if words[0] != "OFF":
        raise SystemExit(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    at = 4
    vertices = np.array(words[at:at + 3 * nv], dtype=np.float64).reshape(nv, 3)
    at += 3 * nv
    faces = np.array(words[at:at + 4 * nf], dtype=np.int64).reshape(nf, 4)
    if not (faces[:, 0] == 3).all():
        raise SystemExit(f"{path}: only triangle faces are read here")
    return vertices, faces[:, 1:].astype(np.uint32)


def camera_rays(vertices, count):
    """A square grid of pinhole rays (unit directions, float32, (side * side, 6)) through a
    40-degree view of the mesh."""
    lower, upper = vertices.min(axis=0), vertices.max(axis=0)
    # As csgrt_bench's framing_camera: from (0.3, 0.25, 1) of the centre, far enough that a
    # sphere of the box's largest extent fills the 40-degree view's height.
    centre, extent = 0.5 * (lower + upper), (upper - lower).max()
    view = np.array([0.3, 0.25, 1.0]) / np.linalg.norm([0.3, 0.25, 1.0])
    eye = centre + view * 0.5 * extent / np.tan(np.radians(20.0))
    side = int(round(count**0.5))
    forward = (centre - eye) / np.linalg.norm(centre - eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = np.tan(np.radians(20.0))
    s = (np.arange(side) + 0.5) / side * 2 - 1
    x, y = np.meshgrid(s * half, -s * half)
    d = forward + x[..., None] * right + y[..., None] * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    rays = np.concatenate([np.broadcast_to(eye, d.shape), d], axis=-1).astype(np.float32)
    return rays.reshape(-1, 6)


def best_of(repetitions, run):
    """Median and min-max seconds of `run()` over the repetitions, after one warm-up, and the
    median process CPU seconds (the measure for one thread: other processes on a shared
    machine barely change it, as csgrt_bench's one-thread rows)."""
    run()
    wall, cpu = [], []
    for _ in range(repetitions):
        start, start_cpu = time.perf_counter(), time.process_time()
        run()
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return float(np.median(wall)), float(min(wall)), float(max(wall)), float(np.median(cpu))


def row(variant, threads, timing):
    median, lo, hi, cpu = timing
    return {"variant": variant, "threads": threads, "seconds": median, "min": lo, "max": hi,
            "cpu_seconds": cpu}


def time_csgrt(vertices, triangles, rays, repetitions, threads_list):
    import csgrt

    scene = csgrt.RaycastingScene()
    scene.add_triangles(vertices.astype(np.float32), triangles)
    rows = []
    for threads in threads_list:
        for outputs, label in [(None, "csgrt cast_rays (all outputs)"),
                               (["t_hit", "primitive_ids"], "csgrt cast_rays (t, id)")]:
            timing = best_of(
                repetitions, lambda: scene.cast_rays(rays, outputs=outputs, nthreads=threads))
            rows.append(row(label, threads, timing))
    hits = np.isfinite(scene.cast_rays(rays, outputs=["t_hit"])["t_hit"]).mean()
    return rows, float(hits)


def time_cpp_batch(timer, vertices, triangles, rays, repetitions, threads_list):
    """The C++ batch on the same mesh and rays (bench/batch_timer_main.cpp), for the ratio of
    Python's cast_rays to it."""
    with tempfile.TemporaryDirectory() as folder:
        folder = pathlib.Path(folder)
        vertices.astype(np.float32).tofile(folder / "vertices")
        triangles.astype(np.uint32).tofile(folder / "triangles")
        np.ascontiguousarray(rays, dtype=np.float32).tofile(folder / "rays")
        result = subprocess.run([str(timer), str(folder / "vertices"), str(folder / "triangles"),
                                 str(folder / "rays"), "--repetitions", str(repetitions),
                                 "--threads", ",".join(str(t) for t in threads_list)],
                                check=True, capture_output=True, text=True)
    return json.loads(result.stdout)


def time_peers(vertices, triangles, rays, repetitions, threads_list):
    rows = []
    try:
        import open3d as o3d

        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)),
                            o3d.core.Tensor(triangles.astype(np.uint32)))
        tensor = o3d.core.Tensor(rays)
        for threads in threads_list:
            timing = best_of(repetitions, lambda: scene.cast_rays(tensor, nthreads=threads))
            rows.append(row(f"open3d {o3d.__version__} cast_rays", threads, timing))
    except ImportError as error:
        print(f"bench_python: open3d not available ({error})", file=sys.stderr)
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, vertices.astype(np.float32)[triangles])
        origins, directions = np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:])
        timing = best_of(repetitions, lambda: scene.run(origins, directions, output=1))
        rows.append(row("embreex run (rtcIntersect1 loop)", 1, timing))
    except ImportError as error:
        print(f"bench_python: embreex not available ({error})", file=sys.stderr)
    try:
        import trimesh

        mesh = trimesh.Trimesh(vertices, triangles.astype(np.int64), process=False)
        origins, directions = rays[:, :3].astype(np.float64), rays[:, 3:].astype(np.float64)
        timing = best_of(max(1, repetitions // 5),
                         lambda: mesh.ray.intersects_first(origins, directions))
        rows.append(row(f"trimesh {trimesh.__version__} intersects_first "
                        f"({type(mesh.ray).__module__})", 1, timing))
    except ImportError as error:
        print(f"bench_python: trimesh not available ({error})", file=sys.stderr)
    return rows


def make_venv(venv):
    if (venv / "bin" / "python").exists():
        return
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    # NumPy stays Debian's (1.24, which the csgrt module was built against).
    subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "-q", "numpy<2",
                    "open3d", "embreex", "trimesh"], check=True)


def main():
    root = pathlib.Path(__file__).resolve().parents[2]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", default=str(root / "data/meshes/armadillo.off"))
    parser.add_argument("--rays", type=int, default=1_000_000)
    parser.add_argument("--repetitions", type=int, default=5)
    parser.add_argument("--venv", default=str(root / "build/bench-venv"))
    parser.add_argument("--make-venv", action="store_true")
    parser.add_argument("--peers-only", action="store_true")
    parser.add_argument("--json")
    parser.add_argument("--batch-timer",
                        help="csgrt_batch_timer (default: bench/ beside the csgrt module's build)")
    args = parser.parse_args()

    vertices, triangles = read_off(args.mesh)
    rays = camera_rays(vertices, args.rays)
    threads_list = [1, os.cpu_count() or 1] if (os.cpu_count() or 1) > 1 else [1]
    if args.peers_only:
        print(json.dumps(time_peers(vertices, triangles, rays, args.repetitions, threads_list)))
        return

    venv = pathlib.Path(args.venv)
    if args.make_venv:
        make_venv(venv)
    rows, hit_fraction = time_csgrt(vertices, triangles, rays, args.repetitions, threads_list)
    import csgrt

    timer = pathlib.Path(args.batch_timer or
                         pathlib.Path(csgrt.__file__).resolve().parents[1] / "bench" /
                         "csgrt_batch_timer")
    if timer.exists():
        rows += time_cpp_batch(timer, vertices, triangles, rays, args.repetitions, threads_list)
    else:
        print(f"bench_python: no {timer}: the C++ batch is not measured", file=sys.stderr)
    if (venv / "bin" / "python").exists():
        result = subprocess.run([str(venv / "bin" / "python"), __file__, "--peers-only",
                                 "--mesh", args.mesh, "--rays", str(args.rays),
                                 "--repetitions", str(args.repetitions)],
                                check=True, capture_output=True, text=True,
                                env={**os.environ})
        sys.stderr.write(result.stderr)
        rows += json.loads(result.stdout.strip().splitlines()[-1])
    else:
        print(f"bench_python: no venv at {venv} (scripts/bench makes it): peers not measured",
              file=sys.stderr)

    load = os.getloadavg()
    print(f"Python ray casting: {len(rays):,} camera rays on {pathlib.Path(args.mesh).name} "
          f"({len(triangles):,} triangles), {hit_fraction:.0%} hit; median of "
          f"{args.repetitions} (min-max); load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    print(f"{'variant':58} {'threads':>7} {'Mrays/s':>9}   {'min-max (wall)':>14}  "
          f"Mrays/s of CPU time")
    for r in rows:
        n = len(rays) * 1e-6
        r["mrays_per_second"] = n / r["seconds"]
        r["mrays_per_cpu_second"] = n / r["cpu_seconds"] if r["cpu_seconds"] > 0 else None
        # One thread: CPU time, as csgrt_bench; several: wall time, the only one that scales.
        rate = r["mrays_per_cpu_second"] if r["threads"] == 1 else r["mrays_per_second"]
        print(f"{r['variant']:58} {r['threads']:>7} {rate:9.2f}   "
              f"{n / r['max']:6.2f}-{n / r['min']:<6.2f}  {n / r['cpu_seconds']:.2f}")
    # The ratios the floors name, each from two figures of this run, in wall time
    # (median, and min-max: the slowest over the fastest repetition and the fastest over the
    # slowest), so the spread is that of the ratio itself.
    def rate(r, pick):
        seconds = {"median": r["seconds"], "fast": r["min"], "slow": r["max"]}[pick]
        return len(rays) / seconds

    def find(prefix, threads):
        return next((r for r in rows if r["variant"].startswith(prefix) and
                     r["threads"] == threads), None)

    print(f"\n{'ratio (wall time)':58} {'threads':>7} {'median':>9}   {'min-max':>14}")
    for threads in threads_list:
        for label, mine, peer in [
                ("Python cast_rays / C++ batch (all outputs)", "csgrt cast_rays (all",
                 "C++ batch intersect (all"),
                ("Python cast_rays / C++ batch (t, id)", "csgrt cast_rays (t", "C++ batch intersect (t"),
                ("csgrt cast_rays (all outputs) / Open3D cast_rays", "csgrt cast_rays (all",
                 "open3d")]:
            a, b = find(mine, threads), find(peer, threads)
            if a is None or b is None:
                continue
            print(f"{label:58} {threads:>7} {rate(a, 'median') / rate(b, 'median'):9.2f}   "
                  f"{rate(a, 'slow') / rate(b, 'fast'):6.2f}-{rate(a, 'fast') / rate(b, 'slow'):<6.2f}")
    if args.json:
        pathlib.Path(args.json).write_text(json.dumps(
            {"rays": len(rays), "triangles": len(triangles), "load_average": load,
             "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
