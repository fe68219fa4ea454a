#!/usr/bin/python3
"""A helmet-class PBR model with five 2048² textures, and the same model without them.

    /usr/bin/python3 bench/scenes/textured_model.py OUT_DIR [--seed 59] [--size 2048]

Writes into OUT_DIR:
  model.gltf, model.bin        14,336 triangles in four parts (shell, visor, neck ring, two ear
                               cups) sharing one metallic-roughness material that names all five
                               textures, as glTF sample models of this class do
  base_color.png               sRGB colour: painted panels, scratches, grime
  metallic_roughness.png       linear: roughness in green, metalness in blue (glTF's packing)
  normal.png                   tangent-space normals of the panels' grooves, rivets and noise
  emissive.jpg                 sRGB: a few glowing strips on black
  occlusion.jpg                linear: ambient occlusion baked into the grooves (glTF readers that
                               trace light, gilt and Cycles among them, do not apply it)
  untextured.gltf              the same geometry (model.bin) and material with no textures; each
                               factor is the mean of the texture it replaces, so both models
                               reflect about as much light and paths are about as long
  textured.json, untextured.json   gilt scenes: a sun, a sky and a camera framing the model
  five_files.obj, five_files.mtl   two triangles whose two materials name all five images (map_Kd,
                               map_d, map_Ke and norm; bump): the load benchmark, since a glTF
                               reader that traces light leaves the occlusion image unread

The textures are built from seeded noise (numpy's PCG64 with --seed), so the same arguments
write the same texels on any machine. They are not smooth gradients: fine noise and scratches
keep the PNGs about as hard to decode as photographed textures (several MB each). Needs numpy and
OpenImageIO's Python module (Debian: python3-numpy, python3-openimageio).
"""

import argparse
import json
import math
import os
import struct
import sys

import numpy as np
import OpenImageIO as oiio


# ---------------------------------------------------------------------------------------------
# Textures.


def value_noise(rng, size, cells):
    """Smooth noise in [0, 1]: a random cells × cells grid, bicubically resized to size²."""
    grid = rng.random((cells, cells), dtype=np.float32)
    src = oiio.ImageBuf(oiio.ImageSpec(cells, cells, 1, oiio.FLOAT))
    src.set_pixels(oiio.ROI(0, cells, 0, cells, 0, 1, 0, 1), grid[:, :, None])
    dst = oiio.ImageBufAlgo.resize(src, roi=oiio.ROI(0, size, 0, size, 0, 1, 0, 1), filtername="catmull-rom")
    return np.clip(dst.get_pixels(oiio.FLOAT)[:, :, 0], 0.0, 1.0)


def fractal(rng, size, octaves=(8, 32, 128, 512)):
    total, weight = np.zeros((size, size), np.float32), 0.0
    for i, cells in enumerate(octaves):
        w = 0.5**i
        total += w * value_noise(rng, size, cells)
        weight += w
    return total / weight


def panels(size, count):
    """Per texel: the panel's index (count × count grid) and the distance to its nearest edge in
    panel widths (0 at a seam, 0.5 at the centre)."""
    coord = (np.arange(size, dtype=np.float32) + 0.5) / size * count
    fx, fy = np.meshgrid(coord, coord)
    index = np.floor(fy).astype(np.int32) * count + np.floor(fx).astype(np.int32)
    gx, gy = fx - np.floor(fx), fy - np.floor(fy)
    edge = np.minimum(np.minimum(gx, 1 - gx), np.minimum(gy, 1 - gy))
    return index, edge, gx, gy


def scratches(rng, size, count):
    """A mask of thin straight scratches."""
    mask = np.zeros((size, size), np.float32)
    for _ in range(count):
        x0, y0 = rng.random(2) * size
        angle = rng.random() * math.pi
        length = 20 + rng.random() * size / 8
        t = np.linspace(0, length, int(length * 2))
        xs = np.clip((x0 + t * math.cos(angle)).astype(int), 0, size - 1)
        ys = np.clip((y0 + t * math.sin(angle)).astype(int), 0, size - 1)
        mask[ys, xs] = 1.0
    return mask


