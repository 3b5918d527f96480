#!/usr/bin/env python3
"""Scenes that grow, for docs/performance.md: how samples/s, build time and memory scale with
scene size, Ember against Mitsuba 3 on the same meshes. The scenes are generated (only this
script is committed), into --out:

  mesh-1m     a floor and 100 UV spheres of 10,240 triangles each (1.02 M triangles, one glTF
              mesh) under a 1 x 1 area light
  emitters-10k  10,000 small emissive triangles (one glTF mesh, 10,000 triangle lights) above a
              floor and a diffuse sphere
  demo-1080p  scenes/demo.json at 1920 x 1080 (Ember only: its cone, Phong and mixed materials
              have no Mitsuba equivalent in benchmarks/mitsuba_scene.py)

Mitsuba gets the same triangles as PLY files, and both renderers the same materials: the JSON
scenes give the glTF meshes Ember's `diffuse` (the spheres white, the emitters black), as Mitsuba's
`diffuse` BSDFs, rather than the files' glTF metallic-roughness materials, whose specular lobe
Mitsuba's scenes do not have. Needs numpy, and mitsuba for the comparison:

    /tmp/mi/bin/python benchmarks/scaling_scenes.py --out /tmp/scaling            # write + run
    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /tmp/mi/bin/python \\
        benchmarks/scaling_scenes.py --out /tmp/scaling --spp 32 --mitsuba llvm_ad_rgb

Reported per scene: Ember's and Mitsuba's samples/s (render loop only, as compare_mitsuba.py),
their ratio, Ember's load+build seconds, Mitsuba's load_dict seconds, and Ember's resident
memory (RssAnon) per triangle above that of the small cornell-area scene.
"""
import argparse
import json
import math
import os
import re
import struct
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def uv_sphere(center, radius, n_phi=160, n_theta=32):
    """2 n_phi (n_theta - 1) triangles, outward winding, smooth normals."""
    theta = np.linspace(0.0, math.pi, n_theta + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, n_phi + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3)
    v = (np.asarray(center) + radius * n).astype(np.float32)
    idx = []
    w = n_phi + 1
    for i in range(n_theta):
        a = np.arange(n_phi) + i * w
        b, c, d = a + 1, a + w, a + w + 1
        if i > 0:
            idx.append(np.stack([a, c, b], -1))
        if i < n_theta - 1:
            idx.append(np.stack([b, c, d], -1))
    return v, n.astype(np.float32), np.concatenate(idx).astype(np.uint32)


def write_glb(path, vertices, normals, indices, emissive=None):
    """One mesh, one primitive, one material (white diffuse, or emissive with strength)."""
    blobs, views, accessors = bytearray(), [], []

    def add(array, gltf_type, component, target, minmax=False):
        while len(blobs) % 4:
            blobs.append(0)
        data = array.tobytes()
        views.append({"buffer": 0, "byteOffset": len(blobs), "byteLength": len(data), "target": target})
        blobs.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": int(array.shape[0]),
               "type": gltf_type}
        if minmax:
            acc["min"] = array.min(0).tolist()
            acc["max"] = array.max(0).tolist()
        accessors.append(acc)
        return len(accessors) - 1

    pos = add(vertices, "VEC3", 5126, 34962, True)
    nor = add(normals, "VEC3", 5126, 34962)
    ind = add(indices.reshape(-1), "SCALAR", 5125, 34963)
    material = {"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "metallicFactor": 0.0,
                                         "roughnessFactor": 1.0}}
    if emissive is not None:
        material = {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0},
                    "emissiveFactor": [1.0, 1.0, 1.0],
                    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": float(emissive)}}}
    doc = {"asset": {"version": "2.0", "generator": "ember benchmarks/scaling_scenes.py"},
           "extensionsUsed": ["KHR_materials_emissive_strength"] if emissive is not None else [],
           "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nor}, "indices": ind,
                                       "material": 0}]}],
           "materials": [material], "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(blobs)}]}
    if not doc["extensionsUsed"]:
        del doc["extensionsUsed"]
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    blobs.extend(b"\0" * (-len(blobs) % 4))
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blobs)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(blobs), 0x004E4942) + bytes(blobs))


def write_ply(path, vertices, indices, normals=None):
    with open(path, "wb") as f:
        props = "property float x\nproperty float y\nproperty float z\n"
        if normals is not None:
            props += "property float nx\nproperty float ny\nproperty float nz\n"
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n{props}"
                 f"element face {len(indices)}\nproperty list uchar uint vertex_indices\nend_header\n").encode())
        vert = vertices if normals is None else np.concatenate([vertices, normals], 1)
        f.write(np.ascontiguousarray(vert, dtype="<f4").tobytes())
        faces = np.zeros(len(indices), dtype=[("n", "u1"), ("i", "<u4", 3)])
        faces["n"] = 3
        faces["i"] = indices
        f.write(faces.tobytes())


