#!/usr/bin/env python3
"""How much does denoising buy? Each analytic scene rendered at 4-64 spp with `--denoise` (Intel
Open Image Denoise, guided by the albedo and normal AOVs); the denoised colour and the noisy one
(its noisy.R/G/B layer) are each compared with the Mitsuba 3 reference of tests/data (relMSE and
FLIP, `ember compare`). Then the spp at which the noisy render alone reaches the denoised 16-spp
image's relMSE (found by doubling, then interpolated with relMSE ~ 1/spp), and the denoiser's
time per megapixel (`ember denoise`, 1920x1080 with both guides). Prints Markdown tables.

  python3 benchmarks/denoise_table.py --ember build/app/ember [--threads 2] [--picture docs/x.jpg]
"""
import argparse
import os
import re
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = ("cornell-area", "cornell-point", "shapes", "textured")


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(" ".join(cmd) + "\n" + r.stderr)
    return r.stderr + r.stdout


def render(args, scene, out, spp, extra=()):
    text = run([args.ember, "render", scene, "-o", out, "-q", "--spp", str(spp), "--seed", "1",
                "--threads", str(args.threads)] + list(extra))
    secs = float(re.search(r"render ([0-9.]+) s", text).group(1))
    d = re.search(r"denoised in ([0-9.]+) s", text)
    return secs, float(d.group(1)) if d else 0.0


def metrics(args, image, reference):
    text = run([args.ember, "compare", image, reference])
    m = re.search(r"relMSE \(all channels\) ([0-9.eE+-]+), FLIP mean ([0-9.eE+-]+)", text)
    return float(m.group(1)), float(m.group(2))


def split_noisy(path, out):
    """The noisy.R/G/B layer of a --denoise EXR as its own RGB file (oiiotool)."""
    run(["oiiotool", path, "--ch", "R=noisy.R,G=noisy.G,B=noisy.B", "-o", out])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--out", default="/tmp/ember-denoise")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--spp", type=int, nargs="+", default=[4, 8, 16, 32, 64])
    ap.add_argument("--picture", help="write noisy | denoised | reference of cornell-area at 16 spp here")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    print("| scene | spp | noisy relMSE | denoised relMSE | noisy FLIP | denoised FLIP | render s | denoise s |")
    print("|---|---|---|---|---|---|---|---|")
    at16 = {}
    for name in SCENES:
        scene = os.path.join(ROOT, "scenes", name + ".json")
        ref = os.path.join(ROOT, "tests", "data", name, "reference.exr")
        extra = ["--caustics", "path"] if name == "cornell-point" else []
        for spp in args.spp:
            d = os.path.join(args.out, f"{name}_{spp}_denoised.exr")
            n = os.path.join(args.out, f"{name}_{spp}_noisy.exr")
            secs, dsecs = render(args, scene, d, spp, extra + ["--denoise"])
            split_noisy(d, n)
            (nr, nf), (dr, df) = metrics(args, n, ref), metrics(args, d, ref)
            if spp == 16:
                at16[name] = dr
            print(f"| {name} | {spp} | {nr:.3g} | {dr:.3g} | {nf:.3f} | {df:.3f} | {secs:.2f} | {dsecs:.2f} |",
                  flush=True)

    print()
    print("| scene | denoised 16 spp relMSE | noisy spp for the same relMSE |")
    print("|---|---|---|")
    for name in SCENES:
        scene = os.path.join(ROOT, "scenes", name + ".json")
        ref = os.path.join(ROOT, "tests", "data", name, "reference.exr")
        extra = ["--caustics", "path"] if name == "cornell-point" else []
        spp, err = 32, None
        while spp <= 16384:
            n = os.path.join(args.out, f"{name}_{spp}_plain.exr")
            render(args, scene, n, spp, extra)
            err, _ = metrics(args, n, ref)
            if err <= at16[name]:
                break
            spp *= 2
        print(f"| {name} | {at16[name]:.3g} | {spp * err / at16[name]:.0f} |", flush=True)

    # The denoiser's cost: a 1920x1080 image with both guides.
    big = os.path.join(args.out, "big.exr")
    render(args, os.path.join(ROOT, "scenes", "shapes.json"), big, 1,
           ["--width", "1920", "--height", "1080", "--aov", "albedo,normal"])
    for prefilter in ([], ["--no-prefilter"]):
        text = run([args.ember, "denoise", big, "-o", os.path.join(args.out, "big_d.exr"),
                    "--threads", str(args.threads)] + prefilter)
        per = re.search(r"\(([0-9.]+) s per megapixel", text).group(1)
        print(f"\nDenoiser, 1920x1080, {args.threads} threads{' ' + prefilter[0] if prefilter else ''}: "
              f"{per} s per megapixel")

    if args.picture:
        tiles = []
        d = os.path.join(args.out, "cornell-area_16_denoised.exr")
        n = os.path.join(args.out, "cornell-area_16_noisy.exr")
        ref = os.path.join(ROOT, "tests", "data", "cornell-area", "reference.exr")
        for k, src in enumerate((n, d, ref)):
            png = os.path.join(args.out, f"tile{k}.png")
            # One exposure for all three: the reference's white point.
            run([args.ember, "tonemap", src, "-o", png, "--white", "1.2"])
            tiles.append(png)
        run(["oiiotool"] + tiles + ["--mosaic:pad=4", "3x1", "-o", args.picture])


if __name__ == "__main__":
    main()