def write_image(path, pixels, quality=None):
    """Writes an 8-bit image from values in [0, 1] (height × width × channels)."""
    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, oiio.UINT8)
    if quality is not None:
        spec.attribute("Compression", "jpeg:%d" % quality)
    out = oiio.ImageOutput.create(path)
    if not out or not out.open(path, spec):
        sys.exit("cannot write %s: %s" % (path, oiio.geterror()))
    out.write_image(np.round(np.clip(pixels, 0, 1) * 255).astype(np.uint8))
    out.close()


def srgb_to_linear(x):
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def make_textures(out, rng, size):
    """Writes the five images; returns the linear mean of each as the untextured factors."""
    n_panels = 12
    index, edge, gx, gy = panels(size, n_panels)
    paint = rng.random((n_panels * n_panels, 3)).astype(np.float32)
    palette = np.array([[0.55, 0.56, 0.58], [0.35, 0.30, 0.22], [0.70, 0.62, 0.40], [0.20, 0.22, 0.25]], np.float32)
    panel_colour = palette[(paint[:, 0] * len(palette)).astype(int)] * (0.8 + 0.4 * paint[:, 1:2])
    metal_panel = paint[:, 2] > 0.55
    grime = fractal(rng, size)
    fine = rng.random((size, size), dtype=np.float32)
    scratch = scratches(rng, size, 600)
    seam = np.clip(edge * 60.0, 0.0, 1.0)  # 0 in a groove a sixtieth of a panel wide

    # Base colour (sRGB as stored): the panel's paint, darkened by grime and grooves, scratches
    # showing bright metal.
    base = panel_colour[index] * (0.65 + 0.35 * grime)[:, :, None] * (0.85 + 0.15 * fine)[:, :, None]
    base *= (0.4 + 0.6 * seam)[:, :, None]
    base = base * (1 - scratch[:, :, None]) + 0.8 * scratch[:, :, None]
    write_image(os.path.join(out, "base_color.png"), base)

    # Metallic-roughness: R unused (0), G roughness, B metalness.
    metal = np.where(metal_panel[index], 1.0, 0.0).astype(np.float32)
    metal = np.maximum(metal, scratch)
    rough = np.clip(0.25 + 0.5 * grime + 0.1 * (fine - 0.5) - 0.2 * scratch, 0.05, 1.0)
    mr = np.stack([np.zeros_like(rough), rough, metal], axis=2)
    write_image(os.path.join(out, "metallic_roughness.png"), mr)

    # Normals from a height field: grooves at the seams, a rivet near each panel's corners, noise.
    rivet = np.zeros_like(edge)
    for cx in (0.12, 0.88):
        for cy in (0.12, 0.88):
            d = np.hypot(gx - cx, gy - cy)
            rivet = np.maximum(rivet, np.clip(1 - d / 0.04, 0, 1))
    height = 0.6 * seam + 0.3 * rivet + 0.05 * grime + 0.01 * fine
    dy, dx = np.gradient(height * (size / 64.0))
    normal = np.stack([-dx, -dy, np.ones_like(dx)], axis=2)
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    write_image(os.path.join(out, "normal.png"), normal * 0.5 + 0.5)

    # Emission: three glowing strips across some panels, black elsewhere.
    emissive = np.zeros((size, size, 3), np.float32)
    for p in rng.choice(n_panels * n_panels, 6, replace=False):
        strip = (index == p) & (np.abs(gy - 0.5) < 0.06) & (np.abs(gx - 0.5) < 0.35)
        emissive[strip] = [0.2, 0.8, 1.0]
    write_image(os.path.join(out, "emissive.jpg"), emissive, quality=92)

    # Occlusion: dark in the grooves and under grime.
    occlusion = np.clip(0.55 + 0.45 * seam * (0.8 + 0.2 * grime), 0, 1)
    write_image(os.path.join(out, "occlusion.jpg"), np.repeat(occlusion[:, :, None], 3, axis=2), quality=92)

    # The factors that replace the textures: means of the values as stored, read back from the
    # files (8-bit codes and JPEG's loss included), colour textures decoded to linear first.
    def read(name):
        return oiio.ImageBuf(os.path.join(out, name)).get_pixels(oiio.FLOAT)

    base_linear = srgb_to_linear(read("base_color.png")[:, :, :3]).reshape(-1, 3).mean(axis=0)
    mr_mean = read("metallic_roughness.png").reshape(-1, 3).mean(axis=0)
    emissive_linear = srgb_to_linear(read("emissive.jpg")[:, :, :3]).reshape(-1, 3).mean(axis=0)
    return {
        "base": [float(v) for v in base_linear],
        "roughness": float(mr_mean[1]),
        "metallic": float(mr_mean[2]),
        "emissive": [float(v) for v in emissive_linear],
    }


