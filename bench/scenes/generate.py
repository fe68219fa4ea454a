#!/usr/bin/env python3
"""A seeded family of generated interiors for testing global illumination on scenes nobody tuned on.

    python3 bench/scenes/generate.py OUT_DIR [--count 36] [--seed 2026] [--first 0]
                                     [--triangles MIN,MAX] [--only INDEX ...] [--list]

Writes OUT_DIR/<name>/scene.json (gilt's JSON scene: lights and camera) beside the model it names,
building.obj with its building.mtl (one group per material), one folder per scene, and OUT_DIR/family.json listing every scene with its
axes. Scene k of the family is fully determined by (--seed, k): the same arguments write the same
bytes, on any machine (Python's own random.Random, no third-party module).

The axes, crossed so that every 24 consecutive scenes hold each pair of kind and lighting once:
  kind      atrium (two storeys of arcades round an open courtyard, barrel-vaulted galleries),
            colonnade (a long hall of columns under a barrel vault, open or glazed windows),
            dome (a square hall under a hemispherical dome on a drum, an oculus at its top),
            storeys (two to four stacked floors, thin slabs and a roof that do not touch the
            walls, stair openings), furnished (a room with 100-2,000 closed pieces of furniture
            standing on or piercing the floor, shelves touching the walls), crevices (blocks
            separated by narrow slots, a low beam ceiling)
  lighting  sun-sky (a directional sun and a uniform sky), envmap (a latitude-longitude image of
            a sky, written beside the scene as Radiance .hdr), emitters (hundreds of small
            emitting panels under the ceiling), points (two to five point lights)
  winding   inward (the shell's faces look into the room), outward (away from it, as many
            downloaded models are), mixed (each face's winding flipped at random); furniture
            and columns are closed solids wound outward except under `mixed`
  albedo    grey or coloured, each channel in [0.2, 0.9]
  size      10k-300k triangles, log-uniform (curved parts are tessellated to reach it)

Nothing here depends on gilt; the path tracer is the oracle for every scene (bench/generalise.py).
"""

import argparse
import json
import math
import os
import random
import struct
import sys

KINDS = ["atrium", "colonnade", "dome", "storeys", "furnished", "crevices"]
LIGHTINGS = ["sun-sky", "envmap", "emitters", "points"]
WINDINGS = ["inward", "outward", "mixed"]


