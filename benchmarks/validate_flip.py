#!/usr/bin/env python3
"""Checks Ember's FLIP (io/flip.cpp) against NVIDIA's reference implementation (PyPI
`flip-evaluator`, an optional dependency) on image pairs made from the cornell-area reference:

    /tmp/mi/bin/pip install flip-evaluator numpy OpenEXR
    build/app/ember render scenes/cornell-area.json -o /tmp/f16.exr --spp 16
    /tmp/mi/bin/python benchmarks/validate_flip.py /tmp/f16.exr

Both sides get the same display-referred inputs (Reinhard 2002 with the reference's curve, as
`ember compare` applies) and `ember compare --ldr` skips its own tone mapping."""
import json
import os
import subprocess
import sys
import tempfile

import flip_evaluator as flip
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exr import load_exr, save_exr  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ref = load_exr(os.path.join(ROOT, "tests", "data", "cornell-area", "reference.exr"))
    test = load_exr(sys.argv[1])
    lum = lambda c: 0.2126 * c[..., 0] + 0.7152 * c[..., 1] + 0.0722 * c[..., 2]
    L = lum(ref)
    logavg, white = np.exp(np.mean(np.log(1e-6 + np.maximum(L, 0)))), L.max()

    def tonemap(c):
        l = lum(c)
        s = 0.18 / logavg
        ls = s * l
        ld = ls * (1 + ls / (white * s) ** 2) / (1 + ls)
        out = c * (ld / np.where(l > 0, l, 1))[..., None]
        out[l <= 0] = 0
        return np.clip(out, 0, 1)

    pairs = {
        "noisy render": (tonemap(ref), tonemap(test)),
        "blurred": (tonemap(ref), tonemap((ref + np.roll(ref, 1, 0) + np.roll(ref, 1, 1)) / 3)),
        "10% darker": (tonemap(ref), tonemap(ref * 0.9)),
        "ramp vs flat": (np.dstack([np.tile(np.linspace(0, 1, 256), (256, 1))] * 3), np.full((256, 256, 3), 0.5)),
    }
    tmp = tempfile.mkdtemp()
    for name, (a, b) in pairs.items():
        save_exr(os.path.join(tmp, "a.exr"), a)
        save_exr(os.path.join(tmp, "b.exr"), b)
        _, official, _ = flip.evaluate(a.astype(np.float32), b.astype(np.float32), "LDR", inputsRGB=False, applyMagma=False)
        out = subprocess.run([os.path.join(ROOT, "build", "app", "ember"), "compare", os.path.join(tmp, "b.exr"),
                              os.path.join(tmp, "a.exr"), "--ldr", "--json"], capture_output=True, text=True).stdout
        ours = json.loads(out)["flip_mean"]
        print(f"{name:14s} flip-evaluator {official:.5f}   ember {ours:.5f}   ratio {ours / official:.4f}")


if __name__ == "__main__":
    main()
