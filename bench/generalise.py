#!/usr/bin/python3
"""Radiosity against the path tracer on a generated family of interiors (bench/scenes/generate.py).

    /usr/bin/python3 bench/generalise.py FAMILY_DIR -o OUT_DIR [--gilt build/cli/gilt]
        [--time 60] [--reference-time 600] [--width 256 --height 192] [--untimed-spp 64]
        [--exports elements,input,lightmap] [--check 2000] [--check-samples 1024]
        [--only NAME_OR_INDEX ...] [--threads N] [--seed 0]

For every scene of FAMILY_DIR/family.json it runs, on the scene's own camera:
  image    `gilt compare SCENE --methods path,radiosity --budgets T --reference-time R`: both
           methods at equal time against a path-traced reference made of two independent
           halves (its noise is subtracted from relMSE; cached by gilt between runs);
  untimed  `gilt render SCENE --method radiosity --spp S` at the solver's default tolerances,
           its mean over the reference's (needs OpenImageIO's Python binding, Debian's
           python3-openimageio, hence /usr/bin/python3);
  exports  `gilt radiosity SCENE --time T --check N --json` for each export: `elements` (the
           element mesh, checked at random points inside the input's faces, with the share of
           points an exported face of the same orientation covers), `input` (--onto input, as .glb) and
           `lightmap` (--lightmap 1024): relMSE and mean ratio against path-traced irradiance.
A family written with `generate.py --furnace` is measured as furnaces instead: the path tracer
and both radiosity views against the exact Le / (1 − ρ), with the darkest pixel and the count of
negative or NaN values.

It writes OUT_DIR/table.md (a Markdown table), OUT_DIR/results.json and OUT_DIR/results.csv, with
every command it ran in OUT_DIR/commands.txt so any number can be reproduced by hand. A command
that fails is recorded with its exit code and message, and the harness goes on to the next one.
"""

import argparse
import csv
import json
import os
import shlex
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run(cmd, log, timeout):
    """Runs cmd, appends it to the command log, returns (exit code, stdout, stderr, seconds)."""
    log.write(" ".join(shlex.quote(c) for c in cmd) + "\n")
    log.flush()
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr, time.monotonic() - start
    except subprocess.TimeoutExpired:
        return -1, "", f"timed out after {timeout} s", time.monotonic() - start


def last_json(text):
    """The last line of stdout that parses as a JSON object (gilt --json prints one)."""
    for line in reversed(text.strip().splitlines()):
        line = line.strip()
        if line.startswith("{"):
            try:
                return json.loads(line)
            except json.JSONDecodeError:
                pass
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return None


def image_stats(path):
    """Mean over pixels and channels, its standard error from the pixels' spread, the smallest
    value, and the count of NaN or negative values."""
    import math
    import OpenImageIO as oiio
    px = oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[..., :3]
    per_pixel = px.mean(axis=2).ravel()
    bad = int((~(px == px)).sum() + (px < 0).sum())
    return float(per_pixel.mean()), float(per_pixel.std(ddof=1)) / math.sqrt(per_pixel.size), float(px.min()), bad


def furnace_rows(args, entry, family_dir, log):
    """A closed white furnace (generate.py --furnace): every method should read Le / (1 − ρ)."""
    scene = os.path.join(family_dir, entry["scene"])
    out = os.path.join(args.out, entry["name"])
    os.makedirs(out, exist_ok=True)
    common = ["--threads", str(args.threads)] if args.threads else []
    expected = entry["furnace"]["emission"] / (1 - entry["furnace"]["albedo"])
    row = {k: entry[k] for k in ("name", "kind", "winding", "triangles")}
    row["expected"] = expected
    row["errors"] = []
    runs = [("path", ["--method", "path", "--spp", str(max(args.untimed_spp, 32))]),
            ("two_pass", ["--method", "radiosity", "--spp", str(args.untimed_spp)]),
            ("mesh_view", ["--method", "radiosity", "--radiosity-view", "mesh", "--spp", str(args.untimed_spp)])]
    for key, flags in runs:
        img = os.path.join(out, key + ".exr")
        rc, so, se, secs = run([args.gilt, "render", scene, *flags, "--width", str(args.width), "--height",
                                str(args.height), "--seed", str(args.seed), "-q", "-o", img] + common, log, args.timeout)
        if rc != 0:
            row["errors"].append(f"{key}: exit {rc}: {se.strip().splitlines()[-1] if se.strip() else ''}")
            continue
        mean, stderr, lowest, bad = image_stats(img)
        row[f"{key}_mean"] = mean / expected
        row[f"{key}_stderr"] = stderr / expected
        row[f"{key}_min"] = lowest / expected
        row[f"{key}_bad"] = bad
        row[f"{key}_seconds"] = secs
    row["errors"] = "; ".join(row["errors"])
    return row


