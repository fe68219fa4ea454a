#!/usr/bin/python3
"""The generated family of interiors (bench/scenes/generate.py) in the default test run.

    generated_family.py --gilt PATH --work DIR

1. The generator is deterministic: the same family seed writes the same bytes twice, and another
   seed writes other scenes.
2. Every scene of a small family loads in gilt with the triangle count the generator reports, and
   its camera stands inside the building (`gilt info --json`: no load errors).
3. The oracle holds on the family's geometry: each scene made a closed white furnace (every
   surface emitting Le from both sides with albedo ρ, closed by an enclosing box) reads
   Le / (1 − ρ) under the path tracer, whatever the winding. The tolerance is five standard errors
   of the image's mean, from the spread of its pixels (independent estimates), so the test fails
   by chance about once in 3.5 million runs.
Exit code 0 when every check holds, 1 otherwise; every check prints what it measured.
"""

import argparse
import filecmp
import json
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.path.join(HERE, "..", "..", "bench", "scenes", "generate.py")
failures = []


def check(ok, message):
    print(("ok    " if ok else "FAIL  ") + message, flush=True)
    if not ok:
        failures.append(message)


def generate(out, seed, extra=()):
    shutil.rmtree(out, ignore_errors=True)
    subprocess.run([sys.executable, GENERATOR, out, "--seed", str(seed), "--count", "6", "--triangles", "2000,5000",
                    *extra], check=True, capture_output=True)
    return json.load(open(os.path.join(out, "family.json")))


def same_tree(a, b):
    cmp = filecmp.dircmp(a, b)
    if cmp.left_only or cmp.right_only or cmp.diff_files or cmp.funny_files:
        return False
    same = True
    for sub in cmp.common_dirs:
        same = same and same_tree(os.path.join(a, sub), os.path.join(b, sub))
    # dircmp compares by os.stat signatures; compare the bytes of every common file as well.
    for f in cmp.common_files:
        same = same and filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False)
    return same


def image_stats(path):
    import OpenImageIO as oiio
    px = oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[..., :3]
    per_pixel = px.mean(axis=2).ravel()
    n = per_pixel.size
    mean = float(per_pixel.mean())
    se = float(per_pixel.std(ddof=1)) / math.sqrt(n)
    return mean, se, int((~(px == px)).sum()), int((px < 0).sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gilt", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    try:
        import OpenImageIO  # noqa: F401  (Debian's python3-openimageio reads the images)
    except ImportError:
        print("skipped: OpenImageIO's Python binding (python3-openimageio) is not installed")
        return 77
    os.makedirs(args.work, exist_ok=True)

    # 1. Determinism.
    a = generate(os.path.join(args.work, "a"), 7)
    generate(os.path.join(args.work, "b"), 7)
    check(same_tree(os.path.join(args.work, "a"), os.path.join(args.work, "b")),
          "the same seed writes the same bytes (6 scenes)")
    c = generate(os.path.join(args.work, "c"), 8)
    differ = sum(not filecmp.cmp(os.path.join(args.work, "a", x["name"], "scene.json"),
                                 os.path.join(args.work, "c", y["name"], "scene.json"), shallow=False)
                 for x, y in zip(a["scenes"], c["scenes"]))
    check(differ == 6, f"another seed writes other scenes ({differ} of 6 differ)")

    # 2. Every scene loads with the generator's triangle count.
    for entry in a["scenes"]:
        scene = os.path.join(args.work, "a", entry["scene"])
        p = subprocess.run([args.gilt, "info", scene, "--json"], capture_output=True, text=True)
        if p.returncode != 0:
            check(False, f"{entry['name']}: gilt info exited {p.returncode}: {p.stderr.strip()}")
            continue
        info = json.loads(p.stdout)
        check(info["triangles"] == entry["triangles"],
              f"{entry['name']}: gilt reads {info['triangles']} triangles, the generator wrote {entry['triangles']}")
        eye = json.load(open(scene))["camera"]["look_from"]
        lo, hi = info["bounds"]["min"], info["bounds"]["max"]
        check(all(lo[i] < eye[i] < hi[i] for i in range(3)),
              f"{entry['name']}: the camera {eye} stands inside the bounds {lo} .. {hi}")

    # 3. The path tracer's furnace on every winding the family has.
    albedo, emission = 0.6, 1.0
    expected = emission / (1 - albedo)
    f = generate(os.path.join(args.work, "furnace"), 7, ["--furnace", f"{albedo},{emission}"])
    for entry in f["scenes"]:
        scene = os.path.join(args.work, "furnace", entry["scene"])
        image = os.path.join(args.work, "furnace", entry["name"] + "-path.exr")
        p = subprocess.run([args.gilt, "render", scene, "--method", "path", "--spp", "32", "--width", "48", "--height", "36",
                            "--seed", str(entry["index"] + 1), "-q", "-o", image], capture_output=True, text=True)
        if p.returncode != 0:
            check(False, f"{entry['name']}: gilt render exited {p.returncode}: {p.stderr.strip()}")
            continue
        mean, se, nan, negative = image_stats(image)
        check(nan == 0 and negative == 0 and abs(mean - expected) <= 5 * se,
              f"{entry['name']} ({entry['winding']}) furnace, path tracer: {mean:.5f} ± {se:.5f} against "
              f"{expected:.5f} (|z| = {abs(mean - expected) / max(se, 1e-12):.2f}, bound 5; {nan} NaN, {negative} negative)")

    print(f"{len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
