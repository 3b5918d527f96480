"""Ember, a physically based path tracer on Intel Embree, from Python (docs/python.md).

    import ember
    scene = ember.load("scenes/cornell-area.json")
    image = scene.render(spp=64)          # float32 (height, width, 3), linear radiance
    scene.set_camera(fov=30)              # edit, then render again: only the camera is rebuilt
    ember.write_exr("out.exr", scene.render(spp=64))
"""
from ._ember import SceneError
from .image import Image, compare, png_bytes, read_exr, tonemap, write_exr
from .scene import RenderInterrupted, Scene, load

# Shown as ember.Image, ember.Scene, ... in tracebacks and reprs, as they are imported.
for _public in (Image, RenderInterrupted, Scene):
    _public.__module__ = __name__

__all__ = ["Image", "RenderInterrupted", "Scene", "SceneError", "compare", "load", "png_bytes", "read_exr",
           "tonemap", "write_exr"]
