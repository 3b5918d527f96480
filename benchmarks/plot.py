#!/usr/bin/env python3
"""Plots for docs/performance.md from the JSON the benchmarks write:

    ember bench scenes/cornell-area.json --threads 1 --json t1.json   (and --threads 2 ... t2.json)
    benchmarks/compare_mitsuba.py ... --json cmp.json
    python3 benchmarks/plot.py --bench t1.json t2.json --compare cmp.json --out docs/

Writes perf_threads.png (samples/s against threads) and perf_relmse_time.png (relMSE against
render time on cornell-area, Ember and Mitsuba). Needs matplotlib (an optional dependency)."""
import argparse
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", nargs="+", required=True, help="ember bench --json outputs, one per thread count")
    ap.add_argument("--compare", required=True, help="compare_mitsuba.py --json output")
    ap.add_argument("--scene", default="cornell-area")
    ap.add_argument("--out", default="docs")
    args = ap.parse_args()

    per_scene = {}
    for path in args.bench:
        report = json.load(open(path))
        for row in report["scenes"]:
            name = os.path.splitext(os.path.basename(row["scene"]))[0]
            per_scene.setdefault(name, []).append((row["threads"], row["samples_per_second"] / 1e6))
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for name, points in sorted(per_scene.items()):
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], "o-", label=name)
    threads = sorted({p[0] for pts in per_scene.values() for p in pts})
    ax.set_xticks(threads)
    ax.set_xlabel("threads")
    ax.set_ylabel("M samples/s")
    ax.set_title("Ember throughput against threads")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "perf_threads.png"), dpi=110)

    rows = [r for r in json.load(open(args.compare)) if r["scene"] == args.scene]
    fig, ax = plt.subplots(figsize=(5, 3.5))
    for key in [k for k in rows[0] if k not in ("scene", "spp")]:
        pts = sorted((r[key]["seconds"], r[key]["relmse"]) for r in rows)
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=key)
    ax.set_xlabel("render time (s)")
    ax.set_ylabel("relMSE against the reference")
    ax.set_title(f"{args.scene}: error against time ({', '.join(str(r['spp']) for r in rows)} spp)")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "perf_relmse_time.png"), dpi=110)


if __name__ == "__main__":
    main()
