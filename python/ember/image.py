"""Images as numpy arrays: ember.Image (shows itself in Jupyter), EXR files with their layers and
metadata, tone mapping and comparison with a reference, all by the command line's own code."""
from __future__ import annotations

import os
import struct
import zlib
from typing import Any, Mapping, Optional, Union

import numpy as np

from . import _ember

PathLike = Union[str, "os.PathLike[str]"]

# The EXR channel names of the renderer's AOVs (docs/aovs.md), by the names render() and
# read_exr() use for them.
_LAYER_CHANNELS = {
    "albedo": ["albedo.R", "albedo.G", "albedo.B"],
    "normal": ["N.X", "N.Y", "N.Z"],
    "depth": ["Z"],
    "position": ["P.X", "P.Y", "P.Z"],
    "uv": ["uv.U", "uv.V"],
    "coverage": ["coverage"],
    "variance": ["variance.R", "variance.G", "variance.B"],
    "spp": ["spp"],
    "noisy": ["noisy.R", "noisy.G", "noisy.B"],
}
_LAYER_NAMES = {"N": "normal", "Z": "depth", "P": "position"}
_SUFFIX_ORDER = {s: i for i, s in enumerate(["R", "G", "B", "A", "X", "Y", "Z", "U", "V"])}


class Image(np.ndarray):
    """A float32 array of shape (height, width, 3), linear radiance, that displays itself in Jupyter
    (tone-mapped as ``ember tonemap`` does). ``metadata`` holds what produced it: a render's
    statistics, or an EXR file's attributes. Arithmetic on it gives plain arrays' values."""

    metadata: dict
    layers: dict

    def __new__(cls, array: Any, metadata: Optional[Mapping[str, Any]] = None) -> "Image":
        image = np.asarray(array, dtype=np.float32).view(cls)
        image.metadata = dict(metadata or {})
        return image

    def __array_finalize__(self, obj: Any) -> None:
        self.metadata = dict(getattr(obj, "metadata", {}) or {})

    def _repr_png_(self) -> Optional[bytes]:
        if self.ndim != 3 or self.shape[2] != 3 or self.size == 0:
            return None
        return png_bytes(tonemap(self))


def png_bytes(rgb8: np.ndarray) -> bytes:
    """An 8-bit (height, width, 3) array as the bytes of a PNG file (zlib, no filter)."""
    rgb8 = np.ascontiguousarray(rgb8, dtype=np.uint8)
    height, width = rgb8.shape[:2]
    rows = np.concatenate([np.zeros((height, 1), np.uint8), rgb8.reshape(height, width * 3)], axis=1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
            + chunk(b"IEND", b""))


def _rgb(image: Any, what: str) -> np.ndarray:
    array = np.ascontiguousarray(image, dtype=np.float32)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{what}: expected an array of shape (height, width, 3), got {array.shape}")
    return array


def tonemap(image: Any, *, key: float = 0.18, white: Optional[float] = None) -> np.ndarray:
    """Reinhard et al. 2002's global operator and the sRGB curve, as ``ember tonemap``: a uint8
    array of shape (height, width, 3). ``white``: the input luminance shown as white (default: the
    image's brightest)."""
    return _ember.tonemap(_rgb(image, "image"), key, white)


def compare(image: Any, reference: Any, *, variance: Any = None, ref_stderr: Any = None,
            max_relmse: Optional[float] = None, max_flip: Optional[float] = None, alpha: float = 0.01,
            variance_pool: int = 2, ppd: float = 67.0, ldr: bool = False) -> dict:
    """The metrics of ``ember compare --json`` (docs/compare.md): per-channel means, MAE, RMSE and
    relMSE, FLIP, and with both ``variance`` (of the image's mean, per pixel) and ``ref_stderr``
    the per-pixel z-test; ``passed`` applies the given criteria."""
    return _ember.compare(_rgb(image, "image"), _rgb(reference, "reference"),
                          None if variance is None else _rgb(variance, "variance"),
                          None if ref_stderr is None else _rgb(ref_stderr, "ref_stderr"),
                          max_relmse, max_flip, alpha, variance_pool, ppd, ldr)


def _channels(name: str, array: np.ndarray) -> list:
    count = 1 if array.ndim == 2 else array.shape[2]
    if name in _LAYER_CHANNELS and len(_LAYER_CHANNELS[name]) == count:
        return _LAYER_CHANNELS[name]
    if count == 1:
        return [name]
    suffixes = {3: "RGB", 4: "RGBA"}.get(count, [str(i) for i in range(count)])
    return [f"{name}.{s}" for s in suffixes]


def write_exr(path: PathLike, image: Any, *, layers: Optional[Mapping[str, Any]] = None,
              metadata: Optional[Mapping[str, Any]] = None) -> None:
    """A linear float32 EXR as ``ember render`` writes it (zip, written to a temporary file, then
    renamed): the image as R, G, B, each layer (an array of (height, width) or (height, width, C))
    under its channel names (the AOVs' own, e.g. ``normal`` as N.X/Y/Z), and ``metadata`` (default:
    the image's) as string attributes."""
    rgb = _rgb(image, "image")
    out = []
    for name, layer in (layers or {}).items():
        array = np.ascontiguousarray(layer, dtype=np.float32)
        if array.ndim not in (2, 3) or array.shape[:2] != rgb.shape[:2]:
            raise ValueError(f"layer {name!r}: expected shape {rgb.shape[:2]} (+ channels), got {array.shape}")
        out.append((_channels(name, array), array.reshape(array.shape[0], array.shape[1], -1)))
    if metadata is None:
        metadata = getattr(image, "metadata", {}) or {}
    _ember.write_exr(os.fspath(path), rgb, out, [(str(k), str(v)) for k, v in metadata.items()])


def read_exr(path: PathLike) -> Image:
    """An EXR's R, G, B as an Image whose ``metadata`` holds the file's string attributes (an
    ember render's ``ember:*`` keys) and ``layers`` every other layer by name (AOVs by their
    render() names: albedo, normal, depth, ...), (height, width) or (height, width, C) float32."""
    width, height, channels, metadata = _ember.read_exr(os.fspath(path))
    groups: dict = {}
    for channel, pixels in channels.items():
        prefix, _, suffix = channel.rpartition(".")
        groups.setdefault(prefix, []).append((suffix, pixels))
    def stacked(parts: list) -> np.ndarray:
        parts.sort(key=lambda p: (_SUFFIX_ORDER.get(p[0], len(_SUFFIX_ORDER)), p[0]))
        return parts[0][1] if len(parts) == 1 else np.stack([p[1] for p in parts], axis=-1)
    base = dict(groups.pop("", []))
    if not all(c in base for c in "RGB"):
        raise _ember.SceneError(f"{os.fspath(path)}: no R, G, B channels")
    image = Image(np.stack([base.pop(c) for c in "RGB"], axis=-1), metadata)
    layers = {_LAYER_NAMES.get(name, name): pixels for name, pixels in base.items()}  # single channels: Z, spp
    for prefix, parts in groups.items():
        layers[_LAYER_NAMES.get(prefix, prefix)] = stacked(parts)
    image.layers = layers
    return image
