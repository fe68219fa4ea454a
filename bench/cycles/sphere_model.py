#!/usr/bin/python3
"""Each sphere's radiance, and the ratio gilt / Cycles, predicted from the two BRDF models alone.

  sphere_model.py WRAPPER.json LAYOUT.json WIDTH HEIGHT [LABEL=MEASURED.json ...]
                  [--no-ground] [--absolute] [--samples K]

For every pixel of a sphere's disc (the pixels compare.py scores; sample positions drawn from the
pixel filter, a Gaussian of sigma 0.5 px, as both renderers do) the sphere's radiance towards the
camera is computed with each model of brdf_albedo.py ("gltf", glTF appendix B as gilt implements
it; "cycles", Blender 3.4's Principled BSDF with single-scattering GGX) under the scene's lights:
  - the directional light, unshadowed (in these layouts no sphere shadows another), and
  - the uniform sky above the horizon; below it, with the ground, the radiance of the unshadowed
    Lambertian ground of make_scenes.py (albedo 0.5), E cos(sun) / pi * 0.5 + 0.5 L_sky, and with
    --no-ground the sky again.
Light from the other spheres, the sphere's shadow on the ground and anything after the first bounce
off the sphere are left out. In the furnace layout (spheres 3 units apart, no ground) that leaves
out little and the prediction is nearly the rendered radiance itself (--absolute prints measured /
model per renderer); with the ground and close neighbours it is not, but both models see the same
simplified light, so the predicted ratio still says what the BRDFs alone make of the scene.
Both models use the same random numbers; +- is half the difference of two independent halves
(with --absolute, combined in quadrature with the render's own noise).
Each LABEL=MEASURED.json (compare.py --json) adds a column of rendered ratios gilt / Cycles.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from brdf_albedo import brdf, normalize, sample_lobes   # noqa: E402
from compare import sphere_masks                         # noqa: E402

BASE = np.array([0.8, 0.4, 0.2])
GROUND_ALBEDO = 0.5
FILTER_SIGMA, FILTER_RADIUS = 0.5, 1.5   # gilt's default Gaussian, in pixels


def frame(n):
    """Rows: tangent, bitangent, normal (world to shading frame is frame @ x)."""
    a = np.where(np.abs(n[:, 1:2]) < 0.9, [[0.0, 1, 0]], [[1.0, 0, 0]])
    t = normalize(np.cross(a, n))
    return np.stack([t, np.cross(n, t), n], 1)


def predict(wrapper, layout, width, height, samples, rng, with_ground=True):
    cam = wrapper["camera"]
    sun = next(li for li in wrapper["lights"] if li["type"] == "directional")
    sky = next((li["radiance"] for li in wrapper["lights"] if li["type"] == "environment"), 0.0)
    to_sun = -normalize(np.array(sun["direction"], float))
    E = sun["irradiance"]
    ground = GROUND_ALBEDO * (E * to_sun[1] / math.pi + sky) if with_ground else sky
    eye = np.array(cam["look_from"], float)
    w = normalize(np.array(cam["look_at"], float) - eye)
    u = normalize(np.cross(w, np.array(cam.get("up", [0, 1, 0]), float)))
    v_up = np.cross(u, w)
    half_h = math.tan(math.radians(cam.get("vfov", 40.0)) / 2)
    half_w = half_h * width / height
    out = {}
    for s, mask in sphere_masks(layout, cam, width, height):
        ys, xs = np.nonzero(mask)
        c = np.array(s["center"], float)
        m, r = s["metallic"], s["roughness"]
        half = samples // 2
        sums = {"gltf": np.zeros((2, 3)), "cycles": np.zeros((2, 3))}
        for k in range(2 * half):
            # A camera ray through a point drawn from the pixel filter, and its hit on the sphere.
            off = np.clip(rng.normal(0, FILTER_SIGMA, (2, len(xs))), -FILTER_RADIUS, FILTER_RADIUS)
            px, py = xs + 0.5 + off[0], ys + 0.5 + off[1]
            d = normalize(w + ((2 * px / width - 1) * half_w)[:, None] * u
                          + ((1 - 2 * py / height) * half_h)[:, None] * v_up)
            oc = eye - c
            b = d @ oc
            disc = b * b - (oc @ oc - s["radius"] ** 2)
            if (disc <= 0).any():
                raise SystemExit("sphere_model.py: a filter sample misses sphere %s" % s["name"])
            n = normalize(eye + (-b - np.sqrt(disc))[:, None] * d - c)
            F = frame(n)
            view = np.einsum("pij,pj->pi", F, -d)                 # towards the eye, shading frame
            sun_l = np.einsum("pij,j->pi", F, to_sun)
            # One sky / ground direction from the BRDF's own lobes (brdf_albedo.sample_lobes).
            l, pdf = sample_lobes(view, m, r, rng)
            up = np.einsum("pij,pi->pj", F, l)[:, 1]               # world y of the direction
            L = np.where(up > 0, sky, ground)[:, None]
            weight = L * np.maximum(l[:, 2:3], 0) / np.maximum(pdf, 1e-12)[:, None]
            for model in sums:
                direct = brdf(model, view, sun_l, m, r, BASE) * (E * np.maximum(sun_l[:, 2:3], 0))
                sums[model][k % 2] += (direct + brdf(model, view, l, m, r, BASE) * weight).sum(axis=0)
        ratio_halves = sums["gltf"] / sums["cycles"]
        res = {"ratio": ratio_halves.mean(axis=0), "sigma": np.abs(ratio_halves[0] - ratio_halves[1]) / 2}
        for model, halves in sums.items():
            halves = halves / (half * len(xs))                         # each half's mean radiance
            res[model], res[model + "_sigma"] = halves.mean(axis=0), np.abs(halves[0] - halves[1]) / 2
        out["sphere m=%g r=%g" % (m, r)] = res
    return out


def triple(x, s=None):
    return " / ".join("%.3f" % a if s is None else "%.3f±%.3f" % (a, b) for a, b in zip(x, x if s is None else s))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("wrapper")
    p.add_argument("layout")
    p.add_argument("width", type=int)
    p.add_argument("height", type=int)
    p.add_argument("measured", nargs="*", help="LABEL=compare.py's JSON")
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--no-ground", action="store_true", help="the spheres float in the sky (furnace case)")
    p.add_argument("--absolute", action="store_true", help="also measured / model per renderer (first JSON)")
    o = p.parse_args()
    pred = predict(json.load(open(o.wrapper)), json.load(open(o.layout)), o.width, o.height, o.samples,
                   np.random.default_rng(1), not o.no_ground)
    measured = []
    for arg in o.measured:
        label, path = arg.split("=", 1)
        measured.append((label, {r["region"]: r for r in json.load(open(path))}))
    head = ["sphere", "model gilt / Cycles R / G / B"] + ["%s gilt / Cycles" % label for label, _ in measured]
    if o.absolute:
        head += ["gilt / its model", "Cycles / its model"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for name, pr in pred.items():
        cells = [name[len("sphere "):], triple(pr["ratio"], pr["sigma"])]
        for _, res in measured:
            r = res.get(name)
            cells.append(triple(r["ratio"], r["ratio_sigma"]) if r else "")
        if o.absolute and measured:
            r = measured[0][1][name]
            for who, model in (("gilt", "gltf"), ("cycles", "cycles")):
                mean, sigma = np.array(r["mean_" + who]), np.array(r["sigma_" + who])
                q = mean / pr[model]      # its sigma: the render's noise and the model's, in quadrature
                cells.append(triple(q, q * np.hypot(sigma / mean, pr[model + "_sigma"] / pr[model])))
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
