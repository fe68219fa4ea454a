#!/usr/bin/python3
"""Scores gilt against Cycles on one case and writes a side-by-side PNG.

  compare.py --label NAME --wrapper WRAPPER.json --gilt G1.exr G2.exr --cycles C1.exr C2.exr \
      --out-png SIDE.png [--spheres LAYOUT.json] [--mask NAME=MASK.exr] [--seconds-gilt S] [--seconds-cycles S]
      [--json OUT.json]

Each renderer made two independent renders of half the samples (different seeds); the image scored
is their mean and the half-difference gives each pixel's own noise: for a = (a1 + a2) / 2,
var(a) ~ (a1 - a2)^2 / 4. Cycles' film is transparent; its alpha is the geometry's coverage and the
uniform background radiance is added back as rgb + (1 - alpha) L, which is exact for a constant sky.

Regions: "image" (every pixel), "objects" (alpha > 0.999 in both Cycles halves: pixels that do not
see the background), and with --spheres one disc per sphere (0.7 of its projected radius, inside
"objects"; named by the layout's "label", else by metallic and roughness), and with --mask the
pixels a render of part of the scene covers (alpha > 0.999), inside "objects", in all, where
Cycles' colour is saturated ((max - min) / max > 0.5) and where it is grey
(< 0.1). Per region and channel: mean ratio gilt / Cycles with its 1-sigma noise (from the
per-pixel variances, pixels being independent), and relMSE = mean((a - b)^2 / (b^2 + 1e-2)) next to
the value noise alone would give, mean((var a + var b) / (b^2 + 1e-2)).
Prints one markdown table row per region; needs python3-openimageio and python3-numpy.
"""
import argparse
import json
import math

import numpy as np
import OpenImageIO as oiio


def read(path):
    buf = oiio.ImageBuf(path)
    px = buf.get_pixels(oiio.FLOAT)
    if px is None or px.size == 0:
        raise SystemExit("compare.py: cannot read " + path + ": " + buf.geterror())
    return np.asarray(px, dtype=np.float64)


def srgb8(rgb):
    x = np.clip(rgb, 0.0, None)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(s, 0, 1) * 255 + 0.5).astype(np.uint8)


def ratio_colour(a, b, stops=0.5):
    """log2 of the luminance ratio a/b on a blue (a darker) - white - red (a brighter) scale."""
    w = np.array([0.2126, 0.7152, 0.0722])
    la, lb = a @ w, b @ w
    t = np.clip(np.log2((la + 1e-4) / (lb + 1e-4)) / stops, -1, 1)[..., None]
    white, red, blue = np.ones(3), np.array([0.85, 0.1, 0.1]), np.array([0.1, 0.25, 0.85])
    c = np.where(t > 0, white + t * (red - white), white - t * (blue - white))
    return (c * 255 + 0.5).astype(np.uint8)


def write_png(path, panels, gap=4):
    h = panels[0].shape[0]
    row = []
    for i, p in enumerate(panels):
        if i:
            row.append(np.full((h, gap, 3), 255, np.uint8))
        row.append(p)
    img = np.concatenate(row, axis=1)
    out = oiio.ImageBuf(oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.UINT8))
    out.set_pixels(oiio.ROI(), img)
    if not out.write(path):
        raise SystemExit("compare.py: cannot write " + path + ": " + out.geterror())


def sphere_masks(spheres, cam, width, height):
    """Pixel discs inside each sphere's silhouette, from gilt's pinhole camera model."""
    eye, target = np.array(cam["look_from"], float), np.array(cam["look_at"], float)
    up = np.array(cam.get("up", [0, 1, 0]), float)
    w = (target - eye) / np.linalg.norm(target - eye)
    u = np.cross(w, up); u /= np.linalg.norm(u)
    v = np.cross(u, w)
    half_h = math.tan(math.radians(cam.get("vfov", 40.0)) / 2)
    half_w = half_h * width / height
    ys, xs = np.mgrid[0:height, 0:width] + 0.5
    masks = []
    for s in spheres:
        d = np.array(s["center"], float) - eye
        z = d @ w
        px = ((d @ u) / z / half_w + 1) / 2 * width
        py = (1 - (d @ v) / z / half_h) / 2 * height
        r_px = math.tan(math.asin(s["radius"] / np.linalg.norm(d))) / half_h * height / 2
        masks.append((s, (xs - px) ** 2 + (ys - py) ** 2 <= (0.7 * r_px) ** 2))
    return masks


