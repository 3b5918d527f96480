"""Builds a Mitsuba 3 scene from a neutral reference spec (tests/data/<scene>/scene.json, the
format described in ../shared/refs/CONVENTIONS.md), following those conventions: pinhole camera
with vertical fov, box filter, independent sampler, two-sided Lambertian, one-sided area lights,
`path` integrator with max_depth -1 and rr_depth 5. Used by the side-by-side benchmarks only."""
import json
import math
import os
import tempfile

import mitsuba as mi


def _rgb(v):
    return {"type": "rgb", "value": list(map(float, v))}


def _bsdf(mat, base_dir):
    t = mat["type"]
    if t == "diffuse":
        refl = mat["reflectance"]
        if isinstance(refl, dict):
            tex = {"type": "bitmap", "filename": os.path.join(base_dir, refl["texture"]),
                   "filter_type": "nearest", "wrap_mode": "clamp", "raw": False}
            inner = {"type": "diffuse", "reflectance": tex}
        else:
            inner = {"type": "diffuse", "reflectance": _rgb(refl)}
        return {"type": "twosided", "material": inner}
    if t == "mirror":
        return {"type": "conductor", "material": "none", "specular_reflectance": _rgb(mat.get("reflectance", [1, 1, 1]))}
    if t == "dielectric":
        return {"type": "dielectric", "int_ior": float(mat["ior_inside"]), "ext_ior": float(mat.get("ior_outside", 1.0))}
    raise ValueError(f"unsupported material type {t}")


def _frame_to(n):
    """Rotation taking +z to the unit vector n."""
    n = mi.ScalarVector3f(n)
    n = n / math.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    return mi.ScalarTransform4f.look_at(origin=[0, 0, 0], target=n, up=[0, 1, 0] if abs(n[1]) < 0.99 else [1, 0, 0])


def _write_obj(path, vertices, faces, normals=None, uvs=None):
    with open(path, "w") as f:
        for v in vertices:
            f.write("v %.9g %.9g %.9g\n" % tuple(v))
        for t in uvs or []:
            f.write("vt %.9g %.9g\n" % tuple(t))
        for n in normals or []:
            f.write("vn %.9g %.9g %.9g\n" % tuple(n))
        for face in faces:
            if normals:
                f.write("f " + " ".join(f"{i + 1}//{i + 1}" for i in face) + "\n")
            elif uvs:
                f.write("f " + " ".join(f"{i + 1}/{i + 1}" for i in face) + "\n")
            else:
                f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def _cone_obj(path, base, apex, radius, segments=1024):
    """The reference's cone: `segments` side triangles with the exact cone's smooth normals."""
    base, apex = mi.ScalarVector3f(base), mi.ScalarVector3f(apex)
    axis = apex - base
    h = math.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2)
    frame = _frame_to(axis)
    k = radius / h
    verts, norms, faces = [], [], []
    for i in range(segments):
        for a in (2 * math.pi * i / segments, 2 * math.pi * (i + 1) / segments):
            p = frame @ mi.ScalarPoint3f(radius * math.cos(a), radius * math.sin(a), 0)
            n = frame @ mi.ScalarVector3f(math.cos(a), math.sin(a), k)
            verts.append(list(base + mi.ScalarVector3f(p)))
            norms.append(list(n / math.sqrt(1 + k * k)))
        am = 2 * math.pi * (i + 0.5) / segments
        n = frame @ mi.ScalarVector3f(math.cos(am), math.sin(am), k)
        verts.append(list(apex))
        norms.append(list(n / math.sqrt(1 + k * k)))
        faces.append((3 * i, 3 * i + 1, 3 * i + 2))
    _write_obj(path, verts, faces, normals=norms)


