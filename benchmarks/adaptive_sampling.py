#!/usr/bin/env python3
"""Does adaptive sampling pay? Each scene rendered with `--until-relerr X --adaptive` and uniformly
at the spp that takes about the same render time; both against a reference (the Mitsuba 3
references of tests/data for the four analytic scenes, a long uniform Ember render for glTF files).
Efficiency = 1 / (relMSE x render seconds); the gain is the adaptive render's over the uniform
one's. Prints a Markdown table.

  python3 benchmarks/adaptive_sampling.py --ember build/app/ember [--target 0.05] \\
      [--scenes cornell-area ...] [--gltf path/to/model.gltf ...] [--gltf-ref-spp 4096]
"""
import argparse
import os
import re
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def render(ember, scene, out, extra, seed=3):
    r = subprocess.run([ember, "render", scene, "-o", out, "-q", "--seed", str(seed)] + extra,
                       capture_output=True, text=True, check=True)
    seconds = float(re.search(r"render ([0-9.]+) s", r.stderr).group(1))
    spp = re.search(r"--adaptive: pixels took .*?([0-9.]+) on average", r.stderr)
    return seconds, (float(spp.group(1)) if spp else None)


def relmse(ember, image, reference):
    r = subprocess.run([ember, "compare", image, reference], capture_output=True, text=True)
    return float(re.search(r"relMSE \(all channels\) ([0-9.eE+-]+)", r.stdout + r.stderr).group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--out", default="/tmp/ember-adaptive")
    ap.add_argument("--target", type=float, default=0.05)
    ap.add_argument("--scenes", nargs="*", default=["cornell-area", "cornell-point", "shapes", "textured"])
    ap.add_argument("--gltf", nargs="*", default=[])
    ap.add_argument("--gltf-ref-spp", type=int, default=4096)
    ap.add_argument("--size", type=int, default=240, help="glTF image side")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    cases = []
    for name in args.scenes:
        extra = ["--caustics", "path"] if name == "cornell-point" else []
        cases.append((name, os.path.join(ROOT, "scenes", name + ".json"), extra,
                      os.path.join(ROOT, "tests", "data", name, "reference.exr")))
    for g in args.gltf:
        name = os.path.splitext(os.path.basename(g))[0]
        extra = ["--env", "white", "--width", str(args.size), "--height", str(args.size)]
        ref = os.path.join(args.out, name + "_ref.exr")
        if not os.path.exists(ref):
            render(args.ember, g, ref, extra + ["--spp", str(args.gltf_ref_spp)], seed=1000)
        cases.append((name, g, extra, ref))

    print("| scene | adaptive: s, mean spp, relMSE | uniform: s, spp, relMSE | efficiency gain |")
    print("|---|---|---|---|")
    for name, scene, extra, ref in cases:
        a_out = os.path.join(args.out, name + "_adaptive.exr")
        a_secs, a_spp = render(args.ember, scene, a_out,
                               extra + ["--until-relerr", str(args.target), "--adaptive", "--spp", "65536"])
        a_err = relmse(args.ember, a_out, ref)
        # The uniform spp that takes about as long: from a 16-spp run's rate.
        u_out = os.path.join(args.out, name + "_uniform.exr")
        t16, _ = render(args.ember, scene, u_out, extra + ["--spp", "16"])
        spp = max(4, int(round(16 * a_secs / t16 / 4)) * 4)
        u_secs, _ = render(args.ember, scene, u_out, extra + ["--spp", str(spp)])
        u_err = relmse(args.ember, u_out, ref)
        gain = (u_err * u_secs) / (a_err * a_secs)
        print(f"| {name} | {a_secs:.2f}, {a_spp:.1f}, {a_err:.3g} | {u_secs:.2f}, {spp}, {u_err:.3g} | {gain:.2f}x |",
              flush=True)


if __name__ == "__main__":
    main()