def score(a, b, var_a, var_b, mask):
    n = int(mask.sum())
    A, B, VA, VB = a[mask], b[mask], var_a[mask], var_b[mask]
    ma, mb = A.mean(axis=0), B.mean(axis=0)
    ratio = ma / mb
    # sigma of a region mean = sqrt(sum of pixel variances) / n; relative sigmas add in quadrature
    rel = np.sqrt(VA.sum(axis=0) / n ** 2 / ma ** 2 + VB.sum(axis=0) / n ** 2 / mb ** 2)
    denom = B ** 2 + 1e-2
    return {"pixels": n, "mean_gilt": ma.tolist(), "mean_cycles": mb.tolist(),
            "sigma_gilt": (np.sqrt(VA.sum(axis=0)) / n).tolist(), "sigma_cycles": (np.sqrt(VB.sum(axis=0)) / n).tolist(),
            "ratio": ratio.tolist(),
            "ratio_sigma": (ratio * rel).tolist(),
            "relmse": float(((A - B) ** 2 / denom).mean()), "relmse_noise": float(((VA + VB) / denom).mean()),
            "pixel_noise_gilt": float(np.sqrt((VA / denom).mean())),
            "pixel_noise_cycles": float(np.sqrt((VB / denom).mean()))}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--label", required=True)
    p.add_argument("--wrapper", required=True)
    p.add_argument("--gilt", nargs=2, required=True)
    p.add_argument("--cycles", nargs=2, required=True)
    p.add_argument("--out-png", required=True)
    p.add_argument("--spheres")
    p.add_argument("--mask", action="append", default=[], help="NAME=a render whose alpha covers the region")
    p.add_argument("--seconds-gilt", type=float, default=float("nan"))
    p.add_argument("--seconds-cycles", type=float, default=float("nan"))
    p.add_argument("--json")
    o = p.parse_args()

    wrapper = json.load(open(o.wrapper))
    sky = np.zeros(3)
    for light in wrapper.get("lights", []):
        if light["type"] == "environment":
            sky = np.broadcast_to(np.array(light["radiance"], float), (3,))
    g1, g2 = (read(f)[..., :3] for f in o.gilt)
    c1, c2 = (read(f) for f in o.cycles)
    if g1.shape[:2] != c1.shape[:2]:
        raise SystemExit("compare.py: image sizes differ: gilt %s, Cycles %s" % (g1.shape, c1.shape))
    objects = (c1[..., 3] > 0.999) & (c2[..., 3] > 0.999)
    c1, c2 = (c[..., :3] + (1 - c[..., 3:4]) * sky for c in (c1, c2))
    a, b = (g1 + g2) / 2, (c1 + c2) / 2
    var_a, var_b = (g1 - g2) ** 2 / 4, (c1 - c2) ** 2 / 4
    height, width = a.shape[:2]

    regions = [("image", np.ones((height, width), bool)), ("objects", objects)]
    if o.spheres:
        for s, m in sphere_masks(json.load(open(o.spheres)), wrapper["camera"], width, height):
            label = s.get("label", "sphere m=%g r=%g" % (s["metallic"], s["roughness"]))
            regions.append((label, m & objects))
    # Saturation of Cycles' pixels: a textured region split into its colourful and its grey pixels
    # has the same ratio in both only if both renderers decode the texture's colours alike.
    sat = (b.max(axis=-1) - b.min(axis=-1)) / (b.max(axis=-1) + 1e-6)
    for arg in o.mask:
        name, path = arg.split("=", 1)
        mask = (read(path)[..., 3] > 0.999) & objects
        regions += [(name, mask), (name + ": saturated colours", mask & (sat > 0.5) & (b.max(axis=-1) > 0.05)),
                    (name + ": greys", mask & (sat < 0.1))]

    results = []
    for name, mask in regions:
        r = score(a, b, var_a, var_b, mask)
        r.update({"case": o.label, "region": name, "seconds_gilt": o.seconds_gilt, "seconds_cycles": o.seconds_cycles})
        results.append(r)
        ratio = " / ".join("%.3f±%.3f" % (x, s) for x, s in zip(r["ratio"], r["ratio_sigma"]))
        secs = "%.0f / %.0f" % (o.seconds_gilt, o.seconds_cycles) if name == "image" else ""
        print("| %s | %s | %d | %s | %.4f | %.4f | %.1f %% / %.1f %% | %s |" %
              (o.label, name, r["pixels"], ratio, r["relmse"], r["relmse_noise"],
               100 * r["pixel_noise_gilt"], 100 * r["pixel_noise_cycles"], secs))
    if o.json:
        json.dump(results, open(o.json, "w"), indent=1)
    write_png(o.out_png, [srgb8(a), srgb8(b), ratio_colour(a, b)])


if __name__ == "__main__":
    main()
