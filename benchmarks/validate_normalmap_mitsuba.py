#!/usr/bin/env python3
"""Checks Ember's glTF normal maps against Mitsuba 3 (its `normalmap` BSDF around a `diffuse` one)
and against a direct numerical evaluation of the glTF definition, on a Lambertian plane covered by
steep round bumps under one light. Optional dependency, never needed by the tests:

    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba==3.9.1 numpy OpenEXR
    /tmp/mi/bin/python benchmarks/validate_normalmap_mitsuba.py --ember build/app/ember --out /tmp/nm

The script writes, under --out:

- `normal.png`: a 16-bit linear normal map of a 4x4 grid of bumps h(r) = A cos^2(pi r / (2R)) for
  r < R, A/R = 2 tan(slope) / pi so the steepest slope (at r = R/2) is --slope-deg (62 by default).
  The top-left cell has no bump, so any mirroring of u or v shows. Normals are encoded as glTF says
  (section 3.9.3 and the normalTexture schema): rgb = (n + 1) / 2, n = normalize(-dh/dx, -dh/dy, 1),
  +X = +u (right in the image), +Y = up in the image (towards decreasing v, row 0 at the top).
- `plane.gltf`: a 2x2 quad in y = 0 (front +y) with NORMAL, TEXCOORD_0 (u = (x+1)/2, v = (z+1)/2)
  and TANGENT (+x, w = +1, so B = cross(N, T) = -z = decreasing v), material "bumpy" with the map;
  `plane_gen.gltf` is the same without TANGENT (Ember generates tangents).
- `scene.json`: an Ember scene loading it as a `mesh` whose material "bumpy" is overridden by an
  Ember `diffuse` of reflectance 0.8, a camera straight above looking down (image up = -z, so the
  image shows the texture unmirrored), direct light only (max_depth 2) and one light (--light:
  point by default, 39 degrees from the plane normal at the centre, azimuth --azimuth-deg from
  +x towards the image's up; a spot has its inner cone wide enough to light the whole view at
  full intensity; a directional light is at exactly --light-deg everywhere).
- The same scene for Mitsuba 3 (scalar_rgb): an OBJ quad with the same uvs (flip_tex_coords off),
  `normalmap` (flip_invalid_normals and use_shadowing_function off: both are Mitsuba additions
  that glTF does not have) around `diffuse` 0.8, a `bitmap` with raw = true (no sRGB decoding),
  format = variant (float32 texels; the default stores a 16-bit file as float16), bilinear,
  repeat; `path` with max_depth 2 (direct only, as Ember's 2); K seeds give the mean and the
  per-pixel standard error.
- An independent numerical reference: the same camera rays, bilinear texel lookup and
  L = (0.8 / pi) E max(0, n . l) per sample, evaluated with numpy (the glTF definition: diffuse_brdf
  = baseColor / pi, the perturbed normal as N, the cosine clamped at 0 as the glTF sample viewer
  does), with its own per-pixel standard error. The same evaluation with the normal first bent
  as Cycles bends it (ensure_valid_reflection, applied to every closure in Blender 2.8x-3.x) is
  written as `cycles_like.exr` for illustration; it is not glTF.

It then runs `ember compare` (per-pixel z-test with variance pooling, relMSE) for Ember against
Mitsuba and against the numerical reference, adds an image-mean z and 8x8 block z-tests, reports
the fraction of black pixels (max channel < 1e-4) and the bump side the light brightens, and runs
controls that must fail: Ember with the map's green channel inverted, and with its red channel
inverted. PNGs for viewing: `ember tonemap` of each EXR and `side_by_side.png` (one exposure for
all: Mitsuba | Ember | numerical | Ember with green inverted)."""
import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exr import load_exr, save_exr  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ALBEDO = 0.8
BLACK = 1e-4
FLOOR = 1e-6


# ---------------------------------------------------------------- files

def write_png(path, img, bits):
    """RGB PNG without gAMA/sRGB/iCCP chunks: the stored integers are the data."""
    h, w, _ = img.shape
    if bits == 16:
        raw = img.astype(">u2").tobytes()
        stride = w * 6
    else:
        raw = img.astype(np.uint8).tobytes()
        stride = w * 3
    rows = b"".join(b"\x00" + raw[y * stride:(y + 1) * stride] for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bits, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(rows, 9)))
        f.write(chunk(b"IEND", b""))


# ---------------------------------------------------------------- the normal map