# ---------------------------------------------------------------------------------------------
# Geometry: parametric patches on a grid, each in its own rectangle of the texture atlas.


def grid_patch(f, nu, nv, atlas, positions, normals, uvs, indices, flip=False):
    """Samples f(u, v) → point on an (nu + 1) × (nv + 1) grid; normals by central differences."""
    first = len(positions)
    eps = 1e-4
    for j in range(nv + 1):
        for i in range(nu + 1):
            u, v = i / nu, j / nv
            p = np.array(f(u, v))
            du = np.array(f(min(u + eps, 1), v)) - np.array(f(max(u - eps, 0), v))
            dv = np.array(f(u, min(v + eps, 1))) - np.array(f(u, max(v - eps, 0)))
            n = np.cross(du, dv)
            length = np.linalg.norm(n)
            n = n / length if length > 1e-12 else np.array([0.0, 1.0, 0.0])
            positions.append(p)
            normals.append(-n if flip else n)
            x0, y0, x1, y1 = atlas
            uvs.append((x0 + (x1 - x0) * u, y0 + (y1 - y0) * v))
    for j in range(nv):
        for i in range(nu):
            a = first + j * (nu + 1) + i
            b, c, d = a + 1, a + nu + 1, a + nu + 2
            quad = [(a, b, d), (a, d, c)]
            for t in quad:
                indices.append((t[0], t[2], t[1]) if flip else t)


def make_geometry():
    positions, normals, uvs, indices = [], [], [], []

    def shell(u, v):  # a helmet dome: from the crown (v = 0) to below the equator
        phi = 2 * math.pi * u
        theta = 0.05 + v * 0.62 * math.pi
        r = 1.0 + 0.04 * math.cos(3 * theta)
        return (r * math.sin(theta) * math.cos(phi), 0.2 + r * math.cos(theta) * 1.1, r * math.sin(theta) * math.sin(phi) * 1.05)

    def visor(u, v):  # a band in front, a little outside the shell
        phi = math.pi * (0.2 + 0.6 * u)
        theta = math.pi * (0.38 + 0.22 * v)
        r = 1.08
        return (r * math.sin(theta) * math.cos(phi), 0.2 + r * math.cos(theta) * 1.1, r * math.sin(theta) * math.sin(phi) * 1.05)

    def ring(u, v):  # the neck ring under the shell: a torus
        phi = 2 * math.pi * u
        psi = 2 * math.pi * v
        R, r = 0.72, 0.12
        return ((R + r * math.cos(psi)) * math.cos(phi), -0.55 + r * math.sin(psi), (R + r * math.cos(psi)) * math.sin(phi))

    def ear(side):
        def f(u, v):  # a capped cylinder along x
            phi = 2 * math.pi * u
            rad = 0.25 * min(1.0, 4 * v, 4 * (1 - v)) + 1e-3
            x = side * (0.98 + 0.12 * v)
            return (x, 0.05 + rad * math.cos(phi), rad * math.sin(phi))

        return f

    grid_patch(shell, 96, 48, (0.0, 0.0, 1.0, 0.5), positions, normals, uvs, indices)
    grid_patch(visor, 48, 16, (0.0, 0.5, 0.5, 0.75), positions, normals, uvs, indices, flip=True)
    grid_patch(ring, 64, 16, (0.5, 0.5, 1.0, 0.75), positions, normals, uvs, indices)
    grid_patch(ear(1), 32, 12, (0.0, 0.75, 0.5, 1.0), positions, normals, uvs, indices, flip=True)
    grid_patch(ear(-1), 32, 12, (0.5, 0.75, 1.0, 1.0), positions, normals, uvs, indices)
    return (np.array(positions, np.float32), np.array(normals, np.float32), np.array(uvs, np.float32),
            np.array(indices, np.uint32))


# ---------------------------------------------------------------------------------------------
# glTF.


