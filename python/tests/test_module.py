"""The ember Python module against the command line it shares its code with (docs/python.md)."""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import OpenEXR
import pytest

import ember

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = os.path.join(ROOT, "scenes")
CORNELL = os.path.join(SCENES, "cornell-area.json")
MIXED = os.path.join(SCENES, "gltf-mixed.json")
EMBER = os.environ.get("EMBER_BINARY", os.path.join(ROOT, "build", "app", "ember"))


def openexr_rgb(path):
    """The EXR's colour as a reader that shares no code with Ember reads it."""
    with OpenEXR.File(str(path)) as f:
        return np.array(f.channels()["RGB"].pixels, dtype=np.float32)


def small(path=CORNELL, size=64):
    """A JSON scene at a small size, as a dict."""
    with open(path) as f:
        doc = json.load(f)
    doc["image"] = {"width": size, "height": size}
    return doc


# --- the same renderer ------------------------------------------------------------------------

def test_the_image_equals_ember_renders_bit_for_bit(tmp_path):
    out = tmp_path / "cli.exr"
    subprocess.run([EMBER, "render", CORNELL, "-o", str(out), "--spp", "8", "--seed", "3", "-q"], check=True)
    image = ember.load(CORNELL).render(spp=8, seed=3)
    assert image.shape == (256, 256, 3) and image.dtype == np.float32
    assert isinstance(image, ember.Image) and image.metadata["spp"] == 8
    assert np.array_equal(image, openexr_rgb(out))
    # ... and the test can tell: another seed is another image.
    assert not np.array_equal(ember.load(CORNELL).render(spp=8, seed=4), image)


def test_strategy_first_sample_and_aovs_equal_the_command_line(tmp_path):
    out = tmp_path / "cli.exr"
    subprocess.run([EMBER, "render", CORNELL, "-o", str(out), "--spp", "4", "--first-sample", "8", "--strategy",
                    "light", "--aov", "all", "--width", "64", "--height", "48", "-q"], check=True)
    doc = small()
    doc["image"] = {"width": 64, "height": 48}
    image, aovs = ember.load(doc, base_dir=SCENES).render(spp=4, first_sample=8, strategy="light", aovs=["all"])
    assert np.array_equal(image, openexr_rgb(out))
    written = ember.read_exr(out)
    assert np.array_equal(written, image)
    assert set(aovs) == {"albedo", "normal", "depth", "position", "uv", "coverage", "variance", "spp"}
    assert set(written.layers) == set(aovs)
    for name, array in aovs.items():
        assert array.dtype == np.float32 and array.shape[:2] == (48, 64)
        assert np.array_equal(array, written.layers[name]), name
    assert aovs["normal"].shape == (48, 64, 3) and aovs["depth"].shape == (48, 64)
    assert written.metadata["ember:strategy"] == "light"
    assert not np.array_equal(ember.load(doc, base_dir=SCENES).render(spp=4, first_sample=8), image)


# --- the GIL, progress, Ctrl-C ----------------------------------------------------------------

def test_rendering_releases_the_gil():
    scene = ember.load(CORNELL)
    stamps = []
    done = threading.Event()

    def count():
        while not done.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        start = time.perf_counter()
        scene.render(spp=64)
        end = time.perf_counter()
    finally:
        done.set()
        t.join()
    # Python ran in the other thread while render() was inside the renderer, not only around it.
    assert end - start > 0.2
    inside = [s for s in stamps if start + 0.05 < s < end - 0.05]
    assert len(inside) > 10


