# %% [markdown]
# # The caustic of a glass sphere, against its index of refraction
#
# A notebook in script form (Jupyter, VS Code and jupytext open its `# %%` cells): one scene, loaded
# once, its glass ball's IOR changed in place and rendered again at each step. The floor under the
# ball gathers the light the ball focuses. A ball lens of radius R has the paraxial focal length
# f = n R / (2 (n - 1)) from its centre (Hecht, Optics, 5th ed., sec. 6.2); with the lamp at u and
# the floor at h below the centre, 1/f = 1/h + 1/u puts the lamp's paraxial image on the floor, at
# n = 1.38 here. Spherical aberration (strong in a ball) brings the rim's rays to focus nearer the
# ball, so the patch under it is brightest at a somewhat lower n, and dims on either side.
#
#     python examples/ior_sweep.py [--out DIR] [--spp N]

# %%
import argparse
import os

import numpy as np

import ember

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--out", default="ior-sweep", help="folder for the plot, the table and the images")
parser.add_argument("--spp", type=int, default=64)
args = parser.parse_args()
os.makedirs(args.out, exist_ok=True)

# %% The scene: a glass ball over a white floor, a small area light straight above.
RADIUS, HEIGHT, LAMP = 0.5, 1.2, 5.0
document = {
    "image": {"width": 160, "height": 120},
    "camera": {"origin": [0.0, 1.4, 4.0], "target": [0.0, 0.35, 0.0], "fov_y_deg": 35},
    "render": {"seed": 7},
    "materials": {
        "floor": {"type": "diffuse", "reflectance": 0.7},
        "glass": {"type": "dielectric", "ior_inside": 1.5},
        "black": {"type": "diffuse", "reflectance": 0.0},
    },
    "shapes": [
        {"type": "quad", "material": "floor",
         "vertices": [[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]},
        {"id": "ball", "type": "sphere", "center": [0, HEIGHT, 0], "radius": RADIUS, "material": "glass"},
        {"id": "lamp", "type": "quad", "material": "black", "emission": 400,
         "vertices": [[-0.1, LAMP, -0.1], [0.1, LAMP, -0.1], [0.1, LAMP, 0.1], [-0.1, LAMP, 0.1]]},
    ],
}
scene = ember.load(document)

# %% Which pixels see the floor right under the ball: from the position AOV of one render.
_, aovs = scene.render(spp=4, aovs=["position"])
p = aovs["position"]  # the mean of the samples' first hits, over the samples that hit something
under = (aovs["coverage"] == 1) & (np.hypot(p[..., 0], p[..., 2]) < 0.15) & (np.abs(p[..., 1]) < 1e-3)
assert under.sum() > 20, "the camera should see the floor under the ball"

# %% The sweep: one edit and one render per IOR; the ball's "energy" is the light it adds there.
iors = [1.0, 1.1, 1.15, 1.2, 1.25, 1.3, 1.4, 1.5, 1.7, 2.0]
energy = []
for n in iors:
    scene.set_material("glass", ior_inside=n)
    image = scene.render(spp=args.spp)
    energy.append(float(image[under].mean()))
    if n in (1.0, 1.2, 1.5):
        ember.write_exr(os.path.join(args.out, f"ior-{n:.2f}.exr"), image)
# The floor without the ball: what its light is measured against.
no_ball = dict(document, shapes=[s for s in document["shapes"] if s.get("id") != "ball"])
baseline = float(ember.load(no_ball).render(spp=args.spp)[under].mean())
gain = [e / baseline for e in energy]

with open(os.path.join(args.out, "ior-sweep.csv"), "w") as f:
    f.write("ior,mean_radiance_under_ball,gain_over_no_ball\n")
    for n, e, g in zip(iors, energy, gain):
        f.write(f"{n},{e:.6g},{g:.4g}\n")
        print(f"IOR {n:4.2f}: radiance under the ball {e:8.4f}  ({g:5.2f}x the floor without it)")

# %% The plot (matplotlib, when installed).
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.plot(iors, gain, "o-")
    f = 1 / (1 / HEIGHT + 1 / (LAMP - HEIGHT))  # the lamp's paraxial image on the floor
    focus = 1 / (1 - RADIUS / (2 * f))
    ax.axvline(focus, ls="--", c="grey", label=f"paraxial image on the floor (n = {focus:.2f})")
    ax.set_xlabel("index of refraction of the ball")
    ax.set_ylabel("light under the ball / without it")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "ior-sweep.png"), dpi=120)
    print("plot:", os.path.join(args.out, "ior-sweep.png"))
except ImportError:
    print("matplotlib is not installed: the table is in", os.path.join(args.out, "ior-sweep.csv"))

# %% The checks a reader would make: n = 1 changes nothing; the ball focuses up to several times
# the light there, most a little below the paraxial n.
assert abs(gain[0] - 1.0) < 0.05, gain[0]  # n = 1 bends and reflects nothing: as if absent
peak = iors[int(np.argmax(gain))]
assert max(gain) > 3.0 and 1.15 <= peak <= 1.45, (peak, max(gain))