# ---------------------------------------------------------------------------------------------
# Geometry: a triangle list per material, built from a few primitives.


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def mul(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class Mesh:
    """Triangles of one material. `flip` decides, per face, whether its winding is reversed."""

    def __init__(self, rng, winding):
        self.vertices = []
        self.triangles = []
        self.rng = rng
        self.winding = winding

    def _flip(self, shell):
        if self.winding == "mixed":
            return self.rng.random() < 0.5
        return shell and self.winding == "outward"

    def tri(self, a, b, c, shell=False):
        """Counter-clockwise seen from the side the face should look to (for a shell face: into the
        room); reversed when the scene's winding says so. Triangles without area are left out."""
        n = cross(sub(b, a), sub(c, a))
        if dot(n, n) <= 1e-12 * max(dot(sub(b, a), sub(b, a)), dot(sub(c, a), sub(c, a))) ** 2:
            return
        if self._flip(shell):
            b, c = c, b
        n = len(self.vertices)
        self.vertices += [a, b, c]
        self.triangles.append((n, n + 1, n + 2))

    def quad(self, a, b, c, d, shell=False):
        """Two triangles, a-b-c and a-c-d, one winding decision for both (a collapsed corner
        leaves one triangle)."""
        if self._flip(shell):
            a, b, c, d = a, d, c, b
        self.winding, saved = "inward", self.winding  # the decision is made: tri must not flip again
        self.tri(a, b, c)
        self.tri(a, c, d)
        self.winding = saved

    def grid(self, origin, u, v, nu, nv, shell=False):
        """A parallelogram origin + [0,1]u + [0,1]v cut into nu × nv quads, seen from u × v."""
        for i in range(nu):
            for j in range(nv):
                p = lambda a, b: add(origin, add(mul(u, a / nu), mul(v, b / nv)))
                self.quad(p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1), shell)

    def wall(self, origin, u, v, holes=(), shell=True):
        """The rectangle origin + [0,1]u + [0,1]v (seen from u × v) with rectangular holes given as
        (u0, u1, v0, v1) fractions: cut along every hole edge and kept where no hole is."""
        us = sorted({0.0, 1.0} | {h[0] for h in holes} | {h[1] for h in holes})
        vs = sorted({0.0, 1.0} | {h[2] for h in holes} | {h[3] for h in holes})
        for i in range(len(us) - 1):
            for j in range(len(vs) - 1):
                cu, cv = 0.5 * (us[i] + us[i + 1]), 0.5 * (vs[j] + vs[j + 1])
                if any(h[0] < cu < h[1] and h[2] < cv < h[3] for h in holes):
                    continue
                p = lambda a, b: add(origin, add(mul(u, a), mul(v, b)))
                self.quad(p(us[i], vs[j]), p(us[i + 1], vs[j]), p(us[i + 1], vs[j + 1]), p(us[i], vs[j + 1]), shell)

    def box(self, lo, hi):
        """A closed axis-aligned box, faces outward."""
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        for f in [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]:
            self.quad(*[c[i] for i in f])

    def cylinder(self, centre, radius, y0, y1, segments, rings=1, caps=True):
        """A closed vertical cylinder (faces outward): a column, a round table top."""
        cx, cz = centre
        ring = [(cx + radius * math.cos(2 * math.pi * i / segments), cz + radius * math.sin(2 * math.pi * i / segments))
                for i in range(segments)]
        for r in range(rings):
            ya = y0 + (y1 - y0) * r / rings
            yb = y0 + (y1 - y0) * (r + 1) / rings
            for i in range(segments):
                a, b = ring[i], ring[(i + 1) % segments]
                self.quad((a[0], ya, a[1]), (a[0], yb, a[1]), (b[0], yb, b[1]), (b[0], ya, b[1]))
        if caps:
            for i in range(segments):
                a, b = ring[i], ring[(i + 1) % segments]
                self.tri((cx, y1, cz), (b[0], y1, b[1]), (a[0], y1, a[1]))
                self.tri((cx, y0, cz), (a[0], y0, a[1]), (b[0], y0, b[1]))

    def barrel_vault(self, x0, x1, z0, z1, spring, segments, bays, shell=True):
        """A half-cylinder ceiling over [x0, x1] (its span) running along z from z0 to z1, springing
        at height `spring`, seen from below."""
        r = 0.5 * (x1 - x0)
        cx = 0.5 * (x0 + x1)
        for i in range(segments):
            ta, tb = math.pi * i / segments, math.pi * (i + 1) / segments
            a = (cx + r * math.cos(ta), spring + r * math.sin(ta))
            b = (cx + r * math.cos(tb), spring + r * math.sin(tb))
            for k in range(bays):
                za = z0 + (z1 - z0) * k / bays
                zb = z0 + (z1 - z0) * (k + 1) / bays
                # Seen from below (inside the vault): a -> b runs anticlockwise about +z.
                self.quad((a[0], a[1], za), (a[0], a[1], zb), (b[0], b[1], zb), (b[0], b[1], za), shell)

    def dome(self, centre, radius, base, rings, segments, oculus, shell=True):
        """A hemisphere seen from inside, open above the polar angle `oculus` (radians, 0 = closed)."""
        cx, cz = centre
        for r in range(rings):
            pa = math.pi / 2 * r / rings
            pb = math.pi / 2 * (r + 1) / rings
            if oculus > 0 and math.pi / 2 - pb < oculus:
                pb = math.pi / 2 - oculus
                if pb <= pa:
                    break
            for i in range(segments):
                ta, tb = 2 * math.pi * i / segments, 2 * math.pi * (i + 1) / segments
                p = lambda phi, th: (cx + radius * math.cos(phi) * math.cos(th), base + radius * math.sin(phi),
                                     cz + radius * math.cos(phi) * math.sin(th))
                if oculus == 0 and r == rings - 1:
                    self.tri(p(pa, ta), p(pa, tb), (cx, base + radius, cz), shell)
                else:
                    self.quad(p(pa, ta), p(pa, tb), p(pb, tb), p(pb, ta), shell)

    def arcade(self, x0, x1, z, y0, height, bays, depth, segments, shell=True):
        """A row of round arches along x at depth z..z+depth: spandrels on both faces above the
        arches and the curved soffit under each; piers are left to the caller (columns)."""
        w = (x1 - x0) / bays
        r = 0.5 * w
        spring = y0 + height - r - 0.15 * height
        top = y0 + height
        for b in range(bays):
            cx = x0 + (b + 0.5) * w
            for i in range(segments):
                ta, tb = math.pi - math.pi * i / segments, math.pi - math.pi * (i + 1) / segments
                a = (cx + r * math.cos(ta), spring + r * math.sin(ta))
                c = (cx + r * math.cos(tb), spring + r * math.sin(tb))
                ua = x0 + b * w + w * i / segments
                ub = x0 + b * w + w * (i + 1) / segments
                for zz, front in ((z, True), (z + depth, False)):
                    q = [(a[0], a[1], zz), (c[0], c[1], zz), (ub, top, zz), (ua, top, zz)]
                    if front:
                        self.quad(q[0], q[3], q[2], q[1], shell)
                    else:
                        self.quad(*q, shell)
                # The soffit, seen from below.
                self.quad((a[0], a[1], z), (c[0], c[1], z), (c[0], c[1], z + depth), (a[0], a[1], z + depth), shell)
            # Straight jambs from the springing line down to the pier tops are the columns' job.

    def count(self):
        return len(self.triangles)