def write_gltf(out, geometry, factors):
    positions, normals, uvs, indices = geometry
    blobs = [positions.tobytes(), normals.tobytes(), uvs.tobytes(), indices.tobytes()]
    offsets, data = [], b""
    for blob in blobs:
        offsets.append(len(data))
        data += blob + b"\0" * ((-len(blob)) % 4)
    with open(os.path.join(out, "model.bin"), "wb") as f:
        f.write(data)
    views = [{"buffer": 0, "byteOffset": o, "byteLength": len(b)} for o, b in zip(offsets, blobs)]
    n = len(positions)
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
         "min": [float(v) for v in positions.min(axis=0)], "max": [float(v) for v in positions.max(axis=0)]},
        {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5125, "count": int(indices.size), "type": "SCALAR"},
    ]
    base = {
        "asset": {"version": "2.0", "generator": "gilt bench/scenes/textured_model.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "helmet"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                    "indices": 3, "material": 0}]}],
        "buffers": [{"uri": "model.bin", "byteLength": len(data)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    names = ["base_color.png", "metallic_roughness.png", "normal.png", "emissive.jpg", "occlusion.jpg"]
    textured = dict(base)
    textured["images"] = [{"uri": name} for name in names]
    textured["samplers"] = [{"wrapS": 10497, "wrapT": 10497, "minFilter": 9987, "magFilter": 9729}]
    textured["textures"] = [{"sampler": 0, "source": i} for i in range(len(names))]
    textured["materials"] = [{
        "name": "helmet",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1},
                                 "metallicFactor": 1.0, "roughnessFactor": 1.0},
        "normalTexture": {"index": 2},
        "emissiveTexture": {"index": 3},
        "emissiveFactor": [1.0, 1.0, 1.0],
        "occlusionTexture": {"index": 4},
    }]
    untextured = dict(base)
    untextured["materials"] = [{
        "name": "helmet",
        "pbrMetallicRoughness": {"baseColorFactor": factors["base"] + [1.0],
                                 "metallicFactor": factors["metallic"], "roughnessFactor": factors["roughness"]},
        "emissiveFactor": factors["emissive"],
    }]
    for name, doc in (("model.gltf", textured), ("untextured.gltf", untextured)):
        with open(os.path.join(out, name), "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
    return len(indices)


def write_scenes(out):
    for name in ("textured", "untextured"):
        model = "model.gltf" if name == "textured" else "untextured.gltf"
        scene = {
            "meshes": [{"file": model}],
            "lights": [
                {"type": "directional", "direction": [-0.4, -1, -0.6], "irradiance": 3},
                {"type": "environment", "radiance": 0.4},
            ],
            "camera": {"look_from": [1.6, 0.9, 3.4], "look_at": [0, 0.05, 0], "up": [0, 1, 0], "vfov": 38},
        }
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(scene, f, indent=1)
            f.write("\n")


def write_five_files(out):
    with open(os.path.join(out, "five_files.mtl"), "w") as f:
        f.write("newmtl four\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Kd base_color.png\nmap_d metallic_roughness.png\n"
                "map_Ke emissive.jpg\nnorm normal.png\n\nnewmtl fifth\nKd 0.5 0.5 0.5\nbump occlusion.jpg\n")
    with open(os.path.join(out, "five_files.obj"), "w") as f:
        f.write("mtllib five_files.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                "vn 0 0 1\nusemtl four\nf 1/1/1 2/2/1 3/3/1\nusemtl fifth\nf 1/1/1 3/3/1 4/4/1\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out")
    parser.add_argument("--seed", type=int, default=59)
    parser.add_argument("--size", type=int, default=2048, help="texels on a texture's side")
    args = parser.parse_args()
    if args.size < 64:
        sys.exit("--size must be at least 64")
    os.makedirs(args.out, exist_ok=True)
    rng = np.random.Generator(np.random.PCG64(args.seed))
    factors = make_textures(args.out, rng, args.size)
    triangles = write_gltf(args.out, make_geometry(), factors)
    write_scenes(args.out)
    write_five_files(args.out)
    print("%s: %d triangles, five %d² textures; factors of the untextured model %s"
          % (args.out, triangles, args.size, json.dumps(factors)))


if __name__ == "__main__":
    main()
