"""`import` to the first image, and an edit then a render, in Ember's Python module and in Mitsuba 3's
(`llvm_ad_rgb`, whose kernels are compiled on first use and cached), on cornell-area at 256x256 and
1 spp. Each side runs in fresh interpreters (median of --repeats).

    DRJIT_LIBLLVM_PATH=... python benchmarks/python_vs_mitsuba.py --ember-python .venv/bin/python \\
        --mitsuba-python /tmp/mi/bin/python"""
import argparse
import json
import os
import statistics
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

EMBER = """
import json, time
t0 = time.perf_counter()
import ember
t1 = time.perf_counter()
scene = ember.load({scene!r})
t2 = time.perf_counter()
scene.render(spp=1)
t3 = time.perf_counter()
scene.set_camera(fov=35)
scene.render(spp=1)
t4 = time.perf_counter()
scene.set_material("glass", ior_inside=1.7)
scene.render(spp=1)
t5 = time.perf_counter()
print(json.dumps([t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4]))
"""

MITSUBA = """
import json, sys, time
t0 = time.perf_counter()
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
t1 = time.perf_counter()
sys.path.insert(0, {bench!r})
import mitsuba_scene
scene = mitsuba_scene.build({spec!r}, 1)
t2 = time.perf_counter()
mi.render(scene, spp=1).numpy()
t3 = time.perf_counter()
params = mi.traverse(scene)
params["sensor.x_fov"] = 35.0
params.update()
mi.render(scene, spp=1).numpy()
t4 = time.perf_counter()
key = [k for k in params.keys() if k.endswith("bsdf.eta")][0]
params[key] = 1.7
params.update()
mi.render(scene, spp=1).numpy()
t5 = time.perf_counter()
print(json.dumps([t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4]))
"""


def runs(python, code, repeats):
    rows = []
    for _ in range(repeats):
        out = subprocess.run([python, "-c", code], capture_output=True, text=True, check=True).stdout
        rows.append(json.loads(out.strip().splitlines()[-1]))
    return [statistics.median(c) for c in zip(*rows)]


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--ember-python", required=True)
    parser.add_argument("--mitsuba-python", required=True)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    ember = runs(args.ember_python, EMBER.format(scene=os.path.join(ROOT, "scenes", "cornell-area.json")),
                 args.repeats)
    mitsuba = runs(args.mitsuba_python, MITSUBA.format(bench=os.path.join(ROOT, "benchmarks"),
                                                       spec=os.path.join(ROOT, "tests", "data", "cornell-area",
                                                                         "scene.json")), args.repeats)
    names = ["import", "load", "first 1-spp image", "camera edit + 1 spp", "IOR edit + 1 spp"]
    print(f"{'step (s)':<22} {'Ember':>8} {'Mitsuba 3':>10} {'ratio':>7}")
    for name, e, m in zip(names, ember, mitsuba):
        print(f"{name:<22} {e:8.3f} {m:10.3f} {m / e:6.1f}x")
    e, m = sum(ember[:3]), sum(mitsuba[:3])
    print(f"{'import to first image':<22} {e:8.3f} {m:10.3f} {m / e:6.1f}x")


if __name__ == "__main__":
    main()
