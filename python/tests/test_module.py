"""The ember Python module against the command line it shares its code with (docs/python.md)."""
import json
import os
import subprocess
import threading
import time

import numpy as np
import OpenEXR
import pytest

import ember

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORNELL = os.path.join(ROOT, "scenes", "cornell-area.json")
EMBER = os.environ.get("EMBER_BINARY", os.path.join(ROOT, "build", "app", "ember"))


def read_exr(path):
    with OpenEXR.File(str(path)) as f:
        return np.array(f.channels()["RGB"].pixels, dtype=np.float32)


def test_the_image_equals_ember_renders_bit_for_bit(tmp_path):
    out = tmp_path / "cli.exr"
    subprocess.run([EMBER, "render", CORNELL, "-o", str(out), "--spp", "8", "--seed", "3", "-q"], check=True)
    image = ember.load(CORNELL).render(spp=8, seed=3)
    assert image.shape == (256, 256, 3) and image.dtype == np.float32
    assert np.array_equal(image, read_exr(out))
    # ... and the test can tell: another seed is another image.
    assert not np.array_equal(ember.load(CORNELL).render(spp=8, seed=4), image)


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


def test_bad_scenes_raise_scene_error_naming_the_file(tmp_path):
    with pytest.raises(ember.SceneError, match="no-such-scene.json"):
        ember.load(str(tmp_path / "no-such-scene.json"))
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"image": {"width": -4, "height": 4}}))
    with pytest.raises(ember.SceneError, match="bad.json"):
        ember.load(str(bad))
    with pytest.raises(ValueError):
        ember.load(CORNELL).render(spp=0)