def build(spec_path, spp, seed=0):
    spec = json.load(open(spec_path))
    base_dir = os.path.dirname(os.path.abspath(spec_path))
    tmp = tempfile.mkdtemp(prefix="ember_mi_")
    cam = spec["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False},
        "sensor": {
            "type": "perspective", "fov": float(cam["fov_y_deg"]), "fov_axis": "y", "near_clip": 1e-3,
            "to_world": mi.ScalarTransform4f.look_at(origin=cam["origin"], target=cam["target"], up=cam["up"]),
            "film": {"type": "hdrfilm", "width": spec["image"]["width"], "height": spec["image"]["height"],
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        },
    }
    mats = {k: _bsdf(v, base_dir) for k, v in spec["materials"].items()}
    for i, s in enumerate(spec["shapes"]):
        t = s["type"]
        bsdf = mats[s["material"]]
        shapes = []
        if t == "quad":
            v0, v1, v2, v3 = (mi.ScalarVector3f(v) for v in s["vertices"])
            c, e1, e2 = (v0 + v2) * 0.5, (v1 - v0) * 0.5, (v3 - v0) * 0.5
            n = mi.ScalarVector3f(e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
            m = mi.ScalarMatrix4f([[e1[0], e2[0], n[0], c[0]], [e1[1], e2[1], n[1], c[1]], [e1[2], e2[2], n[2], c[2]], [0, 0, 0, 1]])
            shapes.append({"type": "rectangle", "to_world": mi.ScalarTransform4f(m)})
        elif t == "triangle":
            path = os.path.join(tmp, f"tri{i}.obj")
            _write_obj(path, s["vertices"], [(0, 1, 2)])
            shapes.append({"type": "obj", "filename": path, "face_normals": True})
        elif t == "sphere":
            shapes.append({"type": "sphere", "center": s["center"], "radius": float(s["radius"])})
        elif t == "disk":
            shapes.append({"type": "disk", "to_world": mi.ScalarTransform4f.translate(s["center"]) @ _frame_to(s["normal"]) @ mi.ScalarTransform4f.scale(float(s["radius"]))})
        elif t == "cylinder":
            p0, p1, r = s["p0"], s["p1"], float(s["radius"])
            shapes.append({"type": "cylinder", "p0": p0, "p1": p1, "radius": r})
            if s.get("caps", False):
                axis = [b - a for a, b in zip(p0, p1)]
                shapes.append({"type": "disk", "to_world": mi.ScalarTransform4f.translate(p1) @ _frame_to(axis) @ mi.ScalarTransform4f.scale(r)})
                shapes.append({"type": "disk", "to_world": mi.ScalarTransform4f.translate(p0) @ _frame_to([-a for a in axis]) @ mi.ScalarTransform4f.scale(r)})
        elif t == "cone":
            path = os.path.join(tmp, f"cone{i}.obj")
            _cone_obj(path, s["base_center"], s["apex"], float(s["radius"]))
            shapes.append({"type": "obj", "filename": path, "face_normals": False})
            if s.get("cap_base", False):
                axis = [b - a for a, b in zip(s["base_center"], s["apex"])]
                shapes.append({"type": "disk", "to_world": mi.ScalarTransform4f.translate(s["base_center"]) @ _frame_to([-a for a in axis]) @ mi.ScalarTransform4f.scale(float(s["radius"]))})
        elif t == "box":
            size = [x * 0.5 for x in s["size"]]
            shapes.append({"type": "cube", "to_world": mi.ScalarTransform4f.translate(s["center"]) @ mi.ScalarTransform4f.rotate([0, 1, 0], float(s.get("rotate_y_deg", 0))) @ mi.ScalarTransform4f.scale(size)})
        else:
            raise ValueError(f"unsupported shape type {t}")
        for j, sh in enumerate(shapes):
            sh["bsdf"] = bsdf
            if "emission" in s:
                sh["emitter"] = {"type": "area", "radiance": _rgb(s["emission"]["radiance"])}
            scene[f"shape_{i}_{j}"] = sh
    for i, l in enumerate(spec.get("lights", [])):
        scene[f"light_{i}"] = {"type": "point", "position": l["position"], "intensity": _rgb(l["intensity"])}
    return mi.load_dict(scene)
