#!/usr/bin/env python3
"""Side by side with Mitsuba 3 on the shared scenes: relMSE against the 8192-spp references at equal
samples per pixel, render time, samples/s and efficiency = 1 / (relMSE x seconds), Ember and
Mitsuba interleaved in the same run. Optional dependency, never needed by the tests:

    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba==3.9.1 numpy OpenEXR
    apt-get install libllvm19      # Mitsuba's llvm_ad_rgb variant needs LLVM >= 16 (Debian 12: 15)
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        /tmp/mi/bin/python benchmarks/compare_mitsuba.py --spp 16 64 256 --seeds 3

Prints a Markdown table (the one quoted in docs/performance.md). Ember's seconds are its render
loop's, which it prints; Mitsuba's are those of mi.render after a warm-up render has compiled its
kernels. Both thus leave out process start, scene loading and image output."""
import argparse
import itertools
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from exr import load_exr  # noqa: E402


def relmse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))


def render_ember(ember, scene, spp, seed, threads, out, sampler, kernel, caustics):
    """The image, the render loop's seconds (as Ember reports them: without process start, scene
    load and EXR write, like Mitsuba's timing of mi.render after its JIT warm-up) and the wall
    seconds of the whole process."""
    t = time.perf_counter()
    run = subprocess.run([ember, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed),
                          "--threads", str(threads), "--sampler", sampler, "--kernel", kernel,
                          "--caustics", caustics, "-q"],
                         check=True, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t
    loop = float(re.search(r"render ([0-9.]+) s", run.stderr).group(1))
    return load_exr(out), loop, wall


def ember_column(kernel, sampler, caustics):
    # The default kernel's columns are unnamed (runs before 2026-12-05's run 06 had wavefront there).
    name = f"ember-{sampler}" if kernel == "lanes" else f"ember-{kernel}-{sampler}"
    return name if caustics == "trace" else name + "-pathcaustics"


def print_table(rows, cols):
    """The markdown table of `rows`, each compared with the first Mitsuba variant among `cols`."""
    pixels = 256 * 256
    base = next(c for c in cols if not c.startswith("ember"))
    head = "| scene | spp | " + " | ".join(f"{c} relMSE" for c in cols) + " | " + \
           " | ".join(f"{c} Msamples/s" for c in cols) + " | " + \
           " | ".join(f"efficiency {c} / {base}" for c in cols if c != base) + " | " + \
           " | ".join(f"samples/s {c} / {base}" for c in cols if c != base) + " |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    eff = lambda x: 1.0 / (x["relmse"] * x["seconds"])
    for r in rows:
        cells = [r["scene"], str(r["spp"])] + [f"{r[c]['relmse']:.5f}" for c in cols]
        cells += [f"{pixels * r['spp'] / r[c]['seconds'] / 1e6:.2f}" for c in cols]
        cells += [f"{eff(r[c]) / eff(r[base]):.2f}" for c in cols if c != base]
        # Issue 10's samples/s target: the same spp, so the ratio of the render times.
        cells += [f"{r[base]['seconds'] / r[c]['seconds']:.2f}" for c in cols if c != base]
        print("| " + " | ".join(cells) + " |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", nargs="*", default=["cornell-area", "cornell-point", "shapes", "textured"])
    ap.add_argument("--spp", nargs="*", type=int, default=[16, 64, 256])
    ap.add_argument("--seeds", type=int, default=3, help="independent renders per cell; relMSE and time are averaged")
    ap.add_argument("--variants", nargs="*", default=["llvm_ad_rgb"])
    ap.add_argument("--samplers", nargs="*", default=["independent", "sobol"], help="Ember samplers to run")
    ap.add_argument("--kernels", nargs="*", default=["wave"], help="Ember kernels to run (--kernel)")
    ap.add_argument("--caustics", nargs="*", default=["trace"],
                    help="Ember caustics estimators to run (--caustics trace: light tracing, path: path tracing alone)")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--ember", default=os.path.join(ROOT, "build", "app", "ember"))
    ap.add_argument("--json", help="also write the raw numbers here")
    ap.add_argument("--table-from", metavar="JSON",
                    help="render nothing: print the table of an earlier run's --json file")
    args = ap.parse_args()

    if args.table_from:
        with open(args.table_from) as f:
            rows = json.load(f)
        cols = [k for k in rows[0] if k not in ("scene", "spp")]
        ember = [c for c in cols if c.startswith("ember")]
        print_table(rows, ember + [c for c in cols if c not in ember])
        return

    import mitsuba as mi
    import mitsuba_scene

    tmp = tempfile.mkdtemp(prefix="ember_vs_mitsuba_")
    rows = []
    for name in args.scenes:
        ref = load_exr(os.path.join(ROOT, "tests", "data", name, "reference.exr"))
        spec = os.path.join(ROOT, "tests", "data", name, "scene.json")
        for spp in args.spp:
            row = {"scene": name, "spp": spp}
            # Mitsuba's path tracer cannot find a point light's caustics, which Ember light-traces by
            # default: against its references such scenes render path-traced in every column.
            with open(os.path.join(ROOT, "scenes", name + ".json")) as f:
                point_lights = any(l.get("type") in ("point", "spot") for l in json.load(f).get("lights", []))
            for kernel, sampler, caustics in itertools.product(args.kernels, args.samplers, args.caustics):
                errs, times, walls = [], [], []
                for s in range(args.seeds):
                    img, dt, wall = render_ember(args.ember, os.path.join(ROOT, "scenes", name + ".json"), spp,
                                                 100 + s, args.threads, os.path.join(tmp, "e.exr"), sampler, kernel,
                                                 "path" if point_lights else caustics)
                    errs.append(relmse(img, ref))
                    times.append(dt)
                    walls.append(wall)
                row[ember_column(kernel, sampler, caustics)] = {"relmse": float(np.mean(errs)),
                                                                "seconds": float(np.mean(times)),
                                                                "wall_seconds": float(np.mean(walls))}
            for variant in args.variants:
                mi.set_variant(variant)
                mi.set_log_level(mi.LogLevel.Error)
                errs, times = [], []
                for s in range(args.seeds):
                    scene = mitsuba_scene.build(spec, spp, seed=100 + s)
                    if s == 0:
                        mi.render(scene, spp=1)  # JIT warm-up, not timed
                    t = time.perf_counter()
                    img = np.array(mi.render(scene, spp=spp, seed=100 + s))
                    times.append(time.perf_counter() - t)
                    errs.append(relmse(img, ref))
                row[variant] = {"relmse": float(np.mean(errs)), "seconds": float(np.mean(times))}
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)

    cols = [ember_column(k, s, c) for k, s, c in itertools.product(args.kernels, args.samplers, args.caustics)]
    print_table(rows, cols + args.variants)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
