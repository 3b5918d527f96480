"""Linear float RGB EXR files as numpy arrays (height x width x 3), for the benchmark and
validation scripts here (optional dependencies: numpy, OpenEXR from PyPI)."""
import numpy as np
import OpenEXR


def load_exr(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.array(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def save_exr(path, img):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": np.ascontiguousarray(img, dtype=np.float32)}) as f:
        f.write(path)
