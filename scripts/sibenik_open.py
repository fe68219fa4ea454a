#!/usr/bin/env python3
"""Writes a copy of Šibenik without its window glass: open.obj and a diffuse-only sibenik.mtl.

    scripts/sibenik_open.py SIBENIK_FOLDER OUT_FOLDER

Blender's bake script reads only Kd and Ke, so it would make the glass black and opaque where gilt
lets light through; and the radiosity solver treats glass as opaque. Without it, every tool and
method lights the same open-windowed interior. Used by bench/blender_vertex_bake.sh and
bench/sibenik_compare.sh.
"""
import os
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[2].strip())
    src, dst = sys.argv[1], sys.argv[2]
    out, skip = [], False
    with open(os.path.join(src, "sibenik.obj")) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "usemtl":
                skip = t[1].startswith("staklo")  # the glass materials
            if t and t[0] == "f" and skip:
                continue
            out.append(line)
    with open(os.path.join(dst, "open.obj"), "w") as f:
        f.write("".join(out))
    mtl = []
    with open(os.path.join(src, "sibenik.mtl")) as f:
        for line in f:
            t = line.split()
            if t and t[0] in ("Ks", "Tf", "d", "Tr", "illum"):
                continue  # diffuse only, as the bake script reads it
            mtl.append(line)
    with open(os.path.join(dst, "sibenik.mtl"), "w") as f:
        f.write("".join(mtl))


if __name__ == "__main__":
    main()
