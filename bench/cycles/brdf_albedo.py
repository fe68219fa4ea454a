#!/usr/bin/python3
"""Directional albedo of the two BRDFs being compared, without any renderer in between.

  brdf_albedo.py [SAMPLES]

For each (metallic, roughness) of the spheres case and view angles 0, 45, 70 degrees, integrates
rho(v) = integral of f(v, l) cos(l) dl for
  gltf   - glTF 2.0 appendix B, as gilt implements it: f = (1-m)[(1-F_d) c/pi + F_d S] + m F_c S,
           S = D G1(v) G1(l) / (4 |n.v| |n.l|), Schlick F_d with F0 = 0.04, F_c = c + (1-c)(1-v.h)^5
  cycles - Blender 3.4's Principled BSDF as its glTF importer sets it up (specular 0.5, tint 0,
           distribution GGX): (1-m) c * Burley diffuse with roughness retro-reflection, plus
           F S with F = mix(cspec0, 1, (F_dielectric(l.h, 1.5) - 0.04) / 0.96),
           cspec0 = 0.04 (1-m) + m c; the diffuse is not weighted by 1 - F
and prints the per-channel ratio gltf / cycles (base colour (0.8, 0.4, 0.2)). Single scattering only.
A short table gives the ratio of the two BRDF values themselves at a few dielectric (view, light)
pairs, grazing and retro-reflecting ones included.
A second table estimates, for the metals, what Cycles' multiple-scattering GGX (MULTI_GGX, a random
walk the importer does not select) adds, by Kulla & Conty's 2017 approximation: the energy single
scattering loses, 1 - E(mu) for a white metal, returned with the colour F_avg^2 E_avg /
(1 - F_avg (1 - E_avg)), F_avg = c + (1 - c) / 21 (Schlick's hemispherical average).
Monte Carlo with multiple importance sampling of a cosine lobe and GGX visible normals.
"""
import sys

import numpy as np

BASE = np.array([0.8, 0.4, 0.2])


def dot(a, b):
    return (a * b).sum(axis=-1)


def normalize(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def ggx_d(h, a2):
    c2 = h[..., 2] ** 2
    return a2 / (np.pi * (c2 * (a2 - 1) + 1) ** 2)


def ggx_g1(w, a2):
    c2 = np.clip(w[..., 2] ** 2, 1e-12, 1)
    return 2 / (1 + np.sqrt(1 + a2 * (1 - c2) / c2))


def sample_vndf(v, alpha, u1, u2):
    """Heitz 2018: visible normals of GGX seen from v (N x 3, +z hemisphere), one per row."""
    vh = normalize(np.stack([alpha * v[:, 0], alpha * v[:, 1], v[:, 2]], -1))
    lensq = vh[:, 0] ** 2 + vh[:, 1] ** 2
    inv = np.where(lensq > 1e-12, 1 / np.sqrt(np.maximum(lensq, 1e-24)), 0.0)
    t1 = np.where((lensq > 1e-12)[:, None], np.stack([-vh[:, 1] * inv, vh[:, 0] * inv, 0 * inv], -1), [1.0, 0, 0])
    t2 = np.cross(vh, t1)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1 + vh[:, 2])
    p2 = (1 - s) * np.sqrt(np.clip(1 - p1 ** 2, 0, 1)) + s * p2
    nh = p1[:, None] * t1 + p2[:, None] * t2 + np.sqrt(np.clip(1 - p1 ** 2 - p2 ** 2, 0, 1))[:, None] * vh
    return normalize(np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(nh[:, 2], 1e-7)], -1))


