"""Ember, a physically based path tracer on Intel Embree, from Python (docs/python.md).

    import ember
    scene = ember.load("scenes/cornell-area.json")
    image = scene.render(spp=64)   # numpy float32, (height, width, 3), linear radiance
"""
from ._ember import Scene, SceneError, load

__all__ = ["Scene", "SceneError", "load"]