def scene_rows(args, entry, family_dir, log):
    scene = os.path.join(family_dir, entry["scene"])
    out = os.path.join(args.out, entry["name"])
    os.makedirs(out, exist_ok=True)
    common = ["--threads", str(args.threads)] if args.threads else []
    row = {k: entry[k] for k in ("name", "kind", "lighting", "winding", "albedo", "triangles")}
    row["errors"] = []

    # Image at equal time, both methods, against the two-halves reference.
    cmp_dir = os.path.join(out, "compare")
    rc, so, se, secs = run([args.gilt, "compare", scene, "--methods", "path,radiosity", "--budgets", str(args.time),
                            "--reference-time", str(args.reference_time), "--reference-method", "path",
                            "--width", str(args.width), "--height", str(args.height), "--seed", str(args.seed), "-q",
                            "-o", cmp_dir] + common, log, args.timeout)
    reference = os.path.join(cmp_dir, "images", "reference.exr")
    if rc == 0:
        m = json.load(open(os.path.join(cmp_dir, "metrics.json")))
        row["reference_noise_relmse"] = m.get("reference_relmse_floor")
        for e in m["entries"]:
            row[f"{e['method']}_relmse"] = e["relmse"]
            row[f"{e['method']}_mean"] = e["mean_ratio"]
            row[f"{e['method']}_seconds"] = e["seconds"]
    else:
        row["errors"].append(f"compare: exit {rc}: {se.strip().splitlines()[-1] if se.strip() else ''}")

    # Untimed radiosity render: its mean over the reference's.
    if args.untimed_spp > 0 and os.path.exists(reference):
        img = os.path.join(out, "radiosity_untimed.exr")
        rc, so, se, secs = run([args.gilt, "render", scene, "--method", "radiosity", "--spp", str(args.untimed_spp),
                                "--width", str(args.width), "--height", str(args.height), "--seed", str(args.seed), "-q",
                                "-o", img] + common, log, args.timeout)
        if rc == 0:
            mean, _, _, bad = image_stats(img)
            ref_mean = image_stats(reference)[0]
            row["untimed_mean"] = mean / ref_mean if ref_mean > 0 else None
            row["untimed_seconds"] = secs
            row["untimed_bad_pixels"] = bad
        else:
            row["errors"].append(f"untimed render: exit {rc}: {se.strip().splitlines()[-1] if se.strip() else ''}")

    # The exports, each checked at random points inside the input's faces.
    for kind in args.exports:
        if kind == "elements":
            extra, target = [], os.path.join(out, "elements.glb")
        elif kind == "input":
            # glTF, whose vertices split where the light jumps (an OBJ holds one colour per vertex)
            extra, target = ["--onto", "input"], os.path.join(out, "input.glb")
        elif kind == "lightmap":
            extra, target = ["--lightmap", "1024"], os.path.join(out, "lightmap.glb")
        else:
            continue
        rc, so, se, secs = run([args.gilt, "radiosity", scene, "-o", target, "--time", str(args.time), "--check",
                                str(args.check), "--check-samples", str(args.check_samples), "--seed", str(args.seed),
                                "--json"] + extra + common, log, args.timeout)
        j = last_json(so) if rc == 0 else None
        if j is None:
            row["errors"].append(f"{kind}: exit {rc}: {se.strip().splitlines()[-1] if se.strip() else ''}")
            continue
        c = j.get("surface_check") if kind == "elements" else j.get("check")
        row[f"{kind}_seconds"] = secs
        if c:
            row[f"{kind}_relmse"] = c.get("relative_mse")
            row[f"{kind}_mean"] = c.get("mean_ratio")
            if kind == "elements":
                row["elements_covered"] = c.get("covered_share")
    row["errors"] = "; ".join(row["errors"])
    return row


COLUMNS = [
    ("name", "scene", "{}"), ("triangles", "triangles", "{:,}"),
    ("path_relmse", "path relMSE", "{:.4f}"), ("radiosity_relmse", "radiosity relMSE", "{:.4f}"),
    ("radiosity_mean", "radiosity mean", "{:.3f}"), ("untimed_mean", "untimed mean", "{:.3f}"),
    ("elements_mean", "elements mean", "{:.3f}"), ("elements_relmse", "elements relMSE", "{:.4f}"),
    ("elements_covered", "covered", "{:.3f}"),
    ("input_mean", "input mean", "{:.3f}"), ("input_relmse", "input relMSE", "{:.4f}"),
    ("lightmap_mean", "lightmap mean", "{:.3f}"), ("lightmap_relmse", "lightmap relMSE", "{:.4f}"),
    ("errors", "failures", "{}"),
]


def cell(row, key, fmt):
    v = row.get(key)
    if v is None or v == "":
        return "–"
    try:
        return fmt.format(v)
    except (ValueError, TypeError):
        return str(v)


FURNACE_COLUMNS = [
    ("name", "scene", "{}"), ("triangles", "triangles", "{:,}"),
    ("path_mean", "path / exact", "{:.4f}"), ("path_stderr", "± (1 se)", "{:.4f}"),
    ("two_pass_mean", "radiosity two-pass / exact", "{:.4f}"), ("two_pass_min", "its darkest pixel", "{:.3f}"),
    ("mesh_view_mean", "radiosity mesh view / exact", "{:.4f}"), ("mesh_view_min", "its darkest pixel", "{:.3f}"),
    ("mesh_view_bad", "negative or NaN values", "{}"), ("errors", "failures", "{}"),
]


