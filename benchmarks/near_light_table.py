#!/usr/bin/env python3
"""Direct light next to emitters, the measurement of issue 9, as a table: a Lambertian ceiling
(reflectance 0.5, facing down) and one emitter of radiance 1 below it; a camera with a 0.01 degree
field of view, 2 away and 15 degrees below the ceiling (on the side away from the flat emitters),
looks at the ceiling point above the emitter; direct light only (max_depth 2). Each case is
rendered with every strategy and set beside its closed form where there is one: the sphere on its
axis (rho (r/d)^2), and quads and discs (as 720-gons) by Lambert's contour integral,
E = 1/2 sum Theta_i (n . Gamma_i), clipped to the horizon. Without one (the capped cylinder) the bsdf strategy is the unbiased yardstick.

    python3 benchmarks/near_light_table.py build/app/ember [--spp 4096] [--old /path/to/old/ember]

`--old` adds a column for another binary (one without --strategy renders its only estimator, mis).
Needs only the Python standard library (image means come from `ember compare --json`)."""
import argparse
import json
import math
import os
import subprocess
import tempfile

RHO = 0.5


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def polygon_irradiance(poly):
    """Irradiance at the origin (normal -y) from a polygon of radiance 1 facing it."""
    clipped = []
    for i, a in enumerate(poly):
        b = poly[(i + 1) % len(poly)]
        if a[1] < 0:
            clipped.append(a)
        if (a[1] < 0) != (b[1] < 0):
            t = a[1] / (a[1] - b[1])
            clipped.append([a[k] + (b[k] - a[k]) * t for k in range(3)])
    total = 0.0
    for i, a in enumerate(clipped):
        ua, ub = normalize(a), normalize(clipped[(i + 1) % len(clipped)])
        c = cross(ua, ub)
        length = math.sqrt(dot(c, c))
        if length > 0:
            total += math.atan2(length, dot(ua, ub)) * (-c[1] / length)
    return 0.5 * abs(total)


def disc_polygon(center, normal, radius, n=720):
    # Circumscribed-area-preserving n-gon: scale the vertices so its area equals the disc's.
    scale = radius * math.sqrt(2 * math.pi / (n * math.sin(2 * math.pi / n)))
    helper = [0, 1, 0] if abs(normal[1]) < 0.9 else [1, 0, 0]
    s = normalize(cross(normal, helper))
    t = cross(normal, s)
    return [[center[k] + scale * (math.cos(2 * math.pi * i / n) * s[k] + math.sin(2 * math.pi * i / n) * t[k])
             for k in range(3)] for i in range(n)]


def cases():
    out = []
    for r, gap in [(0.15, 0.05), (0.1, 0.02), (0.1, 0.005), (0.15, 0.35)]:
        d = r + gap
        out.append((f"sphere r {r}, gap {gap}",
                    {"type": "sphere", "center": [0, -d, 0], "radius": r}, RHO * (r / d) ** 2))
    out.append(("capped cylinder r 0.1, gap 0.05",
                {"type": "cylinder", "p0": [0, -0.15, -0.2], "p1": [0, -0.15, 0.2], "radius": 0.1}, None))
    for gap in [0.005, 0.02]:
        quad = [[0.05, -gap, -0.2], [0.05, -0.3, -0.2], [0.05, -0.3, 0.2], [0.05, -gap, 0.2]]
        out.append((f"vertical quad beside, top {gap} below (grazing)", {"type": "quad", "vertices": quad},
                    RHO / math.pi * polygon_irradiance(quad)))
        center, normal, radius = [0.05, -gap - 0.15, 0.0], [-1, 0, 0], 0.15
        out.append((f"vertical disc beside, top {gap} below (grazing)",
                    {"type": "disc", "center": center, "normal": normal, "radius": radius},
                    RHO / math.pi * polygon_irradiance(disc_polygon(center, normal, radius))))
    return out


def scene(emitter, spp, strategy):
    render = {"spp": spp, "max_depth": 2, "seed": 1}
    if strategy:
        render["strategy"] = strategy
    emitter = dict(emitter, emission=[1, 1, 1])
    return {
        "image": {"width": 4, "height": 4},
        "camera": {"origin": [-2, -0.54, 0.3], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 0.01},
        "render": render,
        "materials": {"ceiling": {"type": "diffuse", "reflectance": RHO}},
        "shapes": [{"type": "quad", "material": "ceiling",
                    "vertices": [[-10, 0, -10], [10, 0, -10], [10, 0, 10], [-10, 0, 10]]}, emitter],
    }


def average(ember, path):
    # The image against itself: the comparison's mean of each channel, at full double precision.
    out = subprocess.run([ember, "compare", path, path, "--json"], capture_output=True, text=True, check=True).stdout
    means = json.loads(out)["mean_image"]
    return sum(means) / len(means)


def measure(ember, emitter, spp, strategy, tmp):
    path = os.path.join(tmp, "s.json")
    with open(path, "w") as f:
        json.dump(scene(emitter, spp, strategy), f)
    args = [ember, "render", path, "-o", os.path.join(tmp, "m.exr"), "--variance", os.path.join(tmp, "v.exr"),
            "--sampler", "independent", "-q"]
    subprocess.run(args, check=True, capture_output=True)
    # Mean of the 16 pixel means, and its standard error from their variances.
    return average(ember, os.path.join(tmp, "m.exr")), math.sqrt(average(ember, os.path.join(tmp, "v.exr")) / 16)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ember")
    ap.add_argument("--old", help="another ember binary for a 'before' column (mis only)")
    ap.add_argument("--spp", type=int, default=4096)
    a = ap.parse_args()
    columns = ([("before (mis)", a.old, None)] if a.old else []) + [
        ("mis", a.ember, "mis"), ("bsdf", a.ember, "bsdf"), ("light", a.ember, "light")]
    print("| case | closed form | " + " | ".join(c[0] for c in columns) + " |")
    print("|---" * (len(columns) + 2) + "|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, emitter, exact in cases():
            cells, values = [], {}
            for name, binary, strategy in columns:
                mean, err = measure(binary, emitter, a.spp, strategy, tmp)
                values[name] = mean
                cells.append((mean, err))
            ref = exact if exact is not None else values["bsdf"]
            text = []
            for mean, err in cells:
                text.append(f"{mean:.5f} ± {err:.5f} ({100 * (mean / ref - 1):+.2f}%)")
            print(f"| {label} | " + (f"{exact:.5f}" if exact is not None else "— (vs bsdf)") + " | " +
                  " | ".join(text) + " |", flush=True)


if __name__ == "__main__":
    main()