def normal_map(size, cells, slope_deg):
    """Tangent-space normals (size, size, 3) of the bump grid, row 0 = top = v near 0."""
    R = 0.45 / cells                                  # bump radius in uv units (cell = 1/cells)
    A = 2.0 * math.tan(math.radians(slope_deg)) / math.pi * R
    c = (np.arange(size) + 0.5) / size                # texel centres
    u, v = np.meshgrid(c, c)                          # u along columns, v along rows
    cu = (np.floor(u * cells) + 0.5) / cells
    cv = (np.floor(v * cells) + 0.5) / cells
    dx = u - cu                                       # +X = +u
    dy = -(v - cv)                                    # +Y = up in the image = -v
    r = np.hypot(dx, dy)
    dhdr = -A * math.pi / (2 * R) * np.sin(math.pi * r / R)   # d/dr of A cos^2(pi r / 2R)
    inside = (r < R) & ~((np.floor(u * cells) == 0) & (np.floor(v * cells) == 0))
    rs = np.where(r > 0, r, 1.0)
    gx = np.where(inside, dhdr * dx / rs, 0.0)
    gy = np.where(inside, dhdr * dy / rs, 0.0)
    n = np.stack([-gx, -gy, np.ones_like(gx)], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True), R, A


def encode16(n):
    return np.clip(np.round((n + 1.0) * 0.5 * 65535.0), 0, 65535).astype(np.uint16)


# ---------------------------------------------------------------- glTF and Ember scene

def write_gltf(path, png_name, tangents):
    pos = np.array([[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]], np.float32)   # CCW seen from +y
    nrm = np.tile(np.array([0, 1, 0], np.float32), (4, 1))
    uv = np.stack([(pos[:, 0] + 1) / 2, (pos[:, 2] + 1) / 2], -1).astype(np.float32)
    tan = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    idx = np.array([0, 1, 2, 0, 2, 3, 0, 0], np.uint16)    # 2 padding indices, not referenced
    blobs = [pos.tobytes(), nrm.tobytes(), uv.tobytes()] + ([tan.tobytes()] if tangents else []) + [idx.tobytes()]
    views, accessors, offset = [], [], 0
    specs = [("VEC3", 5126, 4), ("VEC3", 5126, 4), ("VEC2", 5126, 4)] + ([("VEC4", 5126, 4)] if tangents else []) + [("SCALAR", 5123, 6)]
    for blob, (typ, comp, count) in zip(blobs, specs):
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        accessors.append({"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": typ})
        offset += len(blob)
    accessors[0]["min"], accessors[0]["max"] = [-1, 0, -1], [1, 0, 1]
    attributes = {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}
    if tangents:
        attributes["TANGENT"] = 3
    data = b"".join(blobs)
    gltf = {
        "asset": {"version": "2.0", "generator": "benchmarks/validate_normalmap_mitsuba.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": len(accessors) - 1, "material": 0}]}],
        "materials": [{"name": "bumpy", "normalTexture": {"index": 0},
                       "pbrMetallicRoughness": {"baseColorFactor": [ALBEDO, ALBEDO, ALBEDO, 1], "metallicFactor": 0, "roughnessFactor": 1}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
        "images": [{"uri": png_name}],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": views, "accessors": accessors,
    }
    with open(path, "w") as f:
        json.dump(gltf, f, indent=1)


def setup(args):
    """Camera and light, shared by all three renderers."""
    half = 0.95                                           # visible half-extent of the plane
    cam_h = 4.0
    fov = 2 * math.degrees(math.atan(half / cam_h))
    th, ph = math.radians(args.light_deg), math.radians(args.azimuth_deg)
    to_light = np.array([math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)])  # image up = -z
    return {"cam_h": cam_h, "fov": fov, "to_light": to_light, "light_pos": 4.0 * to_light}


def ember_scene(path, gltf_name, args, geo):
    if args.light == "point":
        light = {"type": "point", "position": list(geo["light_pos"]), "intensity": args.intensity}
    elif args.light == "spot":
        light = {"type": "spot", "position": list(geo["light_pos"]), "direction": list(-geo["to_light"]),
                 "intensity": args.intensity, "inner_deg": 60, "outer_deg": 75}
    else:
        light = {"type": "directional", "direction": list(-geo["to_light"]), "irradiance": args.irradiance}
    scene = {
        "description": "validate_normalmap_mitsuba.py: normal-mapped Lambertian plane, direct light only",
        "image": {"width": args.size, "height": args.size},
        "camera": {"origin": [0, geo["cam_h"], 0], "target": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": geo["fov"]},
        "render": {"spp": args.ember_spp, "max_depth": 2, "seed": 0, "sampler": "independent"},
        "materials": {"white": {"type": "diffuse", "reflectance": ALBEDO}},
        "shapes": [{"type": "mesh", "file": gltf_name, "materials": {"bumpy": "white"}}],
        "lights": [light],
    }
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)


