#!/usr/bin/env python3
"""A texture set larger than the texture cache: N float .tx files (RGB, tiled, MIP-mapped, made by
OpenImageIO's maketx through oiiotool) on N quads seen by the camera, rendered with
"filter": "trilinear" (looked up straight from the files, tile by tile, within
EMBER_TEXTURE_CACHE_MB) and with "filter": "bilinear" (every texel decoded into memory first).
Prints a Markdown table of peak resident memory, load-and-build time and render time
(docs/performance.md).

  python3 benchmarks/texture_cache.py --ember build/app/ember [--count 8] [--size 4096] [--cache-mb 256 64]

Needs oiiotool (Debian: openimageio-tools) to write the textures.
"""
import argparse
import json
import os
import re
import subprocess
import time


def make_textures(out, count, size):
    paths = []
    for k in range(count):
        path = os.path.join(out, f"noise-{size}-{k}.tx")
        if not os.path.exists(path):
            subprocess.run(["oiiotool", "--pattern", f"noise:type=uniform:min=0.05:max=0.95:seed={k + 1}",
                            f"{size}x{size}", "3", "--otex", path], check=True)
        paths.append(path)
    return paths


def scene(paths, filter_name):
    cols = 4
    rows = (len(paths) + cols - 1) // cols
    materials, shapes = {}, []
    for k, path in enumerate(paths):
        materials[f"m{k}"] = {"type": "diffuse", "reflectance": {"texture": path, "filter": filter_name}}
        x, z = (k % cols) * 1.1 - 0.55 * (cols - 1), (k // cols) * 1.1 - 0.55 * (rows - 1)
        shapes.append({"type": "quad", "material": f"m{k}",
                       "vertices": [[x - 0.5, 0, z + 0.5], [x + 0.5, 0, z + 0.5], [x + 0.5, 0, z - 0.5],
                                    [x - 0.5, 0, z - 0.5]]})
    return {"image": {"width": 640, "height": 360},
            "camera": {"origin": [0, 2.6, 2.2], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 50},
            "render": {"max_depth": 3, "background": [1, 1, 1]},
            "materials": materials, "shapes": shapes}


def run(ember, scene_path, out, spp, cache_mb):
    env = dict(os.environ)
    if cache_mb:
        env["EMBER_TEXTURE_CACHE_MB"] = str(cache_mb)
    cmd = ["/usr/bin/time", "-f", "%M", ember, "render", scene_path, "-o", out, "--spp", str(spp), "--threads", "2"]
    t = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t
    peak_kb = int(p.stderr.strip().splitlines()[-1])
    m = re.search(r"load\+build ([0-9.]+) s, render ([0-9.]+) s", p.stderr)
    return peak_kb / 1024.0, float(m.group(1)), float(m.group(2)), wall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--count", type=int, default=8)
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--cache-mb", type=float, nargs="+", default=[256, 64])
    ap.add_argument("--out", default="/tmp/ember-texture-cache")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    paths = make_textures(a.out, a.count, a.size)
    on_disk = sum(os.path.getsize(p) for p in paths) / 2**20
    texel_mb = a.count * a.size * a.size * 3 * 4 * 4 / 3 / 2**20  # float RGB, with the MIP levels
    print(f"{a.count} textures of {a.size}x{a.size} float RGB: {texel_mb:.0f} MB of texels with their MIP "
          f"levels, {on_disk:.0f} MB on disk\n")
    print("| filter | texture cache | peak resident MB | load+build s | render s |")
    print("|---|---|---|---|---|")
    cases = [("trilinear", mb) for mb in a.cache_mb] + [("bilinear", None)]
    for filter_name, mb in cases:
        path = os.path.join(a.out, f"scene-{filter_name}.json")
        with open(path, "w") as f:
            json.dump(scene(paths, filter_name), f)
        peak, load, render, _ = run(a.ember, path, os.path.join(a.out, f"{filter_name}.exr"), a.spp, mb)
        cache = f"{mb:g} MB" if mb else "none (decoded into memory)"
        print(f"| {filter_name} | {cache} | {peak:.0f} | {load:.2f} | {render:.2f} |", flush=True)


if __name__ == "__main__":
    main()