def write_tables(args, rows, header):
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump({"settings": header, "rows": rows}, f, indent=1)
    keys = sorted({k for r in rows for k in r})
    with open(os.path.join(args.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        if header.get("furnace"):
            f.write(f"Furnace family seed {header['family_seed']}, {args.width} × {args.height}, path tracer at "
                    f"{max(args.untimed_spp, 32)} spp, radiosity views at {args.untimed_spp} spp, default tolerances.\n\n")
        else:
            f.write(f"Family seed {header['family_seed']}, budget {args.time} s, reference {args.reference_time} s, "
                    f"{args.width} × {args.height}, untimed at {args.untimed_spp} spp, checks of {args.check} points × "
                    f"{args.check_samples} samples.\n\n")
        columns = FURNACE_COLUMNS if header.get("furnace") else COLUMNS
        f.write("| " + " | ".join(c[1] for c in columns) + " |\n")
        f.write("|" + "---|" * len(columns) + "\n")
        for r in rows:
            f.write("| " + " | ".join(cell(r, k, fmt) for k, _, fmt in columns) + " |\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("family", help="a folder written by bench/scenes/generate.py")
    ap.add_argument("-o", "--out", required=True, help="folder for the results")
    ap.add_argument("--gilt", default=os.path.join(HERE, "..", "build", "cli", "gilt"))
    ap.add_argument("--time", type=float, default=60, help="equal-time budget, seconds (default 60)")
    ap.add_argument("--reference-time", type=float, default=600, help="path-traced reference, seconds (default 600)")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=192)
    ap.add_argument("--untimed-spp", type=int, default=64, help="untimed radiosity render's spp; 0 skips it")
    ap.add_argument("--exports", default="elements,input,lightmap", help="comma-separated; empty skips them")
    ap.add_argument("--check", type=int, default=2000)
    ap.add_argument("--check-samples", type=int, default=1024)
    ap.add_argument("--only", nargs="*", help="scene names or indices")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=0,
                    help="per command, seconds (default 5 × --time + 600: a command past it is recorded as a failure)")
    args = ap.parse_args()
    if args.timeout <= 0:
        args.timeout = 5 * args.time + 600
    args.exports = [e for e in args.exports.split(",") if e]
    bad = [e for e in args.exports if e not in ("elements", "input", "lightmap")]
    if bad:
        sys.exit(f"generalise.py: --exports: unknown {', '.join(bad)} (expected elements, input, lightmap)")
    listing_path = os.path.join(args.family, "family.json")
    if not os.path.exists(listing_path):
        sys.exit(f"generalise.py: {listing_path} not found: write the family with bench/scenes/generate.py first")
    if not os.access(args.gilt, os.X_OK):
        sys.exit(f"generalise.py: {args.gilt} is not an executable gilt: build it or give --gilt")
    family = json.load(open(listing_path))
    scenes = family["scenes"]
    if args.only:
        scenes = [s for s in scenes if s["name"] in args.only or str(s["index"]) in args.only]
    os.makedirs(args.out, exist_ok=True)
    header = {"family_seed": family["seed"], "time": args.time, "reference_time": args.reference_time,
              "width": args.width, "height": args.height, "untimed_spp": args.untimed_spp, "check": args.check,
              "check_samples": args.check_samples, "seed": args.seed,
              "furnace": any(e.get("furnace") for e in scenes)}
    rows = []
    with open(os.path.join(args.out, "commands.txt"), "a") as log:
        for entry in scenes:
            t0 = time.monotonic()
            if entry.get("furnace"):
                rows.append(furnace_rows(args, entry, args.family, log))
                write_tables(args, rows, header)
                r = rows[-1]
                print(f"{entry['name']}: path {cell(r, 'path_mean', '{:.4f}')}, two-pass "
                      f"{cell(r, 'two_pass_mean', '{:.4f}')}, mesh view {cell(r, 'mesh_view_mean', '{:.4f}')} of "
                      f"the exact radiance" + (f"; failures: {r['errors']}" if r["errors"] else ""), flush=True)
                continue
            rows.append(scene_rows(args, entry, args.family, log))
            write_tables(args, rows, header)
            r = rows[-1]
            print(f"{entry['name']}: radiosity mean {cell(r, 'radiosity_mean', '{:.3f}')}, relMSE "
                  f"{cell(r, 'radiosity_relmse', '{:.4f}')} (path {cell(r, 'path_relmse', '{:.4f}')}), untimed "
                  f"{cell(r, 'untimed_mean', '{:.3f}')}, {time.monotonic() - t0:.0f} s"
                  + (f"; failures: {r['errors']}" if r["errors"] else ""), flush=True)


if __name__ == "__main__":
    main()
