#!/usr/bin/env bash
# Whether `gilt radiosity SCENE --time T` ends in time (issue 57's target: within
# T + max(5 %, 2 s)), on every scene of ../shared/scenes that gilt loads and on generated furnished
# rooms, for each T given. Prints one Markdown row per run: the wall time of the whole command
# (loading to the written file), the target, and what the solve did in it (from --json).
#   bash bench/time_limits.sh BUILD_DIR "20 60 300" [ROOM_DIR ...]
# ROOM_DIR: a folder made by `python3 bench/scenes/generate.py DIR --only 22 --triangles N,N`
# (its 022-furnished-points-inward/scene.json is run). Takes about the sum of the T's per scene.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
gilt="$(cd "${1:?build dir}" && pwd)/cli/gilt"
times=${2:-"20 60"}
shift 2 || true
shared="$root/../shared/scenes"
scenes=("$shared/wrap/sibenik-lit.json" "$shared/wrap/bunny-lit.json" "$shared/wrap/truck-lit.json"
        "$shared/wrap/atten-lit.json" "$shared/winding/atrium-inward.json" "$shared/winding/atrium-outward.json"
        "$shared/cornell-water/CornellBox-Water.obj" "$shared/animate-all/24_animation_pointer.gltf"
        "$shared/conference-mapat-repro/repro-mapat.obj")
for room in "$@"; do scenes+=("$room/022-furnished-points-inward/scene.json"); done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| scene | T | wall | target | elements | links | shots | export s (kept back) |"
echo "|---|---|---|---|---|---|---|---|"
for scene in "${scenes[@]}"; do
  for t in $times; do
    start=$(date +%s.%N)
    if "$gilt" radiosity "$scene" --time "$t" -o "$out/out.ply" --json -q > "$out/run.json" 2> "$out/err.txt"; then
      end=$(date +%s.%N)
      python3 - "$scene" "$t" "$start" "$end" "$out/run.json" <<'PY'
import json, sys
scene, t, path = sys.argv[1], float(sys.argv[2]), sys.argv[5]
wall = float(sys.argv[4]) - float(sys.argv[3])
d = json.load(open(path))
target = t + max(0.05 * t, 2.0)
name = scene.split("/scenes/")[-1] if "/scenes/" in scene else scene
print(f"| {name} | {t:g} | {wall:.1f} s{'' if wall <= target else ' (LATE)'} | {target:g} s | {d['elements']} | "
      f"{d['links']} | {d['shots']} | {d['export_seconds']:.2f} ({d['export_seconds_kept_back']:.2f}) |")
PY
    else
      echo "| $scene | $t | failed: $(tail -1 "$out/err.txt") | | | | | |"
    fi
  done
done
