#!/usr/bin/env python3
"""Ember against Blender's Cycles on glTF files, in the same run: each model rendered by both with
the same camera and a white environment of radiance 1, and the mean over the model's pixels
compared channel by channel (Ember / Cycles). Optional; never needed by the tests:

    apt-get install blender python3-numpy        # Debian 12: Blender 3.4.1
    python3 benchmarks/compare_cycles.py ../shared/assets/gltf/*/*.gltf --spp 64 --out /tmp/cycles

The camera is the framing camera Ember makes for a file without one (io/scene_loader.cpp), written
into a JSON scene that wraps the file so that both renderers see the same view; the model's pixels
are those Cycles renders opaque (alpha > 0.99 with a transparent film). Cycles: CPU, box filter of
width 1, no adaptive sampling, no denoiser, 1024 bounces of every kind. Prints a Markdown table
and writes a side-by-side PNG per model (Ember left, Cycles right, the same exposure) to --out.
Blender 3.4's Principled BSDF is not the glTF BRDF, so ratios near 1 are plausibility, not proof.

--timing compares speed instead (issue 44's method): each model rendered by both at 1 spp and at
--spp, one after the other; the time per sample pass is (wall at --spp - wall at 1) / (--spp - 1),
so that loading, BVH builds and Blender's scene sync cancel out, and the table gives samples/s and
their ratio, Ember / Cycles.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def bounds_of(ember, model):
    out = subprocess.run([ember, "info", model], check=True, capture_output=True, text=True).stdout
    m = re.search(r"bounds:\s+\(([^)]*)\) - \(([^)]*)\)", out)
    lower = [float(v) for v in m.group(1).split(",")]
    upper = [float(v) for v in m.group(2).split(",")]
    return lower, upper


def framing_camera(lower, upper, aspect):
    """io/scene_loader.cpp's framingCamera: fov 40 degrees, from +z and slightly above."""
    center = [(a + b) / 2 for a, b in zip(lower, upper)]
    radius = max(0.5 * math.dist(lower, upper), 1e-3)
    half_fov = math.radians(40.0) * 0.5 * min(1.0, aspect)
    distance = 1.1 * radius / math.sin(half_fov)
    d = [0.0, 0.35, 1.0]
    n = math.sqrt(sum(x * x for x in d))
    origin = [c + distance * x / n for c, x in zip(center, d)]
    return origin, center


def blender_env():
    """The environment without another Python's directories on PATH: Blender derives its Python's
    prefix, and so finds Debian's numpy or not, from the first python3 on PATH (pyenv shims)."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join(d for d in env.get("PATH", "").split(os.pathsep) if "pyenv" not in d)
    return env


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("models", nargs="+")
    ap.add_argument("--ember", default=os.path.join(ROOT, "build", "app", "ember"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--width", type=int, default=512)
    ap.add_argument("--height", type=int, default=384)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default="/tmp/ember-cycles")
    ap.add_argument("--single-scatter", action="store_true",
                    help="Cycles' Principled BSDFs with single-scattering GGX, as glTF's Appendix B")
    ap.add_argument("--timing", action="store_true", help="samples/s at 1 and --spp spp instead of the means")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.timing:
        timing(args)
        return

    rows = []
    for model in args.models:
        name = os.path.splitext(os.path.basename(model))[0]
        result = render_both(args, model, name, args.spp)
        if result:
            rows.append(result)
            print(json.dumps(result), file=sys.stderr)

    print("| model | Ember / Cycles mean (R, G, B) | model pixels | Ember s | Cycles s |")
    print("|---|---|---|---|---|")
    for r in rows:
        ratio = ", ".join(f"{x:.2f}" for x in r["ratio"])
        print(f"| {r['name']} | {ratio} | {r['pixels']} | {r['ember_s']:.1f} | {r['cycles_s']:.1f} |")


def timing(args):
    print("| model | Ember Msamples/s | Cycles Msamples/s | Ember / Cycles |")
    print("|---|---|---|---|")
    pixels = args.width * args.height
    for model in args.models:
        name = os.path.splitext(os.path.basename(model))[0]
        one = render_both(args, model, name, 1)
        many = render_both(args, model, name, args.spp)
        if not one or not many:
            continue
        per_pass = {k: (many[k] - one[k]) / (args.spp - 1) for k in ("ember_s", "cycles_s")}
        rate = {k: pixels / max(v, 1e-9) / 1e6 for k, v in per_pass.items()}
        print(f"| {name} | {rate['ember_s']:.2f} | {rate['cycles_s']:.2f} | "
              f"{rate['ember_s'] / rate['cycles_s']:.2f}x |", flush=True)
        print(json.dumps({"name": name, "one": one, "many": many, "spp": args.spp}), file=sys.stderr)


def render_both(args, model, name, spp):
    """Renders the model with Ember, then with Cycles, at `spp`; their wall times and the means."""
    lower, upper = bounds_of(args.ember, model)
    origin, target = framing_camera(lower, upper, args.width / args.height)
    scene = {
        "image": {"width": args.width, "height": args.height},
        "camera": {"origin": origin, "target": target, "up": [0, 1, 0], "fov_y_deg": 40.0},
        "render": {"background": [1, 1, 1]},
        "shapes": [{"type": "mesh", "file": os.path.abspath(model)}],
    }
    scene_path = os.path.join(args.out, name + ".json")
    with open(scene_path, "w") as f:
        json.dump(scene, f)
    ember_exr = os.path.join(args.out, name + "-ember.exr")
    t = time.perf_counter()
    subprocess.run([args.ember, "render", scene_path, "-o", ember_exr, "--spp", str(spp),
                    "--threads", str(args.threads), "-q"], check=True, capture_output=True)
    ember_s = time.perf_counter() - t
    job = {"model": os.path.abspath(model), "origin": origin, "target": target, "spp": spp,
           "width": args.width, "height": args.height, "threads": args.threads,
           "cycles_exr": os.path.join(args.out, name + "-cycles.exr"), "ember_exr": ember_exr,
           "png": os.path.join(args.out, name + ".png"), "single_scatter": args.single_scatter}
    job_path = os.path.join(args.out, name + "-job.json")
    with open(job_path, "w") as f:
        json.dump(job, f)
    t = time.perf_counter()
    run = subprocess.run([args.blender, "-b", "--factory-startup", "-P", os.path.join(HERE, "cycles_render.py"),
                          "--", job_path], capture_output=True, text=True, env=blender_env())
    cycles_s = time.perf_counter() - t
    m = re.search(r"^RESULT (.*)$", run.stdout, re.M)
    if not m:
        print(f"{name}: Blender failed:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}", file=sys.stderr)
        return None
    result = json.loads(m.group(1))
    result.update(name=name, ember_s=ember_s, cycles_s=cycles_s)
    return result


if __name__ == "__main__":
    main()
