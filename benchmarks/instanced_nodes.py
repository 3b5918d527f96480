#!/usr/bin/env python3
"""Instancing at scale: writes a glTF file that places one UV sphere of 10,000 triangles at
10,000 nodes (100 M placed triangles), renders it with Ember at 1920x1080, and reports the peak
resident memory and the load-and-build time (docs/performance.md, "Instancing").

    python3 benchmarks/instanced_nodes.py --ember build/app/ember [--nodes 10000] [--spp 1]
"""
import argparse
import base64
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_mesh import uv_sphere  # noqa: E402


def sphere(rings, segments):
    return uv_sphere((0.0, 0.0, 0.0), 0.4, rings, segments)


def write_gltf(path, nodes, rings=50, segments=100):
    positions, normals, indices = sphere(rings, segments)
    blob = struct.pack(f"<{len(positions)}f", *positions) + struct.pack(f"<{len(normals)}f", *normals)
    blob += struct.pack(f"<{len(indices)}I", *indices)
    pos_bytes = 4 * len(positions)
    side = math.ceil(math.sqrt(nodes))
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos_bytes},
                        {"buffer": 0, "byteOffset": pos_bytes, "byteLength": pos_bytes},
                        {"buffer": 0, "byteOffset": 2 * pos_bytes, "byteLength": 4 * len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions) // 3, "type": "VEC3",
                       "min": [-0.4, -0.4, -0.4], "max": [0.4, 0.4, 0.4]},
                      {"bufferView": 1, "componentType": 5126, "count": len(normals) // 3, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5125, "count": len(indices), "type": "SCALAR"}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0.0,
                                                "roughnessFactor": 0.5}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "nodes": [{"mesh": 0, "translation": [float(k % side), 0.0, float(k // side)]} for k in range(nodes)],
        "scenes": [{"nodes": list(range(nodes))}],
        "scene": 0,
    }
    with open(path, "w") as f:
        json.dump(doc, f)
    return len(indices) // 3


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ember", default="build/app/ember")
    ap.add_argument("--nodes", type=int, default=10000)
    ap.add_argument("--spp", type=int, default=1)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        gltf = os.path.join(tmp, "instanced.gltf")
        triangles = write_gltf(gltf, args.nodes)
        cmd = ["/usr/bin/time", "-f", "peak_kb %M", args.ember, "render", gltf, "-o", os.path.join(tmp, "out.exr"),
               "--width", "1920", "--height", "1080", "--spp", str(args.spp)]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(run.stderr)
        peak_mb = int(re.search(r"peak_kb (\d+)", run.stderr).group(1)) / 1024.0
        build = re.search(r"load\+build ([0-9.]+) s", run.stderr).group(1)
        summary = [line for line in run.stderr.splitlines() if "load+build" in line][-1]
        print(f"mesh: {triangles} triangles, placed at {args.nodes} nodes = {triangles * args.nodes / 1e6:.0f} M triangles")
        print(f"1920x1080, {args.spp} spp: peak {peak_mb:.0f} MB, load+build {build} s")
        print(summary)


if __name__ == "__main__":
    main()
