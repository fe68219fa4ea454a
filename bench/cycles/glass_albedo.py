#!/usr/bin/python3
"""One rough glass interface, both renderers' models, no renderer: the fraction of the energy
arriving from a direction that the interface reflects (R) and transmits (T), by Monte Carlo.

  glass_albedo.py [--samples N] [--furnace WRAPPER LAYOUT WIDTH HEIGHT [--furnace-paths N]]
      prints markdown tables; needs python3-numpy

Both are GGX with alpha = roughness^2, separable Smith G2 = G1(wo) G1(wi) and eta = 1.5, and both
sample normals visible from wo (Heitz 2018), under which a lobe's weight is its Fresnel factor times
G1(wi). They differ in where the Fresnel factor is taken (Cycles 3.4 sources named):

  gilt (raytrace_core/scene/rough_dielectric.h, Walter et al. 2007): per microfacet, F(wo.h);
      R = E[F(wo.h) G1(r)],  T = E[(1 - F(wo.h)) G1(t)]
  Cycles' Principled BSDF, distribution GGX, transmission 1 (svm/closure.h: a reflection closure of
      weight F(N.wo) whose colour interpolate_fresnel_color(...) is 1 for specular tint 0, plus a
      refraction closure of weight (1 - F(N.wo)), bsdf_microfacet.h): once, at the shading normal;
      R = F(N.wo) E[G1(r)],  T = (1 - F(N.wo)) E[G1(t); no total internal reflection at h]

r and t are wo reflected and refracted about the sampled normal h, counted only on the right side of
the surface (a direction going into the surface is lost, as in both renderers). wo "outside" meets
eta = 1.5, "inside" eta = 1/1.5 (total internal reflection past 41.8 degrees at a smooth surface).
Energy (importance) is counted, not radiance: the 1/eta^2 of refracted radiance cancels on a path that
enters and leaves a closed object. R + T < 1 is the energy single scattering loses; Cycles'
MULTI_GGX glass (bsdf_microfacet_multi.h, a random walk on the microsurface, Heitz et al. 2016)
returns it.

With --furnace, each glass sphere of LAYOUT seen by WRAPPER's camera is traced as a perfect sphere
in a white furnace (uniform sky, nothing else) with either model, and the mean radiance over the
disc compare.py scores (0.7 of the projected radius) is printed in units of the sky's: what the
case glass-furnace should measure if each renderer implements its model (the renderers' spheres are
64 x 32 facets with interpolated normals).
"""
import argparse

import numpy as np

ETA = 1.5


