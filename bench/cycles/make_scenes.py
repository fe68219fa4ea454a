#!/usr/bin/env python3
"""Writes the synthetic glTF files of the Cycles comparison (plain Python, no dependencies).

  make_scenes.py OUT_DIR

OUT_DIR/spheres.gltf  a 5 x 3 grid of UV spheres (32 x 16 segments, smooth normals) resting on
                      a grey ground square: columns roughness 0.1, 0.3, 0.5, 0.7, 1.0, rows (front
                      to back) metallic 0, 0.5, 1, base colour (0.8, 0.4, 0.2)
OUT_DIR/ground.gltf   the ground square alone (16 x 16, centred on the origin), put under the milk
                      truck and used alone as the light calibration case
The ground is Lambertian with albedo 0.5 in both renderers: metallic 0 with KHR_materials_specular's
specularFactor 0, which gilt reads as its diffuse material and cycles_render.py turns into a Diffuse
BSDF. So the ground's radiance has a closed form, the same in both, and only the spheres' and the
truck's materials differ between the two renderers' models.
OUT_DIR/spheres-layout.json  each sphere's centre, radius, metallic and roughness, for per-sphere figures
OUT_DIR/furnace.gltf, furnace-layout.json  the same 15 spheres without the ground, 2.5 units apart,
                      so that each sees almost nothing but the lights: under a directional light and
                      a uniform sky their radiance is a closed form of the BRDF (sphere_model.py)
OUT_DIR/lone.gltf, lone-layout.json  the ground and the rough metal sphere (metallic 1, roughness 1)
                      of spheres.gltf alone, where it was: the grid without the neighbours
OUT_DIR/glass.gltf, glass-layout.json  three solid glass spheres (radius 0.5, 64 x 32 segments) in a
                      row on the ground, left to right roughness 0, 0.3 and 0.6: base colour white,
                      metallic 0, KHR_materials_transmission 1, KHR_materials_ior 1.5 and
                      KHR_materials_volume with thicknessFactor 1 and no attenuation (a solid, refracting
                      glass in gilt; without the volume gilt would make each surface a thin sheet)
OUT_DIR/glass-furnace.gltf  the same three spheres without the ground (a white furnace under a
                      uniform sky, where an energy-conserving glass sphere is exactly as bright as the sky)

Buffers are embedded as base64 data URIs, so each .gltf is a single file.
"""
import base64
import json
import math
import os
import struct
import sys

RADIUS = 0.4
ROUGHNESS = [0.1, 0.3, 0.5, 0.7, 1.0]
METALLIC = [0.0, 0.5, 1.0]          # front row first
SPACING_X, SPACING_Z = 1.0, 1.1
FURNACE_SPACING = 2.5
GLASS_RADIUS = 0.5
GLASS_ROUGHNESS = [0.0, 0.3, 0.6]   # left to right
GLASS_SPACING = 1.25
GLASS_IOR = 1.5
BASE = [0.8, 0.4, 0.2, 1.0]
GROUND_BASE = [0.5, 0.5, 0.5, 1.0]
GROUND_HALF = 8.0


class Builder:
    """Accumulates one binary buffer, its views and accessors."""

    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def _view(self, blob, target):
        while len(self.data) % 4:
            self.data.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob), "target": target})
        self.data += blob
        return len(self.views) - 1

    def vec3(self, values):
        blob = b"".join(struct.pack("<3f", *v) for v in values)
        lo = [min(v[i] for v in values) for i in range(3)]
        hi = [max(v[i] for v in values) for i in range(3)]
        self.accessors.append({"bufferView": self._view(blob, 34962), "componentType": 5126, "count": len(values),
                               "type": "VEC3", "min": lo, "max": hi})
        return len(self.accessors) - 1

    def indices(self, values):
        blob = struct.pack("<%dH" % len(values), *values)
        self.accessors.append({"bufferView": self._view(blob, 34963), "componentType": 5123, "count": len(values),
                               "type": "SCALAR"})
        return len(self.accessors) - 1

    def gltf(self, meshes, materials, nodes):
        uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(self.data)).decode()
        doc = {"asset": {"version": "2.0", "generator": "gilt bench/cycles/make_scenes.py"},
               "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
               "materials": materials, "accessors": self.accessors, "bufferViews": self.views,
               "buffers": [{"byteLength": len(self.data), "uri": uri}]}
        used = sorted({e for m in materials for e in m.get("extensions", {})})
        if used:   # the schema wants at least one name when the list is there
            doc["extensionsUsed"] = used
        return doc


def uv_sphere(segments=32, rings=16):
    """Unit sphere: positions (= normals) and counter-clockwise triangles seen from outside."""
    pos = []
    for j in range(rings + 1):
        theta = math.pi * j / rings                     # 0 at the top (+y)
        for i in range(segments + 1):
            phi = 2 * math.pi * i / segments
            pos.append((math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)))
    idx = []
    row = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b = j * row + i, (j + 1) * row + i       # a above b
            if j > 0:
                idx += [a, b, a + 1]
            if j < rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, idx


