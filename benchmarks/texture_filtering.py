#!/usr/bin/env python3
"""Does texture filtering pay? A checkerboard plane to the horizon under a white sky, rendered with
bilinear lookups (unbiased: the pixel integral of the texture) and with trilinear MIP-mapped ones
("filter": "trilinear", io/filtered_texture.h), at 1 to 16 spp, each against a converged bilinear
reference. Prints a Markdown table of relMSE and FLIP (ember compare).

  python3 benchmarks/texture_filtering.py --ember build/app/ember [--ref-spp 4096] [--out DIR]
"""
import argparse
import json
import os
import struct
import subprocess


def write_checker_pfm(path, size=64, squares=8):
    """A size x size checkerboard of `squares` x `squares` cells, 0.05 and 0.8, as a PFM (linear)."""
    cell = size // squares
    rows = []
    for y in range(size):
        row = []
        for x in range(size):
            v = 0.8 if ((x // cell) + (y // cell)) % 2 == 0 else 0.05
            row += [v, v, v]
        rows.append(row)
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (size, size))
        for row in reversed(rows):  # PFM stores rows from the bottom
            f.write(struct.pack("<%df" % len(row), *row))


def scene(filter_name, repeats=60.0, half=60.0):
    return {
        "image": {"width": 320, "height": 160},
        "camera": {"origin": [0, 1.0, 0], "target": [0, 0.55, -10], "up": [0, 1, 0], "fov_y_deg": 40},
        "render": {"max_depth": -1, "rr_depth": 5, "background": [1, 1, 1]},
        "materials": {"checker": {"type": "diffuse",
                                  "reflectance": {"texture": "checker.pfm", "filter": filter_name}}},
        "shapes": [{"type": "quad", "material": "checker",
                    "vertices": [[-half, 0, half], [half, 0, half], [half, 0, -half], [-half, 0, -half]],
                    "uvs": [[0, 0], [repeats, 0], [repeats, repeats], [0, repeats]]}],
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--out", default="/tmp/ember-texture-filtering")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--spp", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    write_checker_pfm(os.path.join(args.out, "checker.pfm"))
    paths = {}
    for f in ("bilinear", "trilinear"):
        paths[f] = os.path.join(args.out, f + ".json")
        with open(paths[f], "w") as fh:
            json.dump(scene(f), fh, indent=1)

    def render(f, spp, seed, out):
        run = subprocess.run([args.ember, "render", paths[f], "-o", out, "--spp", str(spp), "--seed", str(seed),
                              "-q"], check=True, capture_output=True, text=True)
        return float(run.stderr.split("render ")[1].split(" s")[0])

    ref = os.path.join(args.out, "reference.exr")
    if not os.path.exists(ref):
        render("bilinear", args.ref_spp, 12345, ref)

    print("| spp | bilinear relMSE | trilinear relMSE | bilinear FLIP | trilinear FLIP | trilinear / bilinear render s |")
    print("|---|---|---|---|---|---|")
    for spp in args.spp:
        row = {}
        for f in ("bilinear", "trilinear"):
            out = os.path.join(args.out, f"{f}-{spp}.exr")
            seconds = render(f, spp, spp, out)
            res = subprocess.run([args.ember, "compare", out, ref, "--json"], capture_output=True, text=True)
            metrics = json.loads(res.stdout)
            row[f] = (metrics["relmse_all"], metrics["flip_mean"], seconds)
        b, t = row["bilinear"], row["trilinear"]
        print(f"| {spp} | {b[0]:.5f} | {t[0]:.5f} | {b[1]:.4f} | {t[1]:.4f} | {t[2] / b[2]:.2f} |", flush=True)


if __name__ == "__main__":
    main()