def render_ember(args, out, name, scene):
    exr, var = os.path.join(out, name + ".exr"), os.path.join(out, name + "_var.exr")
    t = time.time()
    subprocess.run([args.ember, "render", scene, "-o", exr, "--variance", var, "--spp", str(args.ember_spp),
                    "--sampler", "independent", "--threads", str(args.threads), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    print(f"  ember {name}: {time.time() - t:.1f} s")
    return exr, var


# ---------------------------------------------------------------- Mitsuba

def render_mitsuba(args, out, png, geo, shadowing=False, name="mitsuba"):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    obj = os.path.join(out, "plane.obj")
    with open(obj, "w") as f:
        # Same vertices, winding and uvs as plane.gltf; flip_tex_coords=False keeps v as written.
        f.write("v -1 0 -1\nv -1 0 1\nv 1 0 1\nv 1 0 -1\n")
        f.write("vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n")
        f.write("vn 0 1 0\n")
        f.write("f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n")
    bsdf = {"type": "normalmap", "flip_invalid_normals": False, "use_shadowing_function": shadowing,
            # format "variant": keep float32 texels; "auto" would store a 16-bit file as float16
            # (bitmap.cpp, 3.9.1), i.e. round the normals to about 5e-4.
            "normalmap": {"type": "bitmap", "filename": png, "raw": True, "filter_type": "bilinear", "wrap_mode": "repeat",
                          "format": "variant"},
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [ALBEDO] * 3}}}
    if args.light == "point":
        light = {"type": "point", "position": list(map(float, geo["light_pos"])),
                 "intensity": {"type": "rgb", "value": [args.intensity] * 3}}
    elif args.light == "spot":
        light = {"type": "spot", "intensity": {"type": "rgb", "value": [args.intensity] * 3},
                 "cutoff_angle": 75.0, "beam_width": 60.0,
                 "to_world": mi.ScalarTransform4f().look_at(origin=list(map(float, geo["light_pos"])), target=[0, 0, 0], up=[0, 0, -1])}
    else:
        light = {"type": "directional", "direction": list(map(float, -geo["to_light"])),
                 "irradiance": {"type": "rgb", "value": [args.irradiance] * 3}}
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2, "hide_emitters": False},
        "sensor": {"type": "perspective", "fov": geo["fov"], "fov_axis": "y", "near_clip": 1e-3,
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, geo["cam_h"], 0], target=[0, 0, 0], up=[0, 0, -1]),
                   "film": {"type": "hdrfilm", "width": args.size, "height": args.size, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": args.mi_spp}},
        "plane": {"type": "obj", "filename": obj, "flip_tex_coords": False, "face_normals": False, "bsdf": bsdf},
        "light": light,
    })
    t = time.time()
    imgs = np.stack([np.array(mi.render(scene, seed=1000 + k, spp=args.mi_spp), dtype=np.float64)[..., :3]
                     for k in range(args.mi_seeds)])
    mean = imgs.mean(0)
    err = imgs.std(0, ddof=1) / math.sqrt(args.mi_seeds)
    exr, err_path = os.path.join(out, name + ".exr"), os.path.join(out, name + "_stderr.exr")
    save_exr(exr, mean)
    save_exr(err_path, err)
    print(f"  mitsuba {name}: {args.mi_seeds} seeds x {args.mi_spp} spp, {time.time() - t:.1f} s")
    # The texture Mitsuba actually sampled, against the 16-bit values the script wrote.
    # (convert keeps the file's transfer flag, so no decoding happens here either)
    b = mi.Bitmap(png)
    bmp = np.array(b.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, b.srgb_gamma()))
    return exr, err_path, bmp


# ---------------------------------------------------------------- numerical glTF reference

