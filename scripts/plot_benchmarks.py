#!/usr/bin/env python3
"""Draws the plots of a csgrt_bench report from its report.json, next to it:

- summary.png: Mrays/s of each structure and peer on the armadillo (camera, incoherent rays);
- scaling.png: query time per ray and build time against the number of triangles, log-log,
  with the fitted exponents k of time ~ N^k;
- accuracy.png: run time against error for each accuracy group, the Pareto front marked.

Usage: scripts/plot_benchmarks.py results/latest/report.json
"""
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ERROR_LABELS = {
    "wrong": "fraction of rays answered wrongly",
    "t_err_p99": "relative t error, 99th percentile",
    "colour_rmse": "RMSE of the shaded image",
    "depth_rmse": "RMSE of depth / mesh diagonal",
}
GROUP_METRICS = {
    "triangles": ["wrong", "t_err_p99"],
    "quartic": ["wrong", "t_err_p99"],
    "decimation": ["colour_rmse", "depth_rmse"],
}


def plot_summary(report, directory):
    rows = [r for r in report.get("summary", []) if r.get("camera") and r.get("incoherent")]
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    names = [r["variant"] for r in rows]
    width = 0.38
    for offset, key in ((-width / 2, "camera"), (width / 2, "incoherent")):
        ax.bar([i + offset for i in range(len(rows))], [r[key] * 1e-6 for r in rows], width,
               label=f"{key} rays")
    ax.set_xticks(range(len(rows)), names, rotation=20)
    ax.set_yscale("log")
    ax.set_ylabel("Mrays/s, one thread")
    ax.set_title("armadillo: structures and peers in one run")
    ax.legend()
    ax.grid(axis="y", which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(directory / "summary.png", dpi=120)
    plt.close(fig)


def plot_scaling(report, directory):
    series = report.get("scaling", [])
    if not series:
        return
    fig, (query, build) = plt.subplots(1, 2, figsize=(12, 5))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for index, s in enumerate(series):
        colour = colours[index % len(colours)]
        fits = s.get("fit", {})
        for key, style in (("camera", "-"), ("incoherent", "--")):
            points = s.get(key, [])
            if not points:
                continue
            k = fits.get(key, {}).get("exponent")
            label = f"{s['variant']} {key}" + (f" (k={k:.2f})" if k is not None else "")
            query.plot([p[0] for p in points], [p[1] for p in points], style, marker="o",
                       color=colour, label=label)
        points = s.get("build", [])
        if points:
            k = fits.get("build", {}).get("exponent")
            label = s["variant"] + (f" (k={k:.2f})" if k is not None else "")
            build.plot([p[0] for p in points], [p[1] for p in points], marker="o", color=colour,
                       label=label)
    for ax, title, unit in ((query, "query time per ray", "ns / ray"),
                            (build, "build time (one thread)", "ms")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("triangles")
        ax.set_ylabel(unit)
        ax.set_title(title)
        ax.grid(which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(directory / "scaling.png", dpi=120)
    plt.close(fig)


def pareto_line(points):
    """The staircase through the front's points, sorted by time."""
    front = sorted(points)
    xs, ys = [], []
    for x, y in front:
        if xs:
            xs.append(x)
            ys.append(ys[-1])
        xs.append(x)
        ys.append(y)
    return xs, ys


def plot_accuracy(report, directory):
    points = report.get("accuracy", [])
    groups = [g for g in GROUP_METRICS if any(p["group"] == g for p in points)]
    if not groups:
        return
    fig, axes = plt.subplots(2, len(groups), figsize=(5 * len(groups), 8), squeeze=False)
    for column, group in enumerate(groups):
        rows = [p for p in points if p["group"] == group]
        for row, metric in enumerate(GROUP_METRICS[group]):
            ax = axes[row][column]
            values = [p.get(metric, float("nan")) for p in rows]
            positive = [v for v in values if v and v > 0 and math.isfinite(v)]
            # Exact zeros cannot sit on a log axis: they are drawn at a floor and labelled.
            floor = min(positive) / 10 if positive else 1e-20
            front = []
            for p, v in zip(rows, values):
                if not math.isfinite(v):
                    continue
                y = v if v > 0 else floor
                on_front = p.get("pareto", {}).get(metric, False)
                ax.scatter(p["ns_per_ray"], y, s=70 if on_front else 30,
                           marker="D" if on_front else "o",
                           color="tab:red" if on_front else "tab:blue", zorder=3)
                ax.annotate(p["variant"] + (" (0)" if v == 0 else ""), (p["ns_per_ray"], y),
                            fontsize=7, xytext=(4, 4), textcoords="offset points")
                if on_front:
                    front.append((p["ns_per_ray"], y))
            if front:
                xs, ys = pareto_line(front)
                ax.plot(xs, ys, color="tab:red", alpha=0.5, label="Pareto front")
                ax.legend(fontsize=7)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("ns per ray (one thread)")
            ax.set_ylabel(ERROR_LABELS.get(metric, metric))
            ax.set_title(group)
            ax.grid(which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(directory / "accuracy.png", dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    path = Path(sys.argv[1])
    report = json.loads(path.read_text())
    plot_summary(report, path.parent)
    plot_scaling(report, path.parent)
    plot_accuracy(report, path.parent)


if __name__ == "__main__":
    main()