def fresnel(c, eta):
    """Unpolarised Fresnel reflectance for cos c (> 0) on the incident side, eta = n_t / n_i."""
    g2 = eta * eta - 1 + c * c
    g = np.sqrt(np.maximum(g2, 0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1) / (c * (g - c) + 1)
    return np.where(g2 <= 0, 1.0, 0.5 * a * a * (1 + b * b))


def g1(cos, alpha):
    cos = np.abs(cos)
    t2 = (1 - cos * cos) / np.maximum(cos * cos, 1e-12)
    return 2 / (1 + np.sqrt(1 + alpha * alpha * t2))


def sample_vndf(wo, alpha, u1, u2):
    """Heitz 2018: normals of the GGX surface of roughness alpha visible from wo (wo.z > 0; one
    direction, or one per sample as rows)."""
    wo = np.broadcast_to(wo, (len(u1), 3))
    vh = np.stack([alpha * wo[:, 0], alpha * wo[:, 1], wo[:, 2]], axis=1)
    vh /= np.linalg.norm(vh, axis=1, keepdims=True)
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    inv = np.where(lensq > 0, 1 / np.sqrt(np.maximum(lensq, 1e-30)), 0)
    t1 = np.where((lensq > 0)[:, None], np.stack([-vh[:, 1] * inv, vh[:, 0] * inv, 0 * inv], axis=1),
                  np.array([[1.0, 0, 0]]))
    t2 = np.cross(vh, t1)
    r = np.sqrt(u1)
    phi = 2 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + vh[:, 2])
    p2 = (1 - s) * np.sqrt(1 - p1 * p1) + s * p2
    p3 = np.sqrt(np.maximum(0, 1 - p1 * p1 - p2 * p2))
    nh = p1[:, None] * t1 + p2[:, None] * t2 + p3[:, None] * vh
    n = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(1e-7, nh[:, 2])], axis=1)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def interface(theta_deg, roughness, eta, n, rng):
    """(R, T) of gilt's and of Cycles' model for wo at theta_deg from the normal, on wo's side."""
    alpha = roughness * roughness
    th = np.radians(theta_deg)
    wo = np.array([np.sin(th), 0.0, np.cos(th)])
    h = sample_vndf(wo, alpha, rng.random(n), rng.random(n))
    c = h @ wo                                            # wo.h > 0 for visible normals
    r = 2 * c[:, None] * h - wo
    k = 1 - (1 - c * c) / (eta * eta)                     # < 0: total internal reflection at h
    t = -wo / eta + (c / eta - np.sqrt(np.maximum(k, 0)))[:, None] * h
    ok_r = r[:, 2] > 0
    ok_t = (k > 0) & (t[:, 2] < 0)
    gr, gt = np.where(ok_r, g1(r[:, 2], alpha), 0), np.where(ok_t, g1(t[:, 2], alpha), 0)
    f = fresnel(c, eta)
    gilt = (np.mean(f * gr), np.mean((1 - f) * gt))
    fm = float(fresnel(np.array(wo[2]), eta))
    cycles = (fm * np.mean(gr), (1 - fm) * np.mean(gt))
    return gilt, cycles


def frame(n):
    """Rows: two tangents and n (unit normals, one per row of n)."""
    a = np.where(np.abs(n[:, :1]) > 0.9, np.array([[0.0, 1, 0]]), np.array([[1.0, 0, 0]]))
    t = np.cross(a, n)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    return t, np.cross(n, t)


