"""Scenes: loaded by the loaders of ``ember render``, edited in place, rendered by its renderer."""
from __future__ import annotations

import os
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np

from . import _ember
from .image import Image

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, int], Any]


class RenderInterrupted(KeyboardInterrupt):
    """Ctrl-C (or KeyboardInterrupt) during Scene.render: the render stopped within about a tenth of
    a second after its running pass, and ``image`` (with ``aovs``) holds the passes it completed,
    ``spp`` samples per pixel (None and 0 if none completed)."""

    def __init__(self, image: Optional[Image], aovs: Dict[str, np.ndarray], spp: int):
        super().__init__(f"render interrupted after {spp} samples per pixel")
        self.image = image
        self.aovs = aovs
        self.spp = spp


class Scene:
    """A built scene (ember.load). render() renders it; set_camera, set_material, set_shape and
    set_light change it in place, in the JSON format's terms (docs/scene-format.md), rebuilding only
    what depends on the change."""

    def __init__(self, handle: "_ember.SceneHandle"):
        self._handle = handle

    @property
    def width(self) -> int:
        return self._handle.width

    @property
    def height(self) -> int:
        return self._handle.height

    @property
    def document(self) -> dict:
        """A JSON scene's document with every edit applied: ``ember.load(scene.document)`` gives the
        same scene (relative paths resolve against ``base_dir`` there)."""
        if not self._handle.is_json:
            raise _ember.SceneError(f"{self._handle.name}: a glTF file has no JSON document")
        return self._handle.document

    def info(self) -> dict:
        """What the scene holds, as ``ember info`` prints it: image settings, camera, shape counts by
        type, meshes and triangles, lights, strategy, caustics, materials, variants, bounds."""
        return self._handle.info()

    @overload
    def render(self, spp: Optional[int] = ..., *, seed: Optional[int] = ..., threads: int = ...,
               first_sample: int = ..., strategy: Optional[str] = ..., aovs: None = ...,
               progress: Optional[Progress] = ..., pass_spp: int = ...) -> Image: ...

    @overload
    def render(self, spp: Optional[int] = ..., *, seed: Optional[int] = ..., threads: int = ...,
               first_sample: int = ..., strategy: Optional[str] = ..., aovs: Sequence[str],
               progress: Optional[Progress] = ..., pass_spp: int = ...) -> Tuple[Image, Dict[str, np.ndarray]]: ...

    def render(self, spp=None, *, seed=None, threads=0, first_sample=0, strategy=None, aovs=None, progress=None,
               pass_spp=4):
        """The image at ``spp`` samples per pixel (default: the scene's), bit for bit what
        ``ember render --spp SPP --seed SEED --first-sample N`` writes: a float32 Image of shape
        (height, width, 3), linear radiance, whose ``metadata`` holds the render's statistics.

        strategy: "mis" (default: the scene's), "bsdf" or "light" (docs/architecture.md).
        aovs: names from albedo, normal, depth, position, uv, variance, spp (or ["all"]); then the
        result is ``(image, {name: array})`` with (height, width) or (height, width, C) arrays
        (coverage comes with any of depth, position, normal, albedo, uv).
        progress: called as ``progress(spp_done, spp)`` from this thread after passes.
        The GIL is released while rendering. Ctrl-C stops the render within about a tenth of a
        second past its running pass and raises RenderInterrupted holding the completed passes."""
        rgb, layers, stats = self._handle.render(spp, seed, threads, first_sample, strategy, list(aovs or []),
                                                 progress, pass_spp)
        image = Image(rgb, stats)
        if stats["interrupted"]:
            done = stats["spp"]
            raise RenderInterrupted(image if done > 0 else None, layers, done)
        return (image, layers) if aovs else image

    def set_camera(self, *, origin: Optional[Sequence[float]] = None, target: Optional[Sequence[float]] = None,
                   up: Optional[Sequence[float]] = None, fov: Optional[float] = None,
                   half_height: Optional[float] = None) -> None:
        """Move or zoom the camera (``fov``: vertical field of view in degrees; ``half_height``:
        an orthographic camera's). Only the camera and what aims at it are derived again."""
        patch = {"origin": origin, "target": target, "up": up, "fov_y_deg": fov, "half_height": half_height}
        self._handle.set_camera({k: v for k, v in patch.items() if v is not None})

    def set_material(self, name: str, **params: Any) -> None:
        """Change material ``name``'s keys of the JSON format, e.g. ``set_material("glass",
        ior_inside=1.7)`` or ``reflectance=[0.8, 0.2, 0.2]``; a value of None restores the key's
        default; ``type=`` changes its kind. A glTF material is replaced by a whole JSON-format
        material (give ``type``). The BVHs are kept."""
        self._handle.set_material(name, params)

    def set_shape(self, key: Union[int, str], **params: Any) -> None:
        """Change a JSON scene's shape entry (by index into ``shapes``, or by its ``id``/``name``/
        type when unique), e.g. ``set_shape("ball", center=[0, 1, 0], radius=0.4)`` or
        ``emission=[20, 20, 20]``. A moved analytic shape rebuilds only the analytic shapes' BVH; a
        ``"mesh"`` entry's ``transform`` moves its instanced meshes without rebuilding their BVHs."""
        self._handle.set_shape(key, params)

    def set_light(self, key: Union[int, str], **params: Any) -> None:
        """Change a JSON scene's light entry (by index into ``lights``, or by ``id``/``name``/type),
        e.g. ``set_light(0, intensity=[50, 50, 50])``. The BVHs are kept."""
        self._handle.set_light(key, params)

    def set_background(self, radiance: Union[float, Sequence[float]]) -> None:
        """The environment: a constant radiance (one number or r, g, b; 0 for none), replacing any
        environment map, as ``render.background`` in a JSON scene or ``ember render --env r,g,b``
        (a glTF file's default is white, 1). The BVHs are kept."""
        self._handle.set_background(radiance)

    def __repr__(self) -> str:
        return f"<ember.Scene {self._handle.name!r} {self.width}x{self.height}>"


def load(source: Union[PathLike, Mapping[str, Any]], *, camera: Optional[int] = None, variant: Optional[str] = None,
         base_dir: Optional[PathLike] = None) -> Scene:
    """Load and build a scene: an Ember JSON file, a glTF 2.0 file (.gltf/.glb) or a dict in the JSON
    format (docs/scene-format.md; relative file names in it resolve against ``base_dir``, default
    the working directory). ``camera`` and ``variant`` choose a glTF file's camera and
    KHR_materials_variants variant. Bad input raises ember.SceneError (a ValueError) naming the file
    (``<dict>`` for a dict) and the JSON path."""
    if isinstance(source, Mapping):
        if camera is not None or variant is not None:
            raise ValueError("camera and variant choose among a glTF file's; a dict scene has one camera")
        name = os.path.join(os.fspath(base_dir), "<dict>") if base_dir is not None else "<dict>"
        return Scene(_ember.load_document(dict(source), name))
    if base_dir is not None:
        raise ValueError("base_dir resolves a dict scene's file names; a file's are relative to its folder")
    return Scene(_ember.load_file(os.fspath(source), -1 if camera is None else camera, variant or ""))