def bend_like_cycles(nx, ny, nz, ix, iy, iz):
    """Cycles' ensure_valid_(specular_)reflection with Ng = +y (intern/cycles/kernel/closure/
    bsdf_util.h): tilts N towards Ng just enough that the view ray's mirror reflection about N
    stays above the surface. Blender 2.8x-3.x applied it to every closure's normal, diffuse
    included; not part of glTF."""
    ndi = nx * ix + ny * iy + nz * iz
    ry = 2 * ndi * ny - iy                           # dot(Ng, R)
    thr = np.minimum(0.9 * iy, 0.01)
    Xx, Xz = nx, nz                                   # N minus its Ng component, normalised
    xl = np.hypot(Xx, Xz)
    xl = np.where(xl > 0, xl, 1.0)
    Xx, Xz = Xx / xl, Xz / xl
    Ix = ix * Xx + iz * Xz
    a = Ix * Ix + iy * iy
    b = 2 * (a + iy * thr)
    c = (thr + iy) ** 2
    disc = np.sqrt(np.maximum(b * b - 4 * a * c, 0))
    nz2 = np.where(Ix < 0, 0.25 * (b + disc) / a, 0.25 * (b - disc) / a)
    bx, by = np.sqrt(np.maximum(1 - nz2, 0)), np.sqrt(np.maximum(nz2, 0))
    keep = ry >= thr
    return np.where(keep, nx, bx * Xx), np.where(keep, ny, by), np.where(keep, nz, bx * Xz)


def reference(args, tex, geo, spp, seed=7, bend=False):
    """Per pixel: mean over spp uniform positions of (0.8/pi) E max(0, n.l), and its stderr.
    bend=True first bends n as Cycles did (bend_like_cycles): an illustration, not glTF."""
    rng = np.random.default_rng(seed)
    W = H = args.size
    t = math.tan(math.radians(geo["fov"]) / 2)
    N = tex.shape[0]
    out = np.zeros((H, W)); err = np.zeros((H, W)); frac_neg = 0.0
    for j in range(H):
        x = np.arange(W)[:, None] + rng.random((W, spp))
        y = j + rng.random((W, spp))
        # Ember's pinhole with f = -y, r = +x, u = -z (docs/scene-format.md), from (0, cam_h, 0).
        dx, dy, dz = (2 * x / W - 1) * t, -np.ones_like(x), -(1 - 2 * y / H) * t
        s = geo["cam_h"] / -dy
        px, pz = dx * s, dz * s
        uu, vv = (px + 1) / 2, (pz + 1) / 2
        fx, fy = uu * N - 0.5, vv * N - 0.5
        x0, y0 = np.floor(fx).astype(int), np.floor(fy).astype(int)
        wx, wy = (fx - x0)[..., None], (fy - y0)[..., None]
        x0m, x1m, y0m, y1m = x0 % N, (x0 + 1) % N, y0 % N, (y0 + 1) % N
        c = ((1 - wy) * ((1 - wx) * tex[y0m, x0m] + wx * tex[y0m, x1m]) + wy * ((1 - wx) * tex[y1m, x0m] + wx * tex[y1m, x1m]))
        n = 2 * c - 1
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        # world normal = n.x T + n.y B + n.z N with T = +x, B = cross(N, T) = -z, N = +y
        nx, ny, nz = n[..., 0], n[..., 2], -n[..., 1]
        if bend:
            vl = np.sqrt(dx * dx + 1 + dz * dz)
            nx, ny, nz = bend_like_cycles(nx, ny, nz, -dx / vl, 1 / vl, -dz / vl)
        if args.light == "directional":
            lx, ly, lz = geo["to_light"]
            E = args.irradiance
        else:
            Lx, Ly, Lz = geo["light_pos"][0] - px, geo["light_pos"][1] - 0.0, geo["light_pos"][2] - pz
            d2 = Lx * Lx + Ly * Ly + Lz * Lz
            d = np.sqrt(d2)
            lx, ly, lz = Lx / d, Ly / d, Lz / d
            E = args.intensity / d2            # the spot's inner cone covers the whole view
        cos = nx * lx + ny * ly + nz * lz
        frac_neg += np.mean(cos <= 0)
        L = ALBEDO / math.pi * E * np.maximum(cos, 0.0)
        out[j] = L.mean(1)
        err[j] = L.std(1, ddof=1) / math.sqrt(spp)
    rgb = np.repeat(out[..., None], 3, -1)
    return rgb, np.repeat(err[..., None], 3, -1), frac_neg / H


# ---------------------------------------------------------------- statistics

