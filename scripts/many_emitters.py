#!/usr/bin/env python3
"""Writes a room lit by a ceiling panel split into N x N quads (2 N^2 triangles), as OBJ + MTL.

    many_emitters.py N all|one|lamps OUT_STEM

`all`: every panel triangle emits (N = 88 gives 15,488 emitters); `one`: only the first quad
does, the rest is white. Both files have the same triangles, so their rays per second compare
the cost of many lights alone (bench/README.md, "Many emitters").
`lamps`: a 40 x 40 floor under N x N small lamps hung 1.5 above it, each a quad facing down,
where most of a floor point's light comes from the few lamps near it (the light BVH's case).
"""
import sys


def main():
    if len(sys.argv) != 4 or sys.argv[2] not in ("all", "one", "lamps"):
        sys.exit(__doc__)
    n, emit_all, out = int(sys.argv[1]), sys.argv[2] == "all", sys.argv[3]
    vertices, faces = [], []

    def quad(a, b, c, d, material):
        i = len(vertices)
        vertices.extend([a, b, c, d])
        faces.append((material, (i + 1, i + 2, i + 3)))
        faces.append((material, (i + 1, i + 3, i + 4)))

    if sys.argv[2] == "lamps":
        quad((-20, 0, -20), (-20, 0, 20), (20, 0, 20), (20, 0, -20), "white")  # faces up
        for i in range(n):
            for j in range(n):
                x, z = -20 + 40 * (i + 0.5) / n, -20 + 40 * (j + 0.5) / n
                quad((x - 0.25, 1.5, z - 0.25), (x + 0.25, 1.5, z - 0.25), (x + 0.25, 1.5, z + 0.25),
                     (x - 0.25, 1.5, z + 0.25), "light")  # faces down
        write(out, vertices, faces)
        return
    # A 10-unit room open towards +z, its faces towards the inside.
    quad((0, 0, 0), (10, 0, 0), (10, 0, 10), (0, 0, 10), "white")
    quad((0, 0, 0), (0, 0, 10), (0, 10, 10), (0, 10, 0), "red")
    quad((10, 0, 0), (10, 10, 0), (10, 10, 10), (10, 0, 10), "green")
    quad((0, 0, 0), (0, 10, 0), (10, 10, 0), (10, 0, 0), "white")
    quad((0, 10, 0), (0, 10, 10), (10, 10, 10), (10, 10, 0), "white")
    for i in range(n):
        for j in range(n):
            x0, x1 = 3 + 4 * i / n, 3 + 4 * (i + 1) / n
            z0, z1 = 3 + 4 * j / n, 3 + 4 * (j + 1) / n
            material = "light" if emit_all or (i == 0 and j == 0) else "white"
            quad((x0, 9.99, z0), (x1, 9.99, z0), (x1, 9.99, z1), (x0, 9.99, z1), material)  # faces down
    write(out, vertices, faces)


def write(out, vertices, faces):
    stem = out.split("/")[-1]
    with open(out + ".mtl", "w") as f:
        f.write("newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.7 0.1 0.1\nnewmtl green\nKd 0.1 0.7 0.1\n"
                "newmtl light\nKd 0 0 0\nKe 5 5 5\n")
    with open(out + ".obj", "w") as f:
        f.write("mtllib %s.mtl\n" % stem)
        for p in vertices:
            f.write("v %g %g %g\n" % p)
        current = None
        for material, t in faces:
            if material != current:
                f.write("usemtl %s\n" % material)
                current = material
            f.write("f %d %d %d\n" % t)


if __name__ == "__main__":
    main()