def ground(builder):
    h = GROUND_HALF
    p = builder.vec3([(-h, 0, -h), (-h, 0, h), (h, 0, h), (h, 0, -h)])
    n = builder.vec3([(0, 1, 0)] * 4)
    i = builder.indices([0, 1, 2, 0, 2, 3])
    return {"primitives": [{"attributes": {"POSITION": p, "NORMAL": n}, "indices": i, "material": 0}], "name": "ground"}


def ground_material():
    return {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": GROUND_BASE, "metallicFactor": 0.0,
                                                        "roughnessFactor": 1.0},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}


def sphere_grid(out, name, with_ground, spacing_x, spacing_z, keep=lambda m, r: True):
    """NAME.gltf: (the ground, mesh 0, material 0, then) one mesh and material per sphere kept;
    NAME-layout.json: those spheres."""
    b = Builder()
    meshes, materials, nodes, spheres = [], [], [], []
    if with_ground:
        meshes, materials, nodes = [ground(b)], [ground_material()], [{"mesh": 0, "name": "ground"}]
    unit_pos, unit_idx = uv_sphere()
    pos_acc = b.vec3([tuple(RADIUS * c for c in p) for p in unit_pos])
    nrm_acc = b.vec3(unit_pos)
    idx_acc = b.indices(unit_idx)
    for row, m in enumerate(METALLIC):
        for col, r in enumerate(ROUGHNESS):
            if not keep(m, r):
                continue
            mat = "m%.1f_r%.1f" % (m, r)
            center = [(col - 2) * spacing_x, RADIUS, (1 - row) * spacing_z]
            materials.append({"name": mat, "pbrMetallicRoughness": {"baseColorFactor": BASE, "metallicFactor": m,
                                                                     "roughnessFactor": r}})
            meshes.append({"name": mat, "primitives": [{"attributes": {"POSITION": pos_acc, "NORMAL": nrm_acc},
                                                        "indices": idx_acc, "material": len(materials) - 1}]})
            nodes.append({"mesh": len(meshes) - 1, "name": mat, "translation": center})
            spheres.append({"name": mat, "center": center, "radius": RADIUS, "metallic": m, "roughness": r})
    with open(os.path.join(out, name + ".gltf"), "w") as f:
        json.dump(b.gltf(meshes, materials, nodes), f)
    with open(os.path.join(out, name + "-layout.json"), "w") as f:
        json.dump(spheres, f, indent=1)


def glass_row(out, name, with_ground=True):
    """NAME.gltf: (the ground, mesh 0, material 0, and) one solid glass sphere per roughness, left to
    right, resting on it; NAME-layout.json: those spheres. A finer tessellation than the grid's,
    since a refracting sphere magnifies the facets' normal interpolation."""
    b = Builder()
    meshes, materials, nodes, spheres = [], [], [], []
    if with_ground:
        meshes, materials, nodes = [ground(b)], [ground_material()], [{"mesh": 0, "name": "ground"}]
    unit_pos, unit_idx = uv_sphere(64, 32)
    pos_acc = b.vec3([tuple(GLASS_RADIUS * c for c in p) for p in unit_pos])
    nrm_acc = b.vec3(unit_pos)
    idx_acc = b.indices(unit_idx)
    n = len(GLASS_ROUGHNESS)
    for i, r in enumerate(GLASS_ROUGHNESS):
        mat = "glass_r%.1f" % r
        center = [(i - (n - 1) / 2) * GLASS_SPACING, GLASS_RADIUS, 0.0]
        materials.append({"name": mat,
                          "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
                                                   "roughnessFactor": r},
                          "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                         "KHR_materials_ior": {"ior": GLASS_IOR},
                                         "KHR_materials_volume": {"thicknessFactor": 1.0}}})
        meshes.append({"name": mat, "primitives": [{"attributes": {"POSITION": pos_acc, "NORMAL": nrm_acc},
                                                    "indices": idx_acc, "material": len(materials) - 1}]})
        nodes.append({"mesh": len(meshes) - 1, "name": mat, "translation": center})
        spheres.append({"name": mat, "label": "glass r=%g" % r, "center": center, "radius": GLASS_RADIUS,
                        "metallic": 0.0, "roughness": r, "transmission": 1.0, "ior": GLASS_IOR})
    with open(os.path.join(out, name + ".gltf"), "w") as f:
        json.dump(b.gltf(meshes, materials, nodes), f)
    with open(os.path.join(out, name + "-layout.json"), "w") as f:
        json.dump(spheres, f, indent=1)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(out, exist_ok=True)
    sphere_grid(out, "spheres", True, SPACING_X, SPACING_Z)
    sphere_grid(out, "furnace", False, FURNACE_SPACING, FURNACE_SPACING)
    sphere_grid(out, "lone", True, SPACING_X, SPACING_Z, keep=lambda m, r: m == 1.0 and r == 1.0)
    glass_row(out, "glass")
    glass_row(out, "glass-furnace", with_ground=False)

    g = Builder()
    with open(os.path.join(out, "ground.gltf"), "w") as f:
        json.dump(g.gltf([ground(g)], [ground_material()], [{"mesh": 0, "name": "ground"}]), f)


if __name__ == "__main__":
    main()
