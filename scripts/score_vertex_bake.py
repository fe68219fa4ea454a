#!/usr/bin/env python3
"""Scores a Blender Cycles vertex bake against the path-traced points of a gilt check.

    score_vertex_bake.py POINTS.csv MODEL.obj BAKE.npy [--label NAME] [--reference REF.csv]

POINTS.csv comes from `gilt radiosity ... --onto input --check N --check-points POINTS.csv` on the
same OBJ. BAKE.npy comes from ../shared/tools/cycles_bake.py on that OBJ: one row per face corner
(OBJ vertex index, radiance r g b), corners in the OBJ's face order. At each point the bake's
radiance is its face's corners interpolated with the point's barycentric weights, as a viewer
shows a per-corner colour, and turned into irradiance, E = pi L / albedo. The figures use gilt's
own definitions (radiosity/bake/check.cpp), so the two bakes are scored by one reference:
  relMSE = mean (E - E_ref)^2 / (E_ref^2 + f^2),  mean relative error = mean |E - E_ref| / (E_ref + f),
with f = 1 % of the mean reference, over points and channels, and the median over points of
the relative error (less ruled by the few worst points). gilt's own bake (the CSV's `baked`
columns) is scored beside it the same way. --reference takes the path-traced columns from another
check of the same scene and seed (the same points, drawn again; say with many more samples), so
several bakes can be scored by one low-noise reference without paying for it each time.
With --own-reference, gilt's bake is scored against POINTS.csv's own path-traced columns and only
the Blender bake against --reference: gilt's check holds each point's reference on the side of
the surface gilt's bake read, which need not be the front that Blender bakes (a wall lit on both
sides), so a reference made with `--one-sided` (every point's front) scores Blender.
"""
import argparse
import csv
import math
import sys


def faces_of(obj_path):
    """Each OBJ face as its list of vertex indices (from 0), in file order."""
    faces = []
    count = 0
    with open(obj_path) as f:
        for line in f:
            s = line.split()
            if not s:
                continue
            if s[0] == "v":
                count += 1
            elif s[0] == "f":
                idx = []
                for t in s[1:]:
                    i = int(t.split("/")[0])
                    idx.append(i - 1 if i > 0 else count + i)
                faces.append(idx)
    return faces


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("points")
    ap.add_argument("obj")
    ap.add_argument("bake")
    ap.add_argument("--label", default="blender")
    ap.add_argument("--reference", help="CSV of the same check points whose reference columns to use")
    ap.add_argument("--own-reference", action="store_true",
                    help="score gilt against POINTS.csv's own reference columns, only Blender against --reference")
    a = ap.parse_args()
    import numpy as np

    bake = np.load(a.bake)
    faces = faces_of(a.obj)
    corners = sum(len(f) for f in faces)
    if bake.shape != (corners, 4):
        sys.exit(f"score_vertex_bake: {a.bake} holds {bake.shape[0]} corners, {a.obj} has {corners}")
    # Corner values of each face, by vertex: a triangle of the loader lies inside one face.
    first = []
    row = 0
    by_triangle = {}
    for fi, f in enumerate(faces):
        first.append(row)
        for k in range(len(f)):
            if int(bake[row + k, 0]) != f[k]:
                sys.exit(f"score_vertex_bake: corner {row + k} of the bake is vertex {int(bake[row + k, 0])}, "
                         f"the OBJ says {f[k]}: not a bake of this file")
        n = len(f)
        for i in range(1, n - 1):  # every fan triangle, keyed by its sorted corners
            by_triangle.setdefault(tuple(sorted((f[0], f[i], f[i + 1]))), fi)
        row += n
    rows = list(csv.DictReader(open(a.points)))
    if not rows:
        sys.exit(f"score_vertex_bake: {a.points} holds no points")
    for r in rows:  # gilt's own reference, on the side its bake read
        for c in "rgb":
            r[f"own_reference_{c}"] = r[f"reference_{c}"]
    if a.reference:
        at = {(r["x"], r["y"], r["z"]): r for r in csv.DictReader(open(a.reference))}
        joined = []
        for r in rows:
            q = at.get((r["x"], r["y"], r["z"]))
            if q is None:
                continue
            for c in "rgb":
                r[f"reference_{c}"] = q[f"reference_{c}"]
                r[f"standard_error_{c}"] = q[f"standard_error_{c}"]
            joined.append(r)
        if not joined:
            sys.exit(f"score_vertex_bake: {a.reference} shares no point with {a.points} (another scene or seed?)")
        rows = joined
    ref = np.array([[float(r[f"reference_{c}"]) for c in "rgb"] for r in rows])
    own = np.array([[float(r[f"own_reference_{c}"]) for c in "rgb"] for r in rows]) if a.own_reference else ref
    se = np.array([[float(r[f"standard_error_{c}"]) for c in "rgb"] for r in rows])
    albedo = np.array([[float(r[f"albedo_{c}"]) for c in "rgb"] for r in rows])
    gilt = np.array([[float(r[f"baked_{c}"]) for c in "rgb"] for r in rows])
    other = np.zeros_like(ref)
    missing = 0
    for i, r in enumerate(rows):
        v = [int(r["v0"]), int(r["v1"]), int(r["v2"])]
        fi = by_triangle.get(tuple(sorted(v)))
        if fi is None:
            missing += 1
            other[i] = np.nan
            continue
        f = faces[fi]
        value = np.zeros(3)
        for k in range(3):
            value += float(r[f"w{k}"]) * bake[first[fi] + f.index(v[k]), 1:4]
        other[i] = math.pi * value / albedo[i]
    keep = ~np.isnan(other[:, 0])

    def score(x, reference):
        r = reference[keep]
        floor = 0.01 * r.mean()
        d = x[keep] - r
        rel = np.abs(d) / (r + floor)
        return ((d * d) / (r * r + floor * floor)).mean(), rel.mean(), np.median(rel.mean(axis=1)), x[keep].mean() / r.mean()

    floor = 0.01 * ref[keep].mean()
    share = (se[keep] ** 2 / (ref[keep] ** 2 + floor * floor)).mean()
    print(f"points {int(keep.sum())} (faces not found: {missing}); reference's own share of relMSE {share:.4g}"
          + ("; gilt scored against its own check's reference" if a.own_reference else ""))
    for name, x, reference in (("gilt", gilt, own), (a.label, other, ref)):
        m, e, med, ratio = score(x, reference)
        print(f"{name:>10}: relMSE {m:.4g}  mean relative error {100 * e:.1f} %  median {100 * med:.1f} %  "
              f"mean {ratio:.3f} of the reference")


if __name__ == "__main__":
    main()