def write_obj(folder, meshes, materials):
    """One model, as most downloaded interiors come: building.obj with a group per material and
    building.mtl beside it. Vertices are shared wherever their printed coordinates agree, so
    adjacent faces are connected as a modeller's export would be."""
    obj = ["# gilt bench/scenes/generate.py", "mtllib building.mtl"]
    faces = []
    index = {}
    for name in sorted(meshes):
        m = meshes[name]
        if not m.triangles:
            continue
        faces.append(f"g {name}\nusemtl {name}")
        ids = []
        for v in m.vertices:
            key = "v %.6g %.6g %.6g" % v
            if key not in index:
                index[key] = len(index) + 1
                obj.append(key)
            ids.append(index[key])
        for t in m.triangles:
            a, b, c = ids[t[0]], ids[t[1]], ids[t[2]]
            if a != b and b != c and a != c:
                faces.append(f"f {a} {b} {c}")
    with open(os.path.join(folder, "building.obj"), "w") as f:
        f.write("\n".join(obj + faces) + "\n")
    mtl = ["# gilt bench/scenes/generate.py"]
    for name in sorted(materials):
        mat = materials[name]
        mtl.append(f"newmtl {name}")
        if mat["kind"] == "dielectric":
            mtl += ["Kd 0 0 0", "Ks 1 1 1", f"Ni {mat['ior']}", "illum 7"]
        else:
            mtl.append("Kd %.4g %.4g %.4g" % tuple(mat["albedo"] if isinstance(mat["albedo"], list) else [mat["albedo"]] * 3))
            if "emission" in mat:
                e = mat["emission"] if isinstance(mat["emission"], list) else [mat["emission"]] * 3
                mtl.append("Ke %.6g %.6g %.6g" % tuple(e))
    with open(os.path.join(folder, "building.mtl"), "w") as f:
        f.write("\n".join(mtl) + "\n")
    return len(faces) - sum(1 for x in faces if x.startswith("g "))


def write_hdr(path, width, height, radiance):
    """A flat (not run-length encoded) Radiance RGBE image of radiance(u, v) -> (r, g, b), v = 0 at
    the top row."""
    def rgbe(c):
        m = max(c)
        if m < 1e-32:
            return bytes(4)
        mant, e = math.frexp(m)
        s = mant * 256.0 / m
        return bytes([min(255, int(c[0] * s)), min(255, int(c[1] * s)), min(255, int(c[2] * s)), e + 128])
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {height} +X {width}\n".encode("ascii"))
        for j in range(height):
            f.write(b"".join(rgbe(radiance((i + 0.5) / width, (j + 0.5) / height)) for i in range(width)))


# ---------------------------------------------------------------------------------------------
# One scene.


class Scene:
    def __init__(self, rng, winding):
        self.rng = rng
        self.winding = winding
        self.meshes = {}  # material name -> Mesh
        self.materials = {}
        self.lights = []
        self.camera = None
        self.openings = []  # (centre, normal) of openings light can come through, for the camera

    def mesh(self, material):
        if material not in self.meshes:
            self.meshes[material] = Mesh(self.rng, self.winding)
        return self.meshes[material]

    def albedo(self, grey):
        if grey:
            g = round(self.rng.uniform(0.2, 0.9), 3)
            return [g, g, g]
        return [round(self.rng.uniform(0.2, 0.9), 3) for _ in range(3)]

    def triangles(self):
        return sum(m.count() for m in self.meshes.values())


def room_shell(s, w, h, d, mat_floor, mat_wall, mat_ceiling, holes=None, ceiling=True, ceiling_holes=()):
    """Floor, four walls and (optionally) a ceiling of a w × h × d room at the origin, faces looking
    in. holes: per wall (south z=0, north z=d, west x=0, east x=w) a list of (u0, u1, v0, v1)."""
    holes = holes or {}
    s.mesh(mat_floor).wall((0, 0, d), (w, 0, 0), (0, 0, -d), shell=True)
    s.mesh(mat_wall).wall((0, 0, 0), (w, 0, 0), (0, h, 0), holes.get("south", ()), shell=True)
    s.mesh(mat_wall).wall((w, 0, d), (-w, 0, 0), (0, h, 0), holes.get("north", ()), shell=True)
    s.mesh(mat_wall).wall((0, 0, d), (0, 0, -d), (0, h, 0), holes.get("west", ()), shell=True)
    s.mesh(mat_wall).wall((w, 0, 0), (0, 0, d), (0, h, 0), holes.get("east", ()), shell=True)
    if ceiling:
        s.mesh(mat_ceiling).wall((0, h, 0), (w, 0, 0), (0, 0, d), ceiling_holes, shell=True)


def window_row(rng, count, v0, v1):
    """`count` window holes spread along a wall, as (u0, u1, v0, v1) fractions."""
    holes = []
    for i in range(count):
        c = (i + 0.5) / count
        half = 0.5 / count * rng.uniform(0.35, 0.7)
        holes.append((round(c - half, 4), round(c + half, 4), v0, v1))
    return holes


def glaze(s, holes, origin, u, v, thickness):
    """Panes of glass (closed thin boxes) filling the holes of the wall origin + u·[0,1] + v·[0,1]."""
    n = cross(u, v)
    ln = math.sqrt(dot(n, n))
    n = mul(n, thickness / ln)
    for (u0, u1, v0, v1) in holes:
        a = add(origin, add(mul(u, u0), mul(v, v0)))
        b = add(origin, add(mul(u, u1), mul(v, v1)))
        # The pane fills the hole, centred on the wall's plane.
        lo = tuple(min(a[i], b[i]) - 0.5 * abs(n[i]) for i in range(3))
        hi = tuple(max(a[i], b[i]) + 0.5 * abs(n[i]) for i in range(3))
        s.mesh("glass").box(lo, hi)


