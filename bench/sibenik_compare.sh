#!/usr/bin/env bash
# The issue's Sponza-class target: gilt compare on Šibenik's nave under a sun and sky, path tracer
# against the radiosity render at equal time, against a long path-traced reference. The windows'
# glass is taken out of a copy of the model (scripts/sibenik_open.py), since the radiosity solver
# treats glass as opaque and a path tracer sees the sky through it only by chance.
#   bench/sibenik_compare.sh [BUDGETS [REFERENCE_SPP [OUT_DIR]]]   (defaults: 60, 2048, out/sibenik-compare)
# The reference (256 x 192, about 10 minutes on two cores at 2048 spp) is kept in OUT_DIR and
# reused. Figures in bench/README.md.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
shared=${SHARED:-$here/../shared}
budgets=${1:-60} spp=${2:-2048} out=${3:-$here/out/sibenik-compare}
mkdir -p "$out"
python3 "$here/scripts/sibenik_open.py" "$shared/scenes/sibenik" "$out"
cat > "$out/open.json" <<'JSON'
{"meshes": [{"file": "open.obj"}],
 "lights": [{"type": "directional", "direction": [0.35, -1, 0.45], "irradiance": 8},
            {"type": "environment", "radiance": 1.0}],
 "camera": {"look_from": [-17, -11, 0], "look_at": [0, -9, 0], "vfov": 60}}
JSON
cd "$out"
if [ ! -f "reference_$spp.exr" ]; then
  echo "== reference: $spp spp path traced"
  "$gilt" render open.json --method path --spp "$spp" --width 256 --height 192 --seed 7 --threads 2 -q \
    -o "reference_$spp.exr"
fi
"$gilt" compare open.json --reference "reference_$spp.exr" --methods path,radiosity --budgets "$budgets" \
  --width 256 --height 192 --threads 2 -o report