CAMERA = {"origin": [0.0, 4.5, 9.0], "target": [0.0, 0.5, 0.0], "up": [0.0, 1.0, 0.0], "fov_y_deg": 40.0}
FLOOR = [[-6, 0, -6], [6, 0, -6], [6, 0, 6], [-6, 0, 6]]


def make_mesh_1m(out):
    parts = [uv_sphere((-4.5 + i, 0.45, -4.5 + j), 0.4) for i in range(10) for j in range(10)]
    offset, vs, ns, ids = 0, [], [], []
    for v, n, idx in parts:
        vs.append(v), ns.append(n), ids.append(idx + offset)
        offset += len(v)
    v, n, idx = np.concatenate(vs), np.concatenate(ns), np.concatenate(ids)
    write_glb(os.path.join(out, "spheres.glb"), v, n, idx)
    write_ply(os.path.join(out, "spheres.ply"), v, idx, n)
    scene = {"image": {"width": 256, "height": 256}, "camera": CAMERA,
             "render": {"spp": 16, "max_depth": -1, "rr_depth": 5},
             "materials": {"white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]}},
             "shapes": [{"type": "mesh", "file": "spheres.glb", "material": "white"},
                        {"type": "quad", "material": "white", "vertices": FLOOR},
                        {"type": "quad", "emission": [40, 40, 40],
                         "vertices": [[-0.5, 6, -0.5], [0.5, 6, -0.5], [0.5, 6, 0.5], [-0.5, 6, 0.5]]}]}
    with open(os.path.join(out, "mesh-1m.json"), "w") as f:
        json.dump(scene, f, indent=1)
    return len(idx)


def make_emitters_10k(out, n=100):
    # 100 x 100 small triangles facing down at height 4, spread over 8 x 8.
    rng = np.random.default_rng(5)
    cells = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    base = np.stack([-4 + 8 * (cells[:, 0] + 0.5) / n, np.full(len(cells), 4.0), -4 + 8 * (cells[:, 1] + 0.5) / n], -1)
    s = 8.0 / n * 0.4
    jitter = rng.uniform(-0.1, 0.1, (len(cells), 3)) * s
    a = base + jitter + [0, 0, -s]
    b = base + jitter + [s, 0, s]
    c = base + jitter + [-s, 0, s]
    v = np.stack([a, b, c], 1).reshape(-1, 3).astype(np.float32)  # winding (a, b, c) faces -y
    idx = np.arange(len(v), dtype=np.uint32).reshape(-1, 3)
    nrm = np.tile(np.array([0, -1, 0], np.float32), (len(v), 1))
    write_glb(os.path.join(out, "emitters.glb"), v, nrm, idx, emissive=3.0)
    write_ply(os.path.join(out, "emitters.ply"), v, idx)
    scene = {"image": {"width": 256, "height": 256}, "camera": CAMERA,
             "render": {"spp": 16, "max_depth": -1, "rr_depth": 5},
             "materials": {"white": {"type": "diffuse", "reflectance": [0.7, 0.7, 0.7]},
                           "black": {"type": "diffuse", "reflectance": [0.0, 0.0, 0.0]}},
             "shapes": [{"type": "mesh", "file": "emitters.glb", "material": "black"},
                        {"type": "quad", "material": "white", "vertices": FLOOR},
                        {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "white"}]}
    with open(os.path.join(out, "emitters-10k.json"), "w") as f:
        json.dump(scene, f, indent=1)
    return len(idx)


def mitsuba_dict(name, out, spp):
    import mitsuba as mi
    T = mi.ScalarTransform4f
    white = {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.7] * 3}}}
    floor = {"type": "rectangle", "to_world": T.scale([6, 1, 6]) @ T.rotate([1, 0, 0], -90), "bsdf": white}
    scene = {"type": "scene",
             "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
             "sensor": {"type": "perspective", "fov": 40.0, "fov_axis": "y",
                        "to_world": T.look_at(origin=CAMERA["origin"], target=CAMERA["target"], up=CAMERA["up"]),
                        "film": {"type": "hdrfilm", "width": 256, "height": 256, "rfilter": {"type": "box"}},
                        "sampler": {"type": "independent", "sample_count": spp}},
             "floor": floor}
    if name == "mesh-1m":
        scene["spheres"] = {"type": "ply", "filename": os.path.join(out, "spheres.ply"), "bsdf": white}
        scene["light"] = {"type": "rectangle", "to_world": T.translate([0, 6, 0]) @ T.scale(0.5) @ T.rotate([1, 0, 0], 90),
                          "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [40] * 3}}}
    else:
        black = {"type": "twosided", "material": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0] * 3}}}
        scene["emitters"] = {"type": "ply", "filename": os.path.join(out, "emitters.ply"), "bsdf": black,
                             "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [3] * 3}}}
        scene["sphere"] = {"type": "sphere", "center": [0, 1, 0], "radius": 1.0, "bsdf": white}
    return scene


def ember_bench(ember, scene, spp, width=None, height=None):
    """Ember's figures from `ember bench --json` (one render; with a size override via render)."""
    if width:
        run = subprocess.run([ember, "render", scene, "-o", "/tmp/ember_scaling.exr", "--spp", str(spp), "-q",
                              "--width", str(width), "--height", str(height)], check=True, stderr=subprocess.PIPE,
                             text=True)
        m = re.search(r"load\+build ([0-9.]+) s, render ([0-9.]+) s", run.stderr)
        return {"build_seconds": float(m.group(1)), "render_seconds_median": float(m.group(2)),
                "samples_per_second": width * height * spp / float(m.group(2)), "anonymous_resident_mb": None}
    out = "/tmp/ember_scaling.json"
    subprocess.run([ember, "bench", scene, "--spp", str(spp), "--repeat", "1", "--json", out], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(out) as f:
        row = json.load(f)["scenes"][0]
    row["build_seconds"] = row["load_seconds"] + row["build_seconds"]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="folder for the generated scenes")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--ember", default=os.path.join(ROOT, "build", "app", "ember"))
    ap.add_argument("--mitsuba", help="a Mitsuba variant (llvm_ad_rgb) to compare with")
    ap.add_argument("--json", help="also write the raw numbers here")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    triangles = {"mesh-1m": make_mesh_1m(args.out), "emitters-10k": make_emitters_10k(args.out)}

    small = ember_bench(args.ember, os.path.join(ROOT, "scenes", "cornell-area.json"), args.spp)
    rows = [{"scene": "cornell-area (small)", "triangles": 0, "ember": small}]
    for name in ("mesh-1m", "emitters-10k"):
        rows.append({"scene": name, "triangles": triangles[name],
                     "ember": ember_bench(args.ember, os.path.join(args.out, name + ".json"), args.spp)})
    rows.append({"scene": "demo-1080p", "triangles": 0,
                 "ember": ember_bench(args.ember, os.path.join(ROOT, "scenes", "demo.json"), max(1, args.spp // 8),
                                      1920, 1080)})
    rows.insert(1, {"scene": "demo (256 x 256)", "triangles": 0,
                    "ember": ember_bench(args.ember, os.path.join(ROOT, "scenes", "demo.json"), args.spp, 256, 256)})

    if args.mitsuba:
        import mitsuba as mi
        mi.set_variant(args.mitsuba)
        mi.set_log_level(mi.LogLevel.Error)
        sys.path.insert(0, HERE)
        import mitsuba_scene
        for r in rows:
            name = r["scene"]
            if name.startswith("demo"):
                continue
            t = time.perf_counter()
            if name.startswith("cornell"):
                scene = mitsuba_scene.build(os.path.join(ROOT, "tests", "data", "cornell-area", "scene.json"), args.spp)
            else:
                scene = mi.load_dict(mitsuba_dict(name, args.out, args.spp))
            load = time.perf_counter() - t
            np.array(mi.render(scene, spp=1))  # JIT warm-up, not timed (np.array forces evaluation)
            t = time.perf_counter()
            np.array(mi.render(scene, spp=args.spp))
            seconds = time.perf_counter() - t
            r["mitsuba"] = {"load_seconds": load, "samples_per_second": 256 * 256 * args.spp / seconds}

    base = rows[0]["ember"]
    print("| scene | triangles | Ember Msamples/s | vs its small scene | Mitsuba Msamples/s | Ember / Mitsuba | "
          "Ember load+build s | Mitsuba load s | Ember bytes/triangle |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        e = r["ember"]
        m = r.get("mitsuba")
        mem = ""
        if r["triangles"] and e.get("anonymous_resident_mb") is not None:
            mem = f"{(e['anonymous_resident_mb'] - base['anonymous_resident_mb']) * 2**20 / r['triangles']:.0f}"
        cells = [r["scene"], f"{r['triangles']:,}", f"{e['samples_per_second'] / 1e6:.3f}",
                 f"{e['samples_per_second'] / base['samples_per_second']:.2f}",
                 f"{m['samples_per_second'] / 1e6:.3f}" if m else "—",
                 f"{e['samples_per_second'] / m['samples_per_second']:.2f}" if m else "—",
                 f"{e['build_seconds']:.2f}", f"{m['load_seconds']:.2f}" if m else "—", mem]
        print("| " + " | ".join(cells) + " |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