def build_atrium(s, density):
    rng = s.rng
    w, d = rng.uniform(18, 26), rng.uniform(18, 26)
    storey = rng.uniform(4.5, 6.0)
    h = 2 * storey
    gallery = rng.uniform(3.5, 5.0)
    seg = max(6, int(10 * density))
    # Outer walls with small windows on the upper storey; no roof over the courtyard.
    win = window_row(rng, 5, 0.62, 0.85)
    room_shell(s, w, h, d, "floor", "stone", "stone", {"south": win, "north": win}, ceiling=False)
    # Roof over the galleries only (a frame round the courtyard opening), seen from below.
    cx0, cx1, cz0, cz1 = gallery, w - gallery, gallery, d - gallery
    roof = s.mesh("stone")
    roof.wall((0, h, 0), (w, 0, 0), (0, 0, d), [(cx0 / w, cx1 / w, cz0 / d, cz1 / d)], shell=True)
    # Thin gallery floor of the upper storey: a slab ring that stops short of the outer walls.
    gap = 0.02
    t = 0.25
    slab = s.mesh("floor")
    for lo, hi in [((gap, storey - t, gap), (w - gap, storey, cz0)), ((gap, storey - t, cz1), (w - gap, storey, d - gap)),
                   ((gap, storey - t, cz0), (cx0, storey, cz1)), ((cx1, storey - t, cz0), (w - gap, storey, cz1))]:
        slab.box(lo, hi)
    # Arcades on the courtyard's four sides, both storeys, columns as closed cylinders.
    bays_x = max(3, int((cx1 - cx0) / 3.0))
    bays_z = max(3, int((cz1 - cz0) / 3.0))
    depth = 0.5
    col_r = 0.25
    for level in range(2):
        y0 = level * storey
        arch_h = storey - t if level == 0 else storey
        s.mesh("stone").arcade(cx0, cx1, cz0 - depth, y0, arch_h, bays_x, depth, seg)
        s.mesh("stone").arcade(cx0, cx1, cz1, y0, arch_h, bays_x, depth, seg)
        # The two sides along z: an arcade along x rotated, written with swapped coordinates.
        side = Mesh(rng, s.winding)
        side.arcade(cz0, cz1, cx0 - depth, y0, arch_h, bays_z, depth, seg)
        side2 = Mesh(rng, s.winding)
        side2.arcade(cz0, cz1, cx1, y0, arch_h, bays_z, depth, seg)
        for m in (side, side2):
            # (x, y, z) -> (z, y, x) mirrors, so reverse each triangle to keep its facing.
            base = len(s.mesh("stone").vertices)
            s.mesh("stone").vertices += [(v[2], v[1], v[0]) for v in m.vertices]
            s.mesh("stone").triangles += [(base + a, base + c, base + b) for a, b, c in m.triangles]
        for i in range(bays_x + 1):
            x = cx0 + (cx1 - cx0) * i / bays_x
            for z in (cz0 - 0.5 * depth, cz1 + 0.5 * depth):
                s.mesh("column").cylinder((x, z), col_r, y0, y0 + arch_h, seg, rings=max(1, seg // 4))
        for i in range(1, bays_z):
            z = cz0 + (cz1 - cz0) * i / bays_z
            for x in (cx0 - 0.5 * depth, cx1 + 0.5 * depth):
                s.mesh("column").cylinder((x, z), col_r, y0, y0 + arch_h, seg, rings=max(1, seg // 4))
    # Barrel vaults over the two long galleries of the ground floor, under the slab.
    s.mesh("stone").barrel_vault(0.05, cx0 - 0.05, cz0, cz1, storey - t - 0.5 * (cx0 - 0.1) - 0.01, seg, max(2, seg // 2))
    s.mesh("stone").barrel_vault(cx1 + 0.05, w - 0.05, cz0, cz1, storey - t - 0.5 * (w - cx1 - 0.1) - 0.01, seg,
                                 max(2, seg // 2))
    s.bounds = (w, h, d)
    s.eye = (cx0 + 0.3 * (cx1 - cx0), 1.7, cz0 + 0.25 * (cz1 - cz0))
    s.target = (0.5 * w, 0.35 * h, d - 0.5 * gallery)
    s.sky_openings = True


def build_colonnade(s, density):
    rng = s.rng
    w, d = rng.uniform(10, 16), rng.uniform(24, 36)
    wall_h = rng.uniform(5, 7)
    seg = max(6, int(12 * density))
    glazed = rng.random() < 0.5 and s.lighting != "sun-sky"
    win = window_row(rng, 6, 0.35, 0.8)
    holes = {"west": win, "east": win, "south": [(0.35, 0.65, 0.0, 0.55)]}
    room_shell(s, w, wall_h, d, "floor", "stone", "stone", holes, ceiling=False)
    s.mesh("stone").barrel_vault(0, w, 0, d, wall_h, seg, max(2, seg))
    # End wall lunettes close the vault's half-discs.
    for z, front in ((0.0, True), (d, False)):
        r = 0.5 * w
        for i in range(seg):
            ta, tb = math.pi * i / seg, math.pi * (i + 1) / seg
            a = (0.5 * w + r * math.cos(ta), wall_h + r * math.sin(ta), z)
            b = (0.5 * w + r * math.cos(tb), wall_h + r * math.sin(tb), z)
            c = (0.5 * w, wall_h, z)
            if front:
                s.mesh("stone").tri(c, b, a, shell=True)
            else:
                s.mesh("stone").tri(c, a, b, shell=True)
    if glazed:
        glaze(s, win, (0, 0, d), (0, 0, -d), (0, wall_h, 0), 0.04)
        glaze(s, win, (w, 0, 0), (0, 0, d), (0, wall_h, 0), 0.04)
    rows = max(4, int(d / 3.0))
    for i in range(rows):
        z = d * (i + 0.5) / rows
        for x in (0.25 * w, 0.75 * w):
            s.mesh("column").cylinder((x, z), rng.uniform(0.25, 0.4), 0.0, wall_h, seg, rings=max(1, seg // 3))
    s.bounds = (w, wall_h + 0.5 * w, d)
    s.eye = (0.5 * w, 1.7, 1.5)
    s.target = (0.5 * w, 0.5 * wall_h, d)
    s.sky_openings = True


def build_dome(s, density):
    rng = s.rng
    w = rng.uniform(12, 20)
    drum = rng.uniform(5, 8)
    seg = 8 * max(2, int(3 * density))
    rings = max(4, seg // 3)
    r = 0.5 * w
    oculus = math.radians(rng.uniform(6, 14))
    win = window_row(rng, 3, 0.3, 0.7)
    room_shell(s, w, drum, w, "floor", "stone", "stone", {"south": win, "east": win}, ceiling=False)
    # The ceiling is the square ring between the walls and the dome's base circle: pendentives
    # approximated by triangles from each corner to the circle.
    # The ceiling is the square ring between the walls and the dome's base circle: each of the
    # circle's segments joined to the square's boundary along the same angles (seg is a multiple
    # of 8, so the square's corners fall on segment ends).
    m = s.mesh("stone")
    def on_square(t):
        c, sn = math.cos(t), math.sin(t)
        k = r / max(abs(c), abs(sn))
        return (r + k * c, drum, r + k * sn)
    def on_circle(t):
        return (r + r * math.cos(t), drum, r + r * math.sin(t))
    for i in range(seg):
        ta, tb = 2 * math.pi * i / seg, 2 * math.pi * (i + 1) / seg
        m.quad(on_square(ta), on_circle(ta), on_circle(tb), on_square(tb), shell=True)
    m.dome((r, r), r * 0.999, drum, rings, seg, oculus)
    # A ring of free-standing columns inside.
    for i in range(8):
        t = 2 * math.pi * (i + 0.5) / 8
        s.mesh("column").cylinder((r + 0.7 * r * math.cos(t), r + 0.7 * r * math.sin(t)), 0.3, 0, drum, seg // 2,
                                  rings=max(1, seg // 6))
    s.bounds = (w, drum + r, w)
    s.eye = (0.15 * w, 1.7, 0.2 * w)
    s.target = (0.7 * w, drum, 0.8 * w)
    s.sky_openings = True


def build_storeys(s, density):
    rng = s.rng
    w, d = rng.uniform(10, 16), rng.uniform(10, 16)
    n = rng.randint(2, 4)
    storey = rng.uniform(3.0, 4.0)
    h = n * storey
    gap = rng.uniform(0.005, 0.05)
    t = rng.uniform(0.08, 0.25)
    cells = max(2, int(6 * density))
    holes = {}
    for wall in ("south", "north", "west", "east"):
        row = []
        for k in range(n):
            for (u0, u1, _, _) in window_row(rng, 3, 0, 1):
                row.append((u0, u1, (k * storey + 0.9) / h, (k * storey + 2.4) / h))
        holes[wall] = row
    room_shell(s, w, h, d, "floor", "plaster", "plaster", holes, ceiling=False)
    # Slabs of every upper floor and the roof: closed boxes `gap` from the walls, a stair opening.
    for k in range(1, n + 1):
        y = k * storey
        sx0 = rng.uniform(0.2, 0.5) * w
        sx1 = sx0 + rng.uniform(0.15, 0.25) * w
        sz0 = rng.uniform(0.1, 0.6) * d
        sz1 = sz0 + 0.25 * d
        slab = s.mesh("floor" if k < n else "plaster")
        if k == n:
            slab.box((gap, y - t, gap), (w - gap, y, d - gap))
        else:
            for lo, hi in [((gap, y - t, gap), (sx0, y, d - gap)), ((sx1, y - t, gap), (w - gap, y, d - gap)),
                           ((sx0, y - t, gap), (sx1, y, sz0)), ((sx0, y - t, sz1), (sx1, y, d - gap))]:
                slab.box(lo, hi)
    # Finely cut partition walls and a few pillars give the mesher triangles to work on.
    for k in range(n):
        y0 = k * storey
        x = rng.uniform(0.55, 0.8) * w
        s.mesh("plaster").grid((x, y0, 0.05 * d), (0, 0, 0.4 * d), (0, storey - t - 0.01, 0), cells * 4, cells * 2)
        s.mesh("plaster").grid((x, y0, 0.95 * d), (0, 0, -0.4 * d), (0, storey - t - 0.01, 0), cells * 4, cells * 2)
        for i in range(3):
            s.mesh("column").cylinder((rng.uniform(0.1, 0.5) * w, rng.uniform(0.55, 0.9) * d), 0.2, y0,
                                      y0 + storey - t, max(8, cells * 4), rings=cells)
    s.bounds = (w, h, d)
    s.eye = (0.1 * w, 1.6, 0.1 * d)
    s.target = (0.9 * w, 1.2, 0.9 * d)
    s.sky_openings = True


def furniture(s, rng, x, z, rot, kind, pierce, seg):
    m = s.mesh("wood")
    def put(lo, hi):
        # Boxes in the piece's own frame (x along its width), turned by 0 or 90 degrees.
        if rot:
            lo, hi = (lo[2], lo[1], lo[0]), (hi[2], hi[1], hi[0])
        m.box((x + lo[0], lo[1], z + lo[2]), (x + hi[0], hi[1], z + hi[2]))
    y0 = -pierce
    def legs(half_x, half_z, leg, top):
        # Four square legs at the corners of a 2·half_x × 2·half_z footprint, from y0 to top.
        for dx in (-half_x, half_x - leg):
            for dz in (-half_z, half_z - leg):
                put((dx, y0, dz), (dx + leg, top, dz + leg))
    if kind == "chair":
        legs(0.2, 0.2, 0.04, 0.45)
        put((-0.2, 0.45, -0.2), (0.2, 0.5, 0.2))
        put((-0.2, 0.5, 0.16), (0.2, 0.95, 0.2))
    elif kind == "table":
        legs(0.7, 0.4, 0.06, 0.72)
        put((-0.75, 0.72, -0.45), (0.75, 0.76, 0.45))
    elif kind == "round":
        s.mesh("wood").cylinder((x, z), 0.05, y0, 0.72, seg)
        s.mesh("wood").cylinder((x, z), 0.5, 0.72, 0.76, 2 * seg)
        s.mesh("wood").cylinder((x, z), 0.25, y0, 0.03, seg)
    else:  # a cabinet
        put((-0.4, y0, -0.25), (0.4, 1.2, 0.25))


def build_furnished(s, density):
    rng = s.rng
    w, d = rng.uniform(14, 30), rng.uniform(14, 30)
    h = rng.uniform(3.0, 4.5)
    win = window_row(rng, 4, 0.3, 0.85)
    glazed = rng.random() < 0.5 and s.lighting != "sun-sky"
    ceiling_holes = []
    if s.lighting in ("sun-sky", "envmap"):
        ceiling_holes = [(0.4, 0.6, 0.3, 0.7)]
    room_shell(s, w, h, d, "carpet", "plaster", "plaster", {"south": win, "west": win}, ceiling=True,
               ceiling_holes=ceiling_holes)
    if glazed:
        glaze(s, win, (0, 0, 0), (w, 0, 0), (0, h, 0), 0.03)
        glaze(s, win, (0, 0, d), (0, 0, -d), (0, h, 0), 0.03)
    seg = max(8, int(16 * density))
    pieces = int(min(2000, max(100, 400 * density * density)))
    # Shelves along the north wall, touching it.
    for i in range(int(w / 1.2)):
        s.mesh("wood").box((0.6 + 1.2 * i, 0.0, d - 0.35), (1.4 + 1.2 * i, rng.uniform(1.2, 2.2), d))
    placed = 0
    cell = 1.1
    nx, nz = int((w - 2) / cell), int((d - 2) / cell)
    free = [(i, j) for i in range(nx) for j in range(nz)]
    rng.shuffle(free)
    for (i, j) in free:
        if placed >= pieces:
            break
        kind = rng.choice(["chair", "chair", "chair", "table", "round", "cabinet"])
        pierce = 0.02 if rng.random() < 0.3 else 0.0
        furniture(s, rng, 1 + (i + 0.5) * cell, 1 + (j + 0.5) * cell, rng.random() < 0.5, kind, pierce, seg)
        placed += 1
    s.pieces = placed
    s.bounds = (w, h, d)
    s.eye = (0.5, 1.6, 0.5)
    s.target = (0.6 * w, 0.5, 0.7 * d)
    s.sky_openings = True


def build_crevices(s, density):
    rng = s.rng
    w, d = rng.uniform(8, 14), rng.uniform(8, 14)
    h = rng.uniform(3, 5)
    win = window_row(rng, 3, 0.4, 0.9)
    room_shell(s, w, h, d, "floor", "stone", "stone", {"south": win}, ceiling=True,
               ceiling_holes=[(0.3, 0.7, 0.4, 0.6)] if s.lighting in ("sun-sky", "envmap") else [])
    cells = max(2, int(5 * density))
    # Blocks in a row separated by narrow slots (0.5-5 % of the block's size), finely cut faces.
    n = rng.randint(4, 9)
    slot = rng.uniform(0.01, 0.08)
    bw = (0.8 * w - (n - 1) * slot) / n
    m = s.mesh("block")
    for i in range(n):
        x0 = 0.1 * w + i * (bw + slot)
        bh = rng.uniform(0.8, 2.5)
        z0, z1 = 0.3 * d, 0.3 * d + rng.uniform(0.8, 2.0)
        # A block as six finely cut faces (outward).
        lo, hi = (x0, 0.0, z0), (x0 + bw, bh, z1)
        ex = (hi[0] - lo[0], 0, 0)
        ey = (0, hi[1] - lo[1], 0)
        ez = (0, 0, hi[2] - lo[2])
        m.grid(lo, ey, ex, cells, cells * 2)  # -z face
        m.grid((lo[0], lo[1], hi[2]), ex, ey, cells * 2, cells)  # +z
        m.grid(lo, ez, ey, cells, cells)  # -x
        m.grid((hi[0], lo[1], lo[2]), ey, ez, cells, cells)  # +x
        m.grid((lo[0], hi[1], lo[2]), ez, ex, cells, cells * 2)  # top
    # Beams under the ceiling with slots between them.
    beams = rng.randint(5, 12)
    gap = rng.uniform(0.02, 0.1)
    bw2 = (d - (beams - 1) * gap) / beams
    for i in range(beams):
        z0 = i * (bw2 + gap)
        m.box((0.02, h - 0.4, z0), (w - 0.02, h - 0.01, z0 + bw2))
    # A ribbed panel on the east wall: thin fins with crevices between them.
    fins = int(20 * density) + 10
    for i in range(fins):
        z = 0.1 * d + 0.8 * d * i / fins
        s.mesh("wood").box((w - 0.3, 0.2, z), (w, h - 0.6, z + 0.3 * 0.8 * d / fins))
    s.bounds = (w, h, d)
    s.eye = (0.5 * w, 1.5, 0.95 * d)
    s.target = (0.5 * w, 0.8, 0.2 * d)
    s.sky_openings = s.lighting in ("sun-sky", "envmap")


BUILDERS = {"atrium": build_atrium, "colonnade": build_colonnade, "dome": build_dome, "storeys": build_storeys,
            "furnished": build_furnished, "crevices": build_crevices}


def light_scene(s, folder):
    rng = s.rng
    w, h, d = s.bounds
    if s.lighting == "sun-sky":
        # A sun high enough to enter through the openings, from a random azimuth.
        elev = math.radians(rng.uniform(45, 80))
        az = rng.uniform(0, 2 * math.pi)
        direction = [round(-math.cos(elev) * math.sin(az), 5), round(-math.sin(elev), 5), round(-math.cos(elev) * math.cos(az), 5)]
        s.lights.append({"type": "directional", "direction": direction, "irradiance": round(rng.uniform(3, 6), 3),
                         "angular_radius_deg": 0.27})
        s.lights.append({"type": "environment", "radiance": round(rng.uniform(0.2, 0.6), 3)})
    elif s.lighting == "envmap":
        # A sky brighter towards a soft glow and the zenith, dark ground; 128 × 64 texels.
        gaz = rng.uniform(0, 2 * math.pi)
        gel = rng.uniform(0.3, 1.2)
        tint = [rng.uniform(0.8, 1.0), rng.uniform(0.85, 1.0), 1.0]
        gd = (math.cos(gel) * math.sin(gaz), math.sin(gel), -math.cos(gel) * math.cos(gaz))
        def radiance(u, v):
            phi = 2 * math.pi * (u - 0.5)
            theta = math.pi * v
            dirn = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
            if dirn[1] < 0:
                return (0.05, 0.045, 0.04)
            glow = math.exp((dot(dirn, gd) - 1) * 8)
            base = 0.3 + 0.7 * dirn[1]
            return tuple(tint[i] * (base + 6 * glow) for i in range(3))
        write_hdr(os.path.join(folder, "sky.hdr"), 128, 64, radiance)
        s.lights.append({"type": "environment", "file": "sky.hdr", "scale": round(rng.uniform(0.5, 1.5), 3)})
    elif s.lighting == "emitters":
        n = rng.randint(100, 600)
        nx = max(1, int(math.sqrt(n * w / d)))
        nz = max(1, n // nx)
        size = rng.uniform(0.08, 0.2)
        ceiling = min(h - 0.45, s.emitter_height if hasattr(s, "emitter_height") else h - 0.45)
        lamp = s.mesh("lamp")
        radiance = round(rng.uniform(15, 40) * (20.0 / (nx * nz)) ** 0.5, 3)
        s.materials["lamp"] = {"kind": "diffuse", "albedo": 0, "emission": [radiance, round(radiance * 0.9, 3), round(radiance * 0.75, 3)]}
        lamp.winding = "inward"  # emitters face down whatever the shell does: they are the lights
        for i in range(nx):
            for j in range(nz):
                x = w * (i + 0.5) / nx
                z = d * (j + 0.5) / nz
                a = (x - size, ceiling, z - size)
                b = (x + size, ceiling, z - size)
                c = (x + size, ceiling, z + size)
                e = (x - size, ceiling, z + size)
                lamp.quad(a, b, c, e)  # counter-clockwise seen from below: faces down
        s.lights.append({"type": "environment", "radiance": 0.01})
    else:
        for i in range(rng.randint(2, 5)):
            p = [round(rng.uniform(0.15, 0.85) * w, 3), round(rng.uniform(0.5, 0.8) * min(h, 4.0), 3),
                 round(rng.uniform(0.15, 0.85) * d, 3)]
            power = rng.uniform(20, 60) * (w * d / 150.0)
            s.lights.append({"type": "point", "position": p, "intensity": [round(power, 3), round(power * 0.95, 3), round(power * 0.85, 3)]})


def make_furnace(s, albedo, emission):
    """The scene as a white furnace: every surface (glass and lamps too) diffuse with one albedo,
    emitting `emission` from both sides, and the whole closed by a box a little larger than the
    building, so that every ray from inside ends on a surface: the radiance everywhere is then
    emission / (1 − albedo), whatever the geometry and winding."""
    w, h, d = s.bounds
    margin = 0.05 * max(w, h, d)
    m = s.mesh("enclosure")
    m.box((-margin, -margin, -margin), (w + margin, h + margin, d + margin))
    # The enclosure is a shell like the building's walls: it faces in, out or either way as the
    # scene's winding says (box() made it face out).
    for i, (a, b, c) in enumerate(m.triangles):
        if s.winding == "inward" or (s.winding == "mixed" and s.rng.random() < 0.5):
            m.triangles[i] = (a, c, b)
    s.lights = []
    white = {"kind": "diffuse", "albedo": albedo, "emission": emission, "two_sided": True}
    s.materials = {m: dict(white) for m in s.meshes}


def generate(index, seed, tri_range, folder_root, furnace=None):
    kind = KINDS[index % len(KINDS)]
    lighting = LIGHTINGS[(index // len(KINDS)) % len(LIGHTINGS)]
    rng_meta = random.Random(f"gilt-family/{seed}/{index}")
    winding = WINDINGS[rng_meta.randrange(3)]
    target = math.exp(rng_meta.uniform(math.log(tri_range[0]), math.log(tri_range[1])))
    grey = rng_meta.random() < 0.5
    name = f"{index:03d}-{kind}-{'furnace' if furnace else lighting}-{winding}"
    folder = os.path.join(folder_root, name)
    os.makedirs(folder, exist_ok=True)
    # Find the tessellation density that reaches the target: triangles grow as density² on the
    # curved parts, so a few secant steps on log(count) settle it.
    density = 1.0
    for _ in range(6):
        s = Scene(random.Random(f"gilt-family/{seed}/{index}/geometry"), winding)
        s.lighting = lighting
        BUILDERS[kind](s, density)
        light_scene(s, folder)
        n = s.triangles()
        if abs(math.log(n / target)) < 0.08:
            break
        density *= (target / n) ** 0.5
        density = min(max(density, 0.05), 160.0)
    if furnace is not None:
        make_furnace(s, *furnace)
    for mat in s.meshes:
        if mat in s.materials:
            continue
        if mat == "glass":
            s.materials[mat] = {"kind": "dielectric", "ior": 1.5}
        else:
            s.materials[mat] = {"kind": "diffuse", "albedo": s.albedo(grey)}
    triangles = write_obj(folder, s.meshes, s.materials)
    meshes = [{"file": "building.obj"}]
    if furnace is not None:
        # MTL cannot say "emit from both sides": the furnace's one material is given here instead.
        meshes[0]["material"] = "furnace"
        s.materials = {"furnace": s.materials["enclosure"]}
    else:
        s.materials = {}  # the MTL holds them
    w, h, d = s.bounds
    scene = {
        "materials": s.materials,
        "meshes": meshes,
        "lights": s.lights,
        "camera": {"look_from": [round(c, 4) for c in s.eye], "look_at": [round(c, 4) for c in s.target], "up": [0, 1, 0],
                   "vfov": 65},
        "render": {"width": 256, "height": 192, "spp": 64},
    }
    with open(os.path.join(folder, "scene.json"), "w") as f:
        json.dump(scene, f, indent=1, sort_keys=True)
        f.write("\n")
    return {"index": index, "name": name, "scene": os.path.join(name, "scene.json"), "kind": kind, "lighting": lighting,
            "winding": winding, "albedo": "grey" if grey else "coloured", "triangles": triangles,
            "target_triangles": int(target), "glass": "glass" in s.meshes,
            "furnace": None if furnace is None else {"albedo": furnace[0], "emission": furnace[1]}, "size": [round(w, 3), round(h, 3), round(d, 3)]}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="folder to write the scenes into")
    ap.add_argument("--count", type=int, default=36, help="scenes in the family (default 36)")
    ap.add_argument("--first", type=int, default=0, help="index of the first scene (default 0)")
    ap.add_argument("--seed", type=int, default=2026, help="the family's seed (default 2026)")
    ap.add_argument("--triangles", default="10000,300000", help="MIN,MAX triangles per scene")
    ap.add_argument("--only", type=int, nargs="*", help="generate only these indices")
    ap.add_argument("--furnace", metavar="ALBEDO,EMISSION",
                    help="write every scene as a closed white furnace instead (see make_furnace)")
    args = ap.parse_args()
    try:
        lo, hi = (float(x) for x in args.triangles.split(","))
        if not (0 < lo <= hi):
            raise ValueError
    except ValueError:
        sys.exit(f"generate.py: --triangles {args.triangles}: expected MIN,MAX with 0 < MIN <= MAX")
    furnace = None
    if args.furnace:
        try:
            furnace = tuple(float(x) for x in args.furnace.split(","))
            if len(furnace) != 2 or not (0 <= furnace[0] < 1 and furnace[1] > 0):
                raise ValueError
        except ValueError:
            sys.exit(f"generate.py: --furnace {args.furnace}: expected ALBEDO,EMISSION with 0 <= ALBEDO < 1 and EMISSION > 0")
    if args.count < 1:
        sys.exit("generate.py: --count must be at least 1")
    os.makedirs(args.out, exist_ok=True)
    indices = args.only if args.only else range(args.first, args.first + args.count)
    listing = []
    for k in indices:
        entry = generate(k, args.seed, (lo, hi), args.out, furnace)
        listing.append(entry)
        print(f"{entry['name']}: {entry['triangles']} triangles", flush=True)
    with open(os.path.join(args.out, "family.json"), "w") as f:
        json.dump({"seed": args.seed, "triangles": [lo, hi], "scenes": listing}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
