#!/usr/bin/python3
"""Rays per second of a five-texture PBR model against the same model without its textures, in
every method of gilt, and Blender Cycles' times on both (issue 59's benchmark).

    /usr/bin/python3 bench/texture_speed.py [OUT_DIR] [--runs 3] [--spp 256,32] [--size 128]
                                            [--methods path,whitted,radiosity,photon,sppm]
                                            [--cycles] [--gilt PATH]

Writes the model with bench/scenes/textured_model.py into OUT_DIR (default out/texture-speed),
then renders textured.json and untextured.json alternately, --runs times each, at --size² and
each spp, with 2 threads. For every method and spp it prints the medians of:
  render   rays per second over the render alone (gilt's --json rays_per_second)
  +load    rays per second over the texture load and the render together: what a user waiting
           for the image gets; the untextured model loads nothing, so its two agree. Twice: with
           a cold texture cache (emptied before each run: the images are decoded and their
           pyramids written to it) and a warm one (the pyramids read back), each in a folder of
           its own under the system's temporary folder
  wall     the whole command's wall time, from process start to the image written
and the textured model's share of the untextured's. First, the load alone: five_files.obj, whose
materials name all five 2048² images, rendered at 1 spp, --runs times: the median and the
range of texture_load_seconds. With --cycles, Blender Cycles renders the same
two wrappers (bench/cycles/cycles_render.py: CPU, 2 threads, no denoising, 128 bounces) once per
spp, and its render time and wall time (Blender's start and glTF import included) are added.
The table is written to OUT_DIR/table.md as well as printed. Needs numpy and OpenImageIO's Python
module; --cycles needs blender.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)


def run_gilt(gilt, scene, method, spp, size, cache):
    """One render; `cache` is the texture cache folder it may read and fill (GILT_TEXTURE_CACHE)."""
    cmd = [gilt, "render", scene, "--method", method, "--width", str(size), "--height", str(size),
           "--spp", str(spp), "--threads", "2", "--json", "-o", os.path.splitext(scene)[0] + "-" + method + ".exr"]
    start = time.monotonic()
    done = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, GILT_TEXTURE_CACHE=cache))
    wall = time.monotonic() - start
    if done.returncode != 0:
        sys.exit("texture_speed.py: %s failed:\n%s" % (" ".join(cmd), done.stderr))
    report = json.loads(done.stdout)
    load = report.get("texture_load_seconds", 0.0)
    rays = report["rays"]
    return {"render": report["rays_per_second"], "load": load,
            "with_load": rays / (report["seconds"] + load), "wall": wall}


def run_cycles(scene, spp, size, out):
    script = os.path.join(here, "cycles", "cycles_render.py")
    exr = os.path.join(out, "cycles-%s-%d.exr" % (os.path.splitext(os.path.basename(scene))[0], spp))
    cmd = ["blender", "-b", "--factory-startup", "-P", script, "--", scene, exr, str(spp), str(size), str(size),
           "--threads", "2"]
    start = time.monotonic()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - start
    seconds = [float(line.split()[1]) for line in done.stdout.splitlines() if line.startswith("RENDER_SECONDS")]
    if done.returncode != 0 or not seconds:
        sys.exit("texture_speed.py: %s failed:\n%s%s" % (" ".join(cmd), done.stdout[-2000:], done.stderr[-2000:]))
    return {"render_seconds": seconds[-1], "wall": wall}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join(root, "out", "texture-speed"))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--spp", default="256,32")
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--methods", default="path,whitted,radiosity,photon,sppm")
    parser.add_argument("--cycles", action="store_true")
    parser.add_argument("--gilt", default=os.path.join(root, "build", "cli", "gilt"))
    args = parser.parse_args()
    if args.runs < 1:
        sys.exit("--runs must be at least 1")
    out = os.path.abspath(args.out)
    if not os.path.exists(os.path.join(out, "model.gltf")):
        subprocess.run([sys.executable, os.path.join(here, "scenes", "textured_model.py"), out], check=True)
    scenes = {name: os.path.join(out, name + ".json") for name in ("textured", "untextured")}
    spps = [int(s) for s in args.spp.split(",")]

    # Texture cache folders: "cold" is emptied before every run (the images decoded, and their
    # pyramids written), "warm" keeps what the first run wrote.
    scratch = tempfile.mkdtemp(prefix="texture-speed-")
    caches = {"cold": os.path.join(scratch, "cold"), "warm": os.path.join(scratch, "warm")}

    def cache_for(mode):
        if mode == "cold":
            shutil.rmtree(caches["cold"], ignore_errors=True)
        return caches[mode]

    load_lines = []
    for mode in ("cold", "warm"):
        loads = []
        for _ in range(args.runs + (mode == "warm")):
            cmd = [args.gilt, "render", os.path.join(out, "five_files.obj"), "--spp", "1", "--width", "8", "--height",
                   "8", "--threads", "2", "--json", "-o", os.path.join(out, "five_files.exr")]
            done = subprocess.run(cmd, capture_output=True, text=True,
                                  env=dict(os.environ, GILT_TEXTURE_CACHE=cache_for(mode)))
            if done.returncode != 0:
                sys.exit("texture_speed.py: %s failed:\n%s" % (" ".join(cmd), done.stderr))
            report = json.loads(done.stdout)
            if report["textures"]["files"] != 5:
                sys.exit("texture_speed.py: five_files.obj loaded %d files, not 5" % report["textures"]["files"])
            loads.append(report["texture_load_seconds"])
        if mode == "warm":
            loads = loads[1:]  # the first run filled the cache
        load_lines.append("Five 2048² images (three PNG, two JPEG) loaded into pyramids, %s cache: median %.3f s "
                          "(%.3f-%.3f s, %d runs)" % (mode, statistics.median(loads), min(loads), max(loads), len(loads)))
        print(load_lines[-1], flush=True)

    lines = load_lines + ["", "| method | spp | M rays/s: render (textured / untextured, share) | +load, cold cache | +load, warm | "
                          "wall s: textured cold / warm / untextured | load s: cold / warm |", "|---|---|---|---|---|---|---|"]
    for method in args.methods.split(","):
        for spp in spps:
            runs = {"cold": [], "warm": [], "untextured": []}
            run_gilt(args.gilt, scenes["textured"], method, 1, 8, cache_for("warm"))  # fills the warm cache
            for _ in range(args.runs):  # alternate, so drift in the machine's speed hits all three
                for mode in ("cold", "warm"):
                    runs[mode].append(run_gilt(args.gilt, scenes["textured"], method, spp, args.size, cache_for(mode)))
                runs["untextured"].append(run_gilt(args.gilt, scenes["untextured"], method, spp, args.size,
                                                   cache_for("cold")))
            med = {name: {k: statistics.median(r[k] for r in runs[name]) for k in runs[name][0]} for name in runs}
            c, w, u = med["cold"], med["warm"], med["untextured"]
            render = statistics.median([r["render"] for r in runs["cold"] + runs["warm"]])
            line = "| %s | %d | %.2f / %.2f (%.0f %%) | %.2f (%.0f %%) | %.2f (%.0f %%) | %.2f / %.2f / %.2f | %.2f / %.3f |" % (
                method, spp, render / 1e6, u["render"] / 1e6, 100 * render / u["render"],
                c["with_load"] / 1e6, 100 * c["with_load"] / u["with_load"],
                w["with_load"] / 1e6, 100 * w["with_load"] / u["with_load"],
                c["wall"], w["wall"], u["wall"], c["load"], w["load"])
            lines.append(line)
            print(line, flush=True)
    if args.cycles:
        lines += ["", "| Cycles | spp | render s (textured / untextured) | wall s (textured / untextured) |",
                  "|---|---|---|---|"]
        for spp in spps:
            c = {name: run_cycles(scene, spp, args.size, out) for name, scene in scenes.items()}
            line = "| path (Cycles) | %d | %.2f / %.2f | %.2f / %.2f |" % (
                spp, c["textured"]["render_seconds"], c["untextured"]["render_seconds"],
                c["textured"]["wall"], c["untextured"]["wall"])
            lines.append(line)
            print(line, flush=True)
    shutil.rmtree(scratch, ignore_errors=True)
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