def furnace_sphere(model, roughness, wrapper, layout, width, height, n, rng, max_bounces=64):
    """Mean radiance / sky radiance over each sphere's disc (0.7 of its projected radius, as
    compare.py) of a perfect glass sphere in a uniform sky, by tracing the interface `model`
    ("gilt" or "cycles") through the sphere. Each path ends in the sky with its weight."""
    cam = wrapper["camera"]
    eye, target = np.array(cam["look_from"], float), np.array(cam["look_at"], float)
    w = (target - eye) / np.linalg.norm(target - eye)
    u = np.cross(w, np.array(cam.get("up", [0, 1, 0]), float)); u /= np.linalg.norm(u)
    v = np.cross(u, w)
    half_h = np.tan(np.radians(cam.get("vfov", 40.0)) / 2)
    half_w = half_h * width / height
    alpha = roughness * roughness
    out = []
    for s in layout:
        if abs(s["roughness"] - roughness) > 1e-9:
            continue
        c, radius = np.array(s["center"], float), s["radius"]
        d = c - eye
        z = d @ w
        px, py = (d @ u) / z / half_w, (d @ v) / z / half_h              # centre, in [-1, 1] screen units
        r_scr = np.tan(np.arcsin(radius / np.linalg.norm(d))) / half_h     # projected radius, screen units (y)
        rad, phi = 0.7 * r_scr * np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
        sx, sy = px + rad * np.cos(phi) * half_h / half_w, py + rad * np.sin(phi)
        dirs = (sx * half_w)[:, None] * u + (sy * half_h)[:, None] * v + w
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        o = np.broadcast_to(eye, dirs.shape).copy()
        weight, alive, inside = np.ones(n), np.ones(n, bool), np.zeros(n, bool)
        for _ in range(max_bounces):
            # next hit with the sphere (from outside: the near root; from inside: the far one)
            oc = o - c
            b = np.sum(oc * dirs, axis=1)
            disc = b * b - (np.sum(oc * oc, axis=1) - radius * radius)
            t = np.where(inside, -b + np.sqrt(np.maximum(disc, 0)), -b - np.sqrt(np.maximum(disc, 0)))
            hit = alive & (disc > 0) & (t > 1e-6)
            alive &= hit                                                      # a miss ends in the sky
            if not alive.any():
                break
            o = np.where(hit[:, None], o + t[:, None] * dirs, o)
            nrm = (o - c) / radius
            nrm = np.where(inside[:, None], -nrm, nrm)                      # the normal on wo's side
            t1, t2 = frame(nrm)
            wo_w = -dirs
            wo = np.stack([np.sum(wo_w * t1, 1), np.sum(wo_w * t2, 1), np.sum(wo_w * nrm, 1)], axis=1)
            wo[:, 2] = np.clip(wo[:, 2], 1e-6, 1)
            eta = np.where(inside, 1 / ETA, ETA)
            wo /= np.linalg.norm(wo, axis=1, keepdims=True)
            h = sample_vndf(wo, alpha, rng.random(n), rng.random(n))
            cos = np.sum(h * wo, axis=1)
            r = 2 * cos[:, None] * h - wo
            k = 1 - (1 - cos * cos) / (eta * eta)
            tr = -wo / eta[:, None] + (cos / eta - np.sqrt(np.maximum(k, 0)))[:, None] * h
            f = fresnel(cos, eta) if model == "gilt" else fresnel(wo[:, 2], eta)
            reflect = rng.random(n) < f
            wi = np.where(reflect[:, None], r, tr)
            ok = np.where(reflect, r[:, 2] > 0, (k > 0) & (tr[:, 2] < 0))
            weight *= np.where(alive & ok, g1(wi[:, 2], alpha), np.where(alive, 0.0, 1.0))
            alive &= ok
            dirs = np.where(alive[:, None], wi[:, :1] * t1 + wi[:, 1:2] * t2 + wi[:, 2:] * nrm, dirs)
            inside = np.where(alive & ~reflect, ~inside, inside)
        weight[alive] = 0.0                                                   # still inside: cut off
        out.append(float(weight.mean()))
    return out


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--samples", type=int, default=400000)
    p.add_argument("--furnace", nargs=4, metavar=("WRAPPER", "LAYOUT", "WIDTH", "HEIGHT"),
                   help="also predict each glass sphere's disc in the white furnace of WRAPPER")
    p.add_argument("--furnace-paths", type=int, default=100000)
    o = p.parse_args()
    rng = np.random.default_rng(1)
    print("| roughness | wo | θ | gilt R / T / R+T | Cycles GGX R / T / R+T | R+T gilt / Cycles |")
    print("|---|---|---|---|---|---|")
    for rough in (0.3, 0.6):
        for side, eta, angles in (("outside", ETA, (0, 30, 60, 75, 85)), ("inside", 1 / ETA, (0, 30, 40, 45, 60))):
            for th in angles:
                (gr, gt), (cr, ct) = interface(th, rough, eta, o.samples, rng)
                print("| %g | %s | %d° | %.3f / %.3f / %.3f | %.3f / %.3f / %.3f | %.3f |" %
                      (rough, side, th, gr, gt, gr + gt, cr, ct, cr + ct, (gr + gt) / (cr + ct)))
    if o.furnace:
        import json
        with open(o.furnace[0]) as f:
            wrapper = json.load(f)
        with open(o.furnace[1]) as f:
            layout = json.load(f)
        width, height = int(o.furnace[2]), int(o.furnace[3])
        print()
        print("| sphere (perfect, in the white furnace) | gilt's model | Cycles' GGX model | gilt / Cycles |")
        print("|---|---|---|---|")
        for rough in sorted({s["roughness"] for s in layout}):
            g = furnace_sphere("gilt", rough, wrapper, layout, width, height, o.furnace_paths, rng)
            c = furnace_sphere("cycles", rough, wrapper, layout, width, height, o.furnace_paths, rng)
            for a, b in zip(g, c):
                print("| glass r=%g | %.4f | %.4f | %.3f |" % (rough, a, b, a / b))


if __name__ == "__main__":
    main()
