#!/usr/bin/env bash
# gilt's vertex bake against the one a Blender user would make (Cycles' vertex-colour bake, run by
# ../shared/tools/cycles_bake.py), on Šibenik under a sun and sky, scored at the same random
# points against one path-traced reference. The windows' glass is taken out of a copy of the
# model (scripts/sibenik_open.py): both tools then light the same open-windowed interior.
#   bench/blender_vertex_bake.sh [GILT_TIME [BLENDER_SAMPLES [REFERENCE_SAMPLES]]]
# Needs build/cli/gilt, blender and python3-numpy. Figures in bench/README.md.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
shared=${SHARED:-$here/../shared}
seconds=${1:-60} samples=${2:-16} reference=${3:-16384}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
py=/usr/bin/python3
$py "$here/scripts/sibenik_open.py" "$shared/scenes/sibenik" "$work"
cat > "$work/open.json" <<'JSON'
{"meshes": [{"file": "open.obj"}],
 "lights": [{"type": "directional", "direction": [0.35, -1, 0.45], "irradiance": 8},
            {"type": "environment", "radiance": 1.0}]}
JSON
cd "$work"
# Blender bakes each face's front; the reference for it is taken on the front too (--one-sided).
# gilt's bakes are scored against their own checks, which hold each point's reference on the
# side the bake read (a wall lit on both sides carries the side the mesher kept).
echo "== reference: 2000 points, $reference path-traced samples each, every point on its face's front"
"$gilt" radiosity open.json --onto input --fit point --link-tolerance 1e-1 --final-gather off --quantity irradiance \
  --one-sided --check 2000 --check-samples "$reference" --check-points ref.csv -o ref.obj -q --threads 2 | grep check:
# The OBJ keeps one colour per `v` line; the GLB splits vertices where the light jumps across an edge.
for ext in obj glb; do
  echo "== gilt radiosity --onto input --time $seconds -o gilt.$ext"
  /usr/bin/time -f "gilt wall %e s" "$gilt" radiosity open.json --onto input --time "$seconds" --quantity irradiance \
    --check 2000 --check-samples 1024 --check-points "gilt-$ext.csv" -o "gilt.$ext" -q --threads 2 |
    grep -E "solve:|time:|positions|check:"
done
echo "== Blender Cycles vertex bake, $samples samples"
SUN="0.35,-1,0.45,8" ENV=1.0 blender -b --factory-startup -P "$shared/tools/cycles_bake.py" -- open.obj "$samples" \
  blender.npy 2 2>&1 | grep BAKE_SECONDS
for ext in obj glb; do
  echo "== scored: gilt.$ext against Blender"
  $py "$here/scripts/score_vertex_bake.py" "gilt-$ext.csv" open.obj blender.npy --reference ref.csv --own-reference \
    --label "blender $samples"
done