def compare(args, img, ref, var=None, err=None):
    cmd = [args.ember, "compare", img, ref, "--json"]
    if var and err:
        cmd += ["--variance", var, "--ref-stderr", err]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode == 2:
        sys.exit(r.stderr)
    return json.loads(r.stdout)


def extra_z(img, ref, var, err, block=8):
    """Image-mean z (per channel; the largest |z| of the three) and block z-tests: the mean
    difference over each block x block tile of one channel against its standard error, Sidak
    over all tiles and channels. Channels are tested apart because in a grey scene they carry
    the same noise."""
    from statistics import NormalDist
    a, b = load_exr(img), load_exr(ref)
    v = load_exr(var) + load_exr(err) ** 2
    H, W, _ = a.shape
    z_mean = [(a[..., c].mean() - b[..., c].mean()) / math.sqrt(v[..., c].sum() / (H * W) ** 2) for c in range(3)]
    hb, wb = H // block, W // block
    d = (a - b)[: hb * block, : wb * block].reshape(hb, block, wb, block, 3).sum((1, 3))
    s = v[: hb * block, : wb * block].reshape(hb, block, wb, block, 3).sum((1, 3))
    zb = np.where(s > 0, d / np.sqrt(np.where(s > 0, s, 1.0)), np.where(np.abs(d) > 1e-6, np.inf, 0.0))
    k = zb.size
    thr = NormalDist().inv_cdf(1 - (1 - (1 - 0.01) ** (1 / k)) / 2)
    return {"z_mean": float(max(z_mean, key=abs)), "block_max_abs_z": float(np.abs(zb).max()),
            "block_rejected": int((np.abs(zb) > thr).sum()), "blocks": int(k), "block_threshold": thr}


def black_fraction(path):
    return float(np.mean(load_exr(path).max(-1) < BLACK))


def lit_side(path, args, geo):
    """Direction (degrees, from image +x towards image up) of the brightness-weighted centroid
    inside the bumps relative to their centres, over the bumps fully in view: should be close to
    the light's azimuth."""
    img = load_exr(path).mean(-1)
    W = args.size
    t = math.tan(math.radians(geo["fov"]) / 2)
    c = (np.arange(W) + 0.5)
    X = (2 * c / W - 1) * t * geo["cam_h"]            # world x of pixel centres (columns)
    Z = -(1 - 2 * c / W) * t * geo["cam_h"]           # world z of pixel centres (rows)
    xx, zz = np.meshgrid(X, Z)
    u, v = (xx + 1) / 2, (zz + 1) / 2
    cells = args.cells
    du = u - (np.floor(u * cells) + 0.5) / cells
    dv = v - (np.floor(v * cells) + 0.5) / cells
    inside = np.hypot(du, dv) < 0.45 / cells
    inside &= ~((np.floor(u * cells) == 0) & (np.floor(v * cells) == 0))
    w = img * inside
    mx, my = (w * du).sum() / w.sum(), (w * -dv).sum() / w.sum()
    return math.degrees(math.atan2(my, mx))


def preview(paths, out_png, scale):
    imgs = [load_exr(p) for p in paths]
    row = np.concatenate([np.pad(i, ((4, 4), (4, 4), (0, 0)), constant_values=0.0) for i in imgs], 1)
    x = np.clip(row / scale, 0, 1)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    write_png(out_png, np.round(srgb * 255), 8)


# ---------------------------------------------------------------- main