def test_progress_reports_passes_up_to_the_end():
    calls = []
    ember.load(small(size=128), base_dir=SCENES).render(spp=256, progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (256, 256)
    assert len(calls) >= 2 and all(t == 256 for _, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)


def test_an_exception_in_the_progress_callback_stops_the_render():
    def fail(done, total):
        raise RuntimeError("stop here")

    start = time.perf_counter()
    with pytest.raises(RuntimeError, match="stop here"):
        ember.load(CORNELL).render(spp=100000, progress=fail)
    assert time.perf_counter() - start < 5


INTERRUPTED_RENDER = """
import json, sys, time
import ember
scene = ember.load(json.loads(sys.argv[1]), base_dir=sys.argv[2])
print("rendering", flush=True)
start = time.perf_counter()
try:
    scene.render(spp=1 << 20, pass_spp=2)
except ember.RenderInterrupted as e:
    ember.write_exr(sys.argv[3], e.image)
    print(json.dumps({"spp": e.spp, "seconds": time.perf_counter() - start}), flush=True)
    raise
"""


def test_ctrl_c_stops_a_render_within_a_second_keeping_whole_passes(tmp_path):
    # In a process of its own, as a user presses Ctrl-C: a render that ignored it would run for
    # hours, and is killed here instead.
    doc = small(size=96)
    out = tmp_path / "partial.exr"
    proc = subprocess.Popen([sys.executable, "-c", INTERRUPTED_RENDER, json.dumps(doc), SCENES, str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "rendering"
    time.sleep(0.5)
    sent = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    try:
        stdout, stderr = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("Ctrl-C did not stop the render")
    stopped = time.perf_counter() - sent
    assert proc.returncode != 0 and "ember.RenderInterrupted: render interrupted after" in stderr
    result = json.loads(stdout)
    assert stopped < 1.5  # the process ended within a second or so of the signal (EXR written)
    assert result["spp"] > 0 and result["spp"] % 2 == 0
    # The passes kept are exactly those of an uninterrupted render of that many samples.
    assert np.array_equal(ember.read_exr(out), ember.load(doc, base_dir=SCENES).render(spp=result["spp"]))


def test_keyboard_interrupt_in_this_process_leaves_the_scene_usable():
    scene = ember.load(small(size=96), base_dir=SCENES)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(ember.RenderInterrupted):
        scene.render(spp=1 << 20, progress=lambda d, t: None)
    timer.join()
    assert scene.render(spp=2).shape == (96, 96, 3)


# --- edits ------------------------------------------------------------------------------------

def reloaded(scene, spp=4):
    return ember.load(scene.document, base_dir=SCENES).render(spp=spp)


@pytest.mark.parametrize("edit", [
    lambda s: s.set_camera(origin=[0.3, 1.1, 3.0], fov=30),
    lambda s: s.set_material("glass", ior_inside=1.8),
    lambda s: s.set_material("red", type="phong", kd=[0.5, 0.1, 0.1], ks=0.3, exponent=20),
    lambda s: s.set_shape("glass_sphere", center=[0.2, 0.3, 0.3], radius=0.3),
    lambda s: s.set_shape("light", emission=[4, 4, 4]),
    lambda s: s.set_shape("light", emission=None, material="white"),  # the only light goes out
    lambda s: s.set_shape(7, type="box", center=[0.4, 0.3, 0.3], size=[0.4, 0.6, 0.4], radius=None),
    lambda s: s.set_background([0.1, 0.2, 0.3]),
], ids=["camera", "ior", "material-type", "move-sphere", "emission", "light-off", "sphere-to-box", "background"])
def test_an_edit_renders_what_loading_the_edited_scene_renders(edit):
    scene = ember.load(small(), base_dir=SCENES)
    before = scene.render(spp=4)
    edit(scene)
    after = scene.render(spp=4)
    assert not np.array_equal(after, before)  # the edit shows
    assert np.array_equal(after, reloaded(scene))  # and is what a reload of it gives, bit for bit


def test_light_edits_on_a_point_light_scene():
    scene = ember.load(os.path.join(SCENES, "cornell-point.json"))
    base = scene.render(spp=4)
    scene.set_light("point", intensity=[8, 8, 8])
    assert np.array_equal(scene.render(spp=4), reloaded(scene))
    assert not np.array_equal(scene.render(spp=4), base)


def test_the_background_of_a_gltf_file_as_ember_render_env_sets_it(tmp_path):
    gltf = os.path.join(SCENES, "gltf", "sphere-grid.gltf")
    out = tmp_path / "cli.exr"
    subprocess.run([EMBER, "render", gltf, "-o", str(out), "--spp", "2", "--env", "0.2,0.3,0.5", "-q"],
                   check=True, capture_output=True)
    scene = ember.load(gltf)
    white = scene.render(spp=2)
    scene.set_background([0.2, 0.3, 0.5])
    assert np.array_equal(scene.render(spp=2), openexr_rgb(out))
    assert not np.array_equal(scene.render(spp=2), white)
    with pytest.raises(ember.SceneError, match="render.background"):
        scene.set_background(-1)


def test_moving_an_instanced_mesh_entry_matches_a_reload():
    scene = ember.load(MIXED)
    before = scene.render(spp=4)
    scene.set_shape(1, transform={"translate": [0.0, 1.9, -3.2], "scale": 0.32})
    after = scene.render(spp=4)
    assert np.array_equal(after, reloaded(scene))
    assert ember.compare(before, after)["relmse_all"] > 1e-2


def test_a_failed_edit_changes_nothing():
    scene = ember.load(small(), base_dir=SCENES)
    before = scene.render(spp=2)
    with pytest.raises(ember.SceneError, match=r"materials\.glass\.ior_inside"):
        scene.set_material("glass", ior_inside=-1)
    with pytest.raises(ember.SceneError, match=r"camera\.target.*must differ"):
        scene.set_camera(target=[0, 1, 3.6])
    with pytest.raises(ember.SceneError, match=r"shapes\[6\]\.radius"):
        scene.set_shape("mirror_sphere", radius=float("nan"))
    assert np.array_equal(scene.render(spp=2), before)
    assert scene.document == ember.load(small(), base_dir=SCENES).document


# --- errors -----------------------------------------------------------------------------------

def test_bad_scenes_raise_scene_error_naming_the_file_and_place(tmp_path):
    with pytest.raises(ember.SceneError, match="no-such-scene.json"):
        ember.load(str(tmp_path / "no-such-scene.json"))
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"image": {"width": -4, "height": 4}}))
    with pytest.raises(ember.SceneError, match=r"bad.json: image\.width"):
        ember.load(bad)
    doc = small()
    doc["shapes"][6]["radius"] = float("nan")
    with pytest.raises(ember.SceneError, match=r"<dict>: shapes\[6\]\.radius"):
        ember.load(doc)
    doc = small()
    doc["shapes"][0]["vertices"] = object()
    with pytest.raises(ember.SceneError, match=r"shapes\[0\]\.vertices"):
        ember.load(doc)
    with pytest.raises(ember.SceneError, match="unknown material 'nope'"):
        ember.load({**small(), "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "nope"}]})
    assert issubclass(ember.SceneError, ValueError)


def test_bad_arguments_and_edits_raise(tmp_path):
    scene = ember.load(small(), base_dir=SCENES)
    with pytest.raises(ValueError, match="spp"):
        scene.render(spp=0)
    with pytest.raises(ValueError, match="strategy 'fast'"):
        scene.render(spp=1, strategy="fast")
    with pytest.raises(ValueError, match="aovs"):
        scene.render(spp=1, aovs=["shine"])
    with pytest.raises(ember.SceneError, match="no material 'gold'"):
        scene.set_material("gold", type="mirror")
    with pytest.raises(ember.SceneError, match="none is named 'teapot'"):
        scene.set_shape("teapot", radius=1)
    with pytest.raises(ember.SceneError, match="out of range"):
        scene.set_light(0, intensity=1)
    mixed = ember.load(MIXED)
    with pytest.raises(ember.SceneError, match="placed in world space"):
        mixed.set_shape(0, transform={"translate": [0, 1, 0]})
    with pytest.raises(ember.SceneError, match=r"shapes\[1\]\.file: only a mesh entry's transform"):
        mixed.set_shape(1, file="other.gltf")


def test_a_scene_rendering_in_another_thread_refuses_edits():
    scene = ember.load(CORNELL)
    worker = threading.Thread(target=lambda: scene.render(spp=128))
    worker.start()
    time.sleep(0.3)
    try:
        with pytest.raises(RuntimeError, match="rendering in another thread"):
            scene.set_camera(fov=20)
    finally:
        worker.join()
    scene.set_camera(fov=20)


# --- helpers ----------------------------------------------------------------------------------

def test_compare_returns_the_command_lines_metrics(tmp_path):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    scene = ember.load(small(), base_dir=SCENES)
    image, other = scene.render(spp=4, seed=1), scene.render(spp=4, seed=2)
    ember.write_exr(a, image)
    ember.write_exr(b, other)
    cli = json.loads(subprocess.run([EMBER, "compare", str(a), str(b), "--json", "--max-relmse", "0.5"],
                                    capture_output=True, text=True).stdout)
    mine = ember.compare(image, other, max_relmse=0.5)
    for key in ("relmse_all", "rmse_all", "mae_all", "flip_mean", "relmse", "mean_image", "passed", "criteria"):
        assert mine[key] == cli[key], key
    assert ember.compare(image, image)["relmse_all"] == 0.0


def test_exr_round_trip_keeps_layers_and_metadata(tmp_path):
    scene = ember.load(small(), base_dir=SCENES)
    image, aovs = scene.render(spp=2, aovs=["albedo", "depth"])
    path = tmp_path / "out.exr"
    ember.write_exr(path, image, layers=aovs, metadata={"note": "hello"})
    back = ember.read_exr(path)
    assert np.array_equal(back, image) and back.metadata["note"] == "hello"
    assert np.array_equal(back.layers["albedo"], aovs["albedo"])
    assert np.array_equal(back.layers["depth"], aovs["depth"])
    assert np.array_equal(openexr_rgb(path), image)  # another reader agrees
    with pytest.raises(ember.SceneError, match="missing.exr"):
        ember.read_exr(tmp_path / "missing.exr")
    with pytest.raises(ValueError, match="shape"):
        ember.write_exr(path, image[:, :, :2])


def test_tonemap_and_png_display(tmp_path):
    image = ember.load(small(), base_dir=SCENES).render(spp=4)
    ember.write_exr(tmp_path / "in.exr", image)
    subprocess.run([EMBER, "tonemap", str(tmp_path / "in.exr"), "-o", str(tmp_path / "cli.png")], check=True)
    rgb8 = ember.tonemap(image)
    assert rgb8.dtype == np.uint8 and rgb8.shape == image.shape
    png = image._repr_png_()
    assert png.startswith(b"\x89PNG") and png == ember.png_bytes(rgb8)
    cli = (tmp_path / "cli.png").read_bytes()
    assert cli.startswith(b"\x89PNG")


def test_info_lists_what_the_scene_holds():
    info = ember.load(CORNELL).info()
    assert info["image"]["width"] == 256 and info["lights"]["area"] == 1
    assert {m["name"] for m in info["materials"]} >= {"glass", "mirror", "white"}
    assert info["shapes"] == {"quad": 6, "sphere": 2}
