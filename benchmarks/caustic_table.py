#!/usr/bin/env python3
"""Caustics of glTF glass at equal time: a smooth glass sphere (KHR_materials_transmission and
_volume, roughness 0) on a table, lit once by an emissive mesh (a small emissive quad,
KHR_materials_emissive_strength) and once by a KHR_lights_punctual spot light. Each is rendered
for the same time budget with the light tracer (--caustics trace) and without it (--caustics path),
and compared against a long light-traced reference (relMSE as in compare_mitsuba.py). Prints a
Markdown table (docs/performance.md).

  python3 benchmarks/caustic_table.py --ember build/app/ember [--seconds 10 30] [--ref-seconds 600]

Needs numpy and OpenEXR (the Mitsuba venv of docs/performance.md has both).
"""
import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np
import OpenEXR

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from exr import load_exr  # noqa: E402
from gltf_mesh import uv_sphere  # noqa: E402


def relmse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01)))


class Gltf:
    """A glTF document with its binary data embedded, built mesh by mesh."""

    def __init__(self):
        self.blob = b""
        self.doc = {"asset": {"version": "2.0"}, "bufferViews": [], "accessors": [], "materials": [],
                    "meshes": [], "nodes": [], "extensionsUsed": []}

    def _view(self, fmt, values, count, kind, component, bounds=None):
        data = struct.pack(f"<{len(values)}{fmt}", *values)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)})
        self.blob += data
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component, "count": count,
               "type": kind}
        if bounds:
            acc["min"], acc["max"] = bounds
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, positions, normals, indices, material):
        xs = [positions[i::3] for i in range(3)]
        p = self._view("f", positions, len(positions) // 3, "VEC3", 5126,
                       ([min(x) for x in xs], [max(x) for x in xs]))
        n = self._view("f", normals, len(normals) // 3, "VEC3", 5126)
        i = self._view("I", indices, len(indices), "SCALAR", 5125)
        self.doc["materials"].append(material)
        self.doc["meshes"].append({"primitives": [{"attributes": {"POSITION": p, "NORMAL": n}, "indices": i,
                                                   "material": len(self.doc["materials"]) - 1}]})
        self.doc["nodes"].append({"mesh": len(self.doc["meshes"]) - 1})

    def quad(self, corners, normal, material):
        """Corners counter-clockwise seen from the side `normal` points to."""
        self.mesh([c for v in corners for c in v], list(normal) * 4, [0, 1, 2, 0, 2, 3], material)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()}]
        self.doc["scenes"] = [{"nodes": list(range(len(self.doc["nodes"])))}]
        self.doc["scene"] = 0
        with open(path, "w") as f:
            json.dump(self.doc, f)


def diffuse(c):
    return {"pbrMetallicRoughness": {"baseColorFactor": [c, c, c, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}}


def write_scene(path, light):
    g = Gltf()
    g.doc["extensionsUsed"] = ["KHR_materials_transmission", "KHR_materials_volume"]
    g.quad([(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], (0, 1, 0), diffuse(0.75))    # the table
    g.quad([(-3, 0, -1.5), (3, 0, -1.5), (3, 3, -1.5), (-3, 3, -1.5)], (0, 0, 1), diffuse(0.5))  # a wall
    glass = {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 0.0},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                            "KHR_materials_volume": {"thicknessFactor": 0.8}}}
    g.mesh(*uv_sphere((0.0, 0.4, 0.0), 0.4, 64, 128), glass)
    top = (-0.9, 1.6, -0.3)
    if light == "mesh":
        g.doc["extensionsUsed"].append("KHR_materials_emissive_strength")
        s = 0.12
        emissive = {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
                    "emissiveFactor": [1, 0.9, 0.8],
                    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 60.0}}}
        x, y, z = top
        g.quad([(x - s, y, z - s), (x + s, y, z - s), (x + s, y, z + s), (x - s, y, z + s)], (0, -1, 0), emissive)
    else:
        g.doc["extensionsUsed"].append("KHR_lights_punctual")
        g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "color": [1, 0.9, 0.8], "intensity": 600.0,
             "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.45}}]}}
        # The spot looks down its -z axis: turn it from the light towards the sphere's centre.
        d = [0.0 - top[0], 0.4 - top[1], 0.0 - top[2]]
        length = math.sqrt(sum(c * c for c in d))
        d = [c / length for c in d]
        axis = [d[1], -d[0], 0.0]  # (-z) x d, normalised below
        s = math.sqrt(sum(c * c for c in axis))
        angle = math.acos(-d[2])
        q = [a / s * math.sin(angle / 2) for a in axis] + [math.cos(angle / 2)]
        g.doc["nodes"].append({"translation": list(top), "rotation": q, "extensions": {"KHR_lights_punctual": {"light": 0}}})
    # The camera, looking at the sphere from the front and above.
    eye, target = (0.0, 1.5, 2.4), (0.0, 0.25, -0.2)
    f = [t - e for t, e in zip(target, eye)]
    fl = math.sqrt(sum(c * c for c in f))
    pitch = math.asin(f[1] / fl)
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.01, "aspectRatio": 4 / 3}}]
    g.doc["nodes"].append({"camera": 0, "translation": list(eye),
                           "rotation": [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]})
    g.write(path)


def render(ember, scene, out, caustics, seconds, seed, width, height):
    cmd = [ember, "render", scene, "-o", out, "--caustics", caustics, "--time", f"{seconds}s",
           "--spp", "16777216", "--seed", str(seed), "--width", str(width), "--height", str(height),
           "--env", "none", "--threads", "2"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with OpenEXR.File(out) as f:
        spp = f.header()["ember:spp"]
    return load_exr(out), spp


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--seconds", type=float, nargs="+", default=[10, 30])
    ap.add_argument("--ref-seconds", type=float, default=600)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--lights", nargs="+", default=["mesh", "spot"], choices=["mesh", "spot"])
    ap.add_argument("--out", default="/tmp/ember-caustics")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print("| light | seconds | trace: spp | trace relMSE | path: spp | path relMSE | path / trace relMSE |")
    print("|---|---|---|---|---|---|---|")
    for light in a.lights:
        scene = os.path.join(a.out, f"glass-{light}.gltf")
        write_scene(scene, light)
        ref_path = os.path.join(a.out, f"ref-{light}.exr")
        if not os.path.exists(ref_path):
            render(a.ember, scene, ref_path, "trace", a.ref_seconds, 1000, a.width, a.height)
        ref = load_exr(ref_path)
        for seconds in a.seconds:
            cells = []
            for k, caustics in enumerate(("trace", "path")):
                img, spp = render(a.ember, scene, os.path.join(a.out, f"{light}-{caustics}-{seconds:g}.exr"),
                                  caustics, seconds, 1 + k, a.width, a.height)
                cells.append((spp, relmse(img, ref)))
            (ts, te), (ps, pe) = cells
            print(f"| {light} | {seconds:g} | {ts} | {te:.3g} | {ps} | {pe:.3g} | {pe / te:.1f} |", flush=True)


if __name__ == "__main__":
    main()