def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--ember", default=os.environ.get("EMBER", os.path.join(ROOT, "build", "app", "ember")))
    p.add_argument("--out", default=None, help="output folder (default: a new temporary one)")
    p.add_argument("--size", type=int, default=128, help="image width and height")
    p.add_argument("--tex", type=int, default=256, help="normal map resolution")
    p.add_argument("--cells", type=int, default=4, help="bumps per side")
    p.add_argument("--slope-deg", type=float, default=62.0)
    p.add_argument("--light", choices=["point", "spot", "directional"], default="point")
    p.add_argument("--light-deg", type=float, default=39.0, help="angle of the light from the plane normal (at the centre)")
    p.add_argument("--azimuth-deg", type=float, default=30.0, help="light azimuth from image +x towards image up")
    p.add_argument("--intensity", type=float, default=25.0, help="point/spot W/sr")
    p.add_argument("--irradiance", type=float, default=3.0, help="directional W/m^2")
    p.add_argument("--ember-spp", type=int, default=1024)
    p.add_argument("--mi-spp", type=int, default=64)
    p.add_argument("--mi-seeds", type=int, default=16)
    p.add_argument("--ref-spp", type=int, default=512, help="samples per pixel of the numerical reference")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--no-controls", action="store_true", help="skip the inverted-channel controls")
    args = p.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="ember_nm_")
    os.makedirs(out, exist_ok=True)
    geo = setup(args)
    print(f"output in {out}; light {args.light} at {args.light_deg} deg, azimuth {args.azimuth_deg} deg; "
          f"camera fov {geo['fov']:.3f} deg from height {geo['cam_h']}")

    n, R, A = normal_map(args.tex, args.cells, args.slope_deg)
    enc = encode16(n)
    tex = enc.astype(np.float64) / 65535.0
    write_png(os.path.join(out, "normal.png"), enc, 16)
    dec = 2 * tex - 1
    dec /= np.linalg.norm(dec, axis=-1, keepdims=True)
    print(f"normal map {args.tex}^2, {args.cells}x{args.cells} bumps, R = {R:.4f} uv, A/R = {A / R:.4f}, "
          f"steepest texel {math.degrees(math.acos(dec[..., 2].min())):.2f} deg")
    write_gltf(os.path.join(out, "plane.gltf"), "normal.png", tangents=True)
    write_gltf(os.path.join(out, "plane_gen.gltf"), "normal.png", tangents=False)
    ember_scene(os.path.join(out, "scene.json"), "plane.gltf", args, geo)
    ember_scene(os.path.join(out, "scene_gen.json"), "plane_gen.gltf", args, geo)
    # A flat map in the same file layout: the override keeps the normal map only if this differs.
    write_png(os.path.join(out, "flat.png"), encode16(np.dstack([np.zeros((8, 8)), np.zeros((8, 8)), np.ones((8, 8))])), 16)
    write_gltf(os.path.join(out, "plane_flat.gltf"), "flat.png", tangents=True)
    ember_scene(os.path.join(out, "scene_flat.json"), "plane_flat.gltf", args, geo)
    if not args.no_controls:
        for tag, ch in (("flipG", 1), ("flipR", 0)):
            bad = enc.copy()
            bad[..., ch] = 65535 - bad[..., ch]
            write_png(os.path.join(out, f"normal_{tag}.png"), bad, 16)
            write_gltf(os.path.join(out, f"plane_{tag}.gltf"), f"normal_{tag}.png", tangents=True)
            ember_scene(os.path.join(out, f"scene_{tag}.json"), f"plane_{tag}.gltf", args, geo)

    print("rendering")
    e_exr, e_var = render_ember(args, out, "ember", os.path.join(out, "scene.json"))
    g_exr, g_var = render_ember(args, out, "ember_gen", os.path.join(out, "scene_gen.json"))
    f_exr, _ = render_ember(args, out, "ember_flat", os.path.join(out, "scene_flat.json"))
    m_exr, m_err, bmp = render_mitsuba(args, out, os.path.join(out, "normal.png"), geo)
    print(f"  Mitsuba's decoded texture vs the written 16-bit values: max |diff| = {np.abs(bmp - tex).max():.2e}")
    ms_exr, ms_err, _ = render_mitsuba(args, out, os.path.join(out, "normal.png"), geo, shadowing=True, name="mitsuba_shadowing")
    t = time.time()
    ref, ref_err, frac_neg = reference(args, tex, geo, args.ref_spp)
    r_exr, r_err = os.path.join(out, "gltf_ref.exr"), os.path.join(out, "gltf_ref_stderr.exr")
    save_exr(r_exr, ref)
    save_exr(r_err, ref_err)
    print(f"  numerical glTF reference: {args.ref_spp} spp, {time.time() - t:.1f} s; "
          f"fraction of the view with n.l <= 0: {frac_neg:.4f}")
    cyc, cyc_err, _ = reference(args, tex, geo, args.ref_spp, bend=True)
    c_exr = os.path.join(out, "cycles_like.exr")
    save_exr(c_exr, cyc)
    controls = {}
    if not args.no_controls:
        for tag in ("flipG", "flipR"):
            controls[tag] = render_ember(args, out, f"ember_{tag}", os.path.join(out, f"scene_{tag}.json"))

    flat = load_exr(f_exr).mean(-1)
    print("\nblack px: max channel < %g; dim px: below 0.1 x the flat-map image" % BLACK)
    print("image                      mean        black px   dim px    lit-side azimuth (light at %.0f deg)" % args.azimuth_deg)
    for name, path in [("Ember (file tangents)", e_exr), ("Ember (generated tangents)", g_exr), ("Ember (flat map)", f_exr),
                       ("Mitsuba", m_exr), ("Mitsuba, shadowing term on", ms_exr), ("numerical glTF", r_exr),
                       ("numerical, Cycles-bent N", c_exr)] + \
                      [(f"Ember {k} (control)", v[0]) for k, v in controls.items()]:
        dim = float(np.mean(load_exr(path).mean(-1) < 0.1 * flat))
        print(f"{name:26s} {load_exr(path).mean():.6f}   {black_fraction(path):.4f}     {dim:.4f}    {lit_side(path, args, geo):7.1f}")

    rows = [("Ember vs Mitsuba", e_exr, m_exr, e_var, m_err),
            ("Ember vs numerical glTF", e_exr, r_exr, e_var, r_err),
            ("Ember (generated tangents) vs Mitsuba", g_exr, m_exr, g_var, m_err),
            ("Mitsuba vs numerical glTF*", m_exr, r_exr, m_err, r_err),
            ("Mitsuba+shadowing vs numerical glTF*", ms_exr, r_exr, ms_err, r_err)]
    rows += [(f"CONTROL Ember {k} vs Mitsuba", v[0], m_exr, v[1], m_err) for k, v in controls.items()]
    rows += [("CONTROL Ember (flat map) vs Mitsuba", f_exr, m_exr, os.path.join(out, "ember_flat_var.exr"), m_err)]
    print(f"\n(* the image's 'variance' there is Mitsuba's stderr squared; every reference stderr has a floor "
          f"of {FLOOR:g} x |reference| for float rounding in zero-variance pixels)")
    print(f"{'comparison':40s} {'max|z|':>8s} {'rejected':>9s} {'t':>6s} {'mean z':>8s} {'blk max|z|':>10s} {'blk rej':>8s} {'relMSE':>10s}  verdict")
    summary = {}
    for name, img, refp, var, err in rows:
        if var.endswith("_stderr.exr"):               # Mitsuba as the image: its variance is stderr^2
            vpath = var.replace("_stderr.exr", "_var.tmp.exr")
            save_exr(vpath, load_exr(var) ** 2)
            var = vpath
        # Pixels of constant radiance (flat ground under a directional light) have zero variance in
        # every renderer; a float32 renderer matches there only to rounding, so the reference's
        # stderr gets a floor of FLOOR x |reference| (far below the noise anywhere else).
        epath = err.replace(".exr", "_floor.tmp.exr")
        save_exr(epath, np.sqrt(load_exr(err) ** 2 + (FLOOR * np.abs(load_exr(refp))) ** 2))
        err = epath
        c = compare(args, img, refp, var, err)
        z = c["ztest"]
        x = extra_z(img, refp, var, err)
        ok = z["passed"] and x["block_rejected"] == 0 and abs(x["z_mean"]) < 3.29
        mz = z["max_abs_z"] if z["max_abs_z"] is not None else float("inf")
        print(f"{name:40s} {mz:8.2f} {z['rejected']:5d}/{z['tests']:<5d} {z['threshold']:5.2f} {x['z_mean']:8.2f} "
              f"{x['block_max_abs_z']:10.2f} {x['block_rejected']:4d}/{x['blocks']:<4d} {c['relmse_all']:10.3e}  {'agree' if ok else 'DIFFER'}")
        summary[name] = {"ztest": z, "relmse_all": c["relmse_all"], "mean_image": c["mean_image"], "mean_reference": c["mean_reference"], **x}
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)

    for path in [e_exr, m_exr, r_exr, ms_exr, c_exr] + [v[0] for v in controls.values()]:
        subprocess.run([args.ember, "tonemap", path, "-o", path[:-4] + ".png"], check=True, stdout=subprocess.DEVNULL)
    side = [m_exr, e_exr, r_exr, c_exr] + ([controls["flipG"][0]] if "flipG" in controls else [])
    preview(side, os.path.join(out, "side_by_side.png"), scale=np.percentile(load_exr(m_exr), 99.5))
    print(f"\nPNGs: {out}/side_by_side.png (Mitsuba | Ember | numerical glTF | Cycles-bent N{' | Ember flipG' if controls else ''}), *.png per EXR")


if __name__ == "__main__":
    main()