def fresnel_dielectric(c, eta):
    g2 = eta * eta - 1 + c * c
    g = np.sqrt(np.maximum(g2, 0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1) / (c * (g - c) + 1)
    return np.where(g2 > 0, 0.5 * a * a * (1 + b * b), 1.0)


def brdf(model, v, l, m, r, base=BASE):
    """f(v, l) per channel (N x 3) for rows of v and l in the shading frame (normal +z); 0 below."""
    a2 = max(r * r, 1e-3) ** 2
    v = np.broadcast_to(v, l.shape)
    h = normalize(v + l)
    cv, cl = v[:, 2], l[:, 2]
    ok = (cv > 1e-9) & (cl > 1e-9)
    vh = np.clip(dot(h, v), 0, 1)   # v.h = l.h
    S = np.where(ok, ggx_d(h, a2) * ggx_g1(v, a2) * ggx_g1(l, a2) / (4 * np.maximum(cv * cl, 1e-12)), 0)[:, None]
    w5 = ((1 - vh) ** 5)[:, None]
    if model == "gltf":
        Fd = 0.04 + 0.96 * w5
        Fc = base + (1 - base) * w5
        f = (1 - m) * ((1 - Fd) * base / np.pi + Fd * S) + m * Fc * S
    else:
        FL, FV = (1 - np.clip(cl, 0, 1)) ** 5, (1 - np.clip(cv, 0, 1)) ** 5
        RR = r * (dot(l, v) + 1)
        burley = ((1 - 0.5 * FL) * (1 - 0.5 * FV) + RR * (FL + FV + FL * FV * (RR - 1))) / np.pi
        fn = ((fresnel_dielectric(vh, 1.5) - 0.04) / 0.96)[:, None]
        cspec0 = 0.04 * (1 - m) + m * base
        F = cspec0 * (1 - fn) + fn
        f = (1 - m) * base * burley[:, None] + F * S
    return np.where(ok[:, None], f, 0)


def sample_lobes(v, m, r, rng):
    """Directions l for rows of v, drawn from an even mix of a cosine lobe and GGX's visible normals,
    with their mixture pdf (one-sample MIS: f cos / pdf is an unbiased estimate of the albedo)."""
    n = len(v)
    alpha = max(r * r, 1e-3); a2 = alpha * alpha
    u = rng.random((n, 3))
    ct = np.sqrt(u[:, 0]); st = np.sqrt(1 - u[:, 0]); ph = 2 * np.pi * u[:, 1]
    l_cos = np.stack([st * np.cos(ph), st * np.sin(ph), ct], -1)
    h = sample_vndf(v, alpha, *rng.random((2, n)))
    l_spec = 2 * dot(h, v)[:, None] * h - v
    l = np.where((u[:, 2] < 0.5)[:, None], l_cos, l_spec)
    hh = normalize(v + l)
    pdf_cos = np.maximum(l[:, 2], 0) / np.pi
    pdf_spec = ggx_g1(v, a2) * ggx_d(hh, a2) / (4 * v[:, 2])
    return l, 0.5 * pdf_cos + 0.5 * pdf_spec


def albedo(model, theta_deg, m, r, n, rng):
    t = np.radians(theta_deg)
    v = np.tile([np.sin(t), 0.0, np.cos(t)], (n, 1))
    l, pdf = sample_lobes(v, m, r, rng)
    f = brdf(model, v, l, m, r)
    return (f * np.maximum(l[:, 2:3], 0) / pdf[:, None]).sum(axis=0) / n


def multiple_scattering(n, rng):
    """Kulla-Conty estimate of single / (single + multiple) scattering albedo for the metals."""
    white = np.ones(3)

    def e_white(theta_deg, r):
        t = np.radians(theta_deg)
        v = np.tile([np.sin(t), 0.0, np.cos(t)], (n // 4, 1))
        l, pdf = sample_lobes(v, 1.0, r, rng)
        return (brdf("gltf", v, l, 1.0, r, white)[:, 0] * np.maximum(l[:, 2], 0) / pdf).mean()

    print()
    print("| metallic 1, roughness | view | E white (single) | E_avg | albedo single | "
          "+ multiple (Kulla-Conty) | ratio single / both |")
    print("|---|---|---|---|---|---|---|")
    for r in (0.5, 0.7, 1.0):
        mus = (np.arange(32) + 0.5) / 32
        e_avg = 2 * np.mean([e_white(np.degrees(np.arccos(mu)), r) * mu for mu in mus])
        f_avg = BASE + (1 - BASE) / 21
        f_ms = f_avg ** 2 * e_avg / (1 - f_avg * (1 - e_avg))
        for th in (0, 45, 70):
            single = albedo("gltf", th, 1.0, r, n, rng)
            e = e_white(th, r)
            both = single + (1 - e) * f_ms
            fmt = lambda x: " ".join("%.3f" % y for y in x)
            print("| %g | %d° | %.3f | %.3f | %s | %s | %s |" % (r, th, e, e_avg, fmt(single), fmt(both),
                                                               fmt(single / both)))


def point_ratios():
    """f_gltf / f_cycles for a few dielectric (view, light) pairs: where Burley's retro-reflection counts."""
    print()
    print("| metallic 0, roughness | view | light | light azimuth from view | f glTF / f Cycles R G B |")
    print("|---|---|---|---|---|")
    for tv, tl, phi in ((0, 45, 0), (60, 60, 0), (80, 40, 180), (80, 40, 0), (80, 80, 0)):
        a, b, p = np.radians([tv, tl, phi])
        v = np.array([[np.sin(a), 0, np.cos(a)]])
        l = np.array([[np.sin(b) * np.cos(p), np.sin(b) * np.sin(p), np.cos(b)]])
        for r in (0.5, 1.0):
            ratio = brdf("gltf", v, l, 0, r)[0] / brdf("cycles", v, l, 0, r)[0]
            print("| %g | %d° | %d° | %d° | %s |" % (r, tv, tl, phi, " ".join("%.3f" % x for x in ratio)))


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 400000
    rng = np.random.default_rng(1)
    print("| metallic | roughness | view | albedo glTF (gilt) | albedo Cycles 3.4 Principled GGX | ratio |")
    print("|---|---|---|---|---|---|")
    for m in (0.0, 0.5, 1.0):
        for r in (0.1, 0.3, 0.5, 0.7, 1.0):
            for th in (0, 45, 70):
                g = albedo("gltf", th, m, r, n, rng)
                c = albedo("cycles", th, m, r, n, rng)
                fmt = lambda x: " ".join("%.3f" % y for y in x)
                print("| %g | %g | %d° | %s | %s | %s |" % (m, r, th, fmt(g), fmt(c), fmt(g / c)))
    point_ratios()
    multiple_scattering(n, rng)


if __name__ == "__main__":
    main()
