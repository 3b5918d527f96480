"""The Python module's edits: an edit, then a render, against loading the scene again, then the same
render (issue 47). `import ember` to the first image: benchmarks/python_vs_mitsuba.py.

    .venv/bin/python benchmarks/python_edits.py [--repeats 7] [--gltf FILE ...]

Each cell is the median of --repeats runs in this process (scenes loaded before timing, so file
caches are warm for both sides)."""
import argparse
import json
import os
import statistics
import time

import ember

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "scenes")


def median_seconds(run, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def edits_of(path):
    """(name, edit) pairs that apply to the scene at path, each undone by the next call's values."""
    flip = {"n": 0}

    def toggled(a, b):
        flip["n"] += 1
        return a if flip["n"] % 2 else b

    scene = ember.load(path)
    doc = scene.document if scene._handle.is_json else None
    camera = scene.info()["camera"]
    edits = [("camera", lambda s: s.set_camera(fov=toggled(camera.get("fov_y_deg", 40) * 0.9,
                                                            camera.get("fov_y_deg", 40))))]
    if doc is None:  # a glTF file: its first material becomes a JSON diffuse one
        name = scene.info()["materials"][0]["name"]
        edits.append(("material", lambda s: s.set_material(name, type="diffuse",
                                                            reflectance=toggled(0.3, 0.6))))
        return edits
    name, material = next(iter(doc["materials"].items()))
    if material["type"] in ("diffuse", "lambertian"):
        edits.append(("material", lambda s: s.set_material(name, reflectance=toggled(0.3, 0.6))))
    for i, shape in enumerate(doc["shapes"]):
        if shape["type"] == "sphere":
            c = shape["center"]
            edits.append(("move a sphere", lambda s, i=i, c=c: s.set_shape(
                i, center=[c[0], toggled(c[1] + 0.1, c[1]), c[2]])))
            break
    for i, shape in enumerate(doc["shapes"]):
        if shape.get("emission"):
            e = shape["emission"]
            edits.append(("emission", lambda s, i=i, e=e: s.set_shape(i, emission=toggled(
                [0.5 * x for x in e] if isinstance(e, list) else 0.5 * e, e))))
            break
    for i, shape in enumerate(doc["shapes"]):
        if shape["type"] == "mesh" and "transform" in shape:
            t = dict(shape["transform"])
            moved = dict(t, translate=[x + 0.1 for x in t.get("translate", [0, 0, 0])])
            try:
                scene.set_shape(i, transform=moved)
                scene.set_shape(i, transform=t)
            except ember.SceneError:
                continue  # baked into world space: not an edit the module makes
            edits.append(("move instanced meshes", lambda s, i=i: s.set_shape(i, transform=toggled(moved, t))))
            break
    if doc.get("lights"):
        light = doc["lights"][0]
        key = "irradiance" if light["type"] == "directional" else "intensity"
        v = light[key]
        edits.append(("light", lambda s: s.set_light(0, **{key: toggled(v * 0.5 if not isinstance(v, list)
                                                                          else [x * 0.5 for x in v], v)})))
    return edits


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--gltf", nargs="*", default=[])
    parser.add_argument("--json", help="also write the results here")
    args = parser.parse_args()
    results = {"edits": []}

    print(f"\n{'scene':<22} {'edit':<22} {'edit ms':>9} {'reload ms':>10} {'ratio':>7} "
          f"{'edit+1spp ms':>13} {'reload+1spp ms':>15}")
    paths = [os.path.join(SCENES, s) for s in ("cornell-area.json", "cornell-point.json", "gltf-mixed.json")]
    for path in paths + args.gltf:
        scene = ember.load(path)
        reload_s = median_seconds(lambda: ember.load(path), args.repeats)
        reload_render = median_seconds(lambda: ember.load(path).render(spp=1), args.repeats)
        for name, edit in edits_of(path):
            edit_s = median_seconds(lambda: edit(scene), args.repeats)
            edit_render = median_seconds(lambda: (edit(scene), scene.render(spp=1)), args.repeats)
            label = os.path.basename(path)
            print(f"{label:<22} {name:<22} {1e3 * edit_s:9.3f} {1e3 * reload_s:10.3f} {reload_s / edit_s:6.0f}x "
                  f"{1e3 * edit_render:13.1f} {1e3 * reload_render:15.1f}")
            results["edits"].append({"scene": label, "edit": name, "edit_s": edit_s, "reload_s": reload_s,
                                     "edit_render_1spp_s": edit_render, "reload_render_1spp_s": reload_render})
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
