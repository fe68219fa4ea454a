#!/usr/bin/env bash
# Issue 10's 300k-triangle target: a radiosity solve of an interior of about 350,000 triangles,
# its time and peak memory. The scene is Šibenik with its windows open (scripts/sibenik_open.py,
# 72,517 triangles) with four Stanford bunnies (69,451 triangles each, an open scanned mesh)
# standing 2.3 m tall in the nave, under the sun and sky of bench/sibenik_compare.sh.
#   bench/interior_300k.sh [OUT_DIR [gilt radiosity options...]]   (default out/interior-300k)
# Prints the wall time and peak resident memory (GNU time) and the solve's phases. 2 threads.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
shared=${SHARED:-$here/../shared}
out=${1:-$here/out/interior-300k}
shift || true
mkdir -p "$out"
python3 "$here/scripts/sibenik_open.py" "$shared/scenes/sibenik" "$out"
bunny=$(cd "$shared/scenes/bunny" && pwd)/bun_zipper.ply
cat > "$out/interior.json" <<JSON
{"materials": {"marble": {"kind": "diffuse", "albedo": [0.7, 0.68, 0.62]}},
 "meshes": [{"file": "open.obj"},
  {"file": "$bunny", "material": "marble", "transform": {"scale": 15, "translate": [-8, -15.8, 2.5]}},
  {"file": "$bunny", "material": "marble", "transform": {"scale": 15, "rotate_deg_axis": [180, 0, 1, 0], "translate": [-2, -15.8, -2.5]}},
  {"file": "$bunny", "material": "marble", "transform": {"scale": 15, "rotate_deg_axis": [90, 0, 1, 0], "translate": [4, -15.8, 2.5]}},
  {"file": "$bunny", "material": "marble", "transform": {"scale": 15, "rotate_deg_axis": [-90, 0, 1, 0], "translate": [10, -15.8, -2.5]}}],
 "lights": [{"type": "directional", "direction": [0.35, -1, 0.45], "irradiance": 8},
            {"type": "environment", "radiance": 1.0}],
 "camera": {"look_from": [-17, -11, 0], "look_at": [0, -9, 0], "vfov": 60}}
JSON
cd "$out"
"$gilt" info interior.json 2>/dev/null | sed -n '/geometry/p;/solver:/p'
/usr/bin/time -f "wall %e s, peak resident %M KB" "$gilt" radiosity interior.json -o interior.ply --threads 2 --json -q "$@" \
  > solve.json 2> solve.err || { tail -5 solve.err; exit 1; }
tail -1 solve.err
python3 - <<'PY'
import json
d = json.load(open("solve.json"))
print(f"elements {d['elements']}, links {d['links']}, iterations {d['iterations']}, residual {d['residual']:.2g}")
print("phases (s): " + ", ".join(f"{k} {v:.1f}" for k, v in d["phase_seconds"].items() if v >= 0.05))
print(f"final gather: {d['final_gather_note']}")
PY
