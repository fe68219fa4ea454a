#!/usr/bin/env bash
# The light BVH against choosing lights by power (--light-sampler bvh|power), on the scenes of
# scripts/many_emitters.py:
#   1. rays per second: the room lit by a panel of 15,488 emitting triangles against the same
#      room with one emitting quad, each sampler, the runs interleaved (median of 3);
#   2. error at equal time: 576 lamps over a floor, gilt compare at 1 and 4 s against one
#      4,096-spp reference (128 x 96).
#   bench/many_lights.sh [OUT_DIR]   (default out/many-lights; about 3 minutes on two cores)
# Figures in bench/README.md, "Many emitters".
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
out=${1:-$here/out/many-lights}
mkdir -p "$out"
cd "$out"
python3 "$here/scripts/many_emitters.py" 88 all many
python3 "$here/scripts/many_emitters.py" 88 one one
python3 "$here/scripts/many_emitters.py" 24 lamps lamps
cat > lamps.json <<'JSON'
{"meshes": [{"file": "lamps.obj"}], "camera": {"look_from": [0, 25, -32], "look_at": [0, 0, -2], "vfov": 50}}
JSON

rate() {  # scene sampler -> Mrays/s
  "$gilt" render "$1.obj" --method path --spp 32 --threads 2 --light-sampler "$2" -o rate.png --json -q |
    python3 -c "import json, sys; print(json.load(sys.stdin)['rays_per_second'] / 1e6)"
}
: > rates.txt
for run in 1 2 3; do
  for scene in one many; do
    for sampler in bvh power; do echo "$scene $sampler $(rate $scene $sampler)" >> rates.txt; done
  done
done
python3 - <<'PY'
import statistics
rates = {}
for line in open("rates.txt"):
    scene, sampler, value = line.split()
    rates.setdefault((scene, sampler), []).append(float(value))
print("| sampler | one light, Mrays/s | 15,488 emitters, Mrays/s | ratio |")
print("|---|---|---|---|")
for sampler in ("bvh", "power"):
    one, many = (statistics.median(rates[(s, sampler)]) for s in ("one", "many"))
    print(f"| {sampler} | {one:.2f} | {many:.2f} | {many / one:.2f} |")
PY

[ -f lamps-ref.exr ] || "$gilt" render lamps.json --spp 4096 --width 128 --height 96 --seed 9 --threads 2 -q -o lamps-ref.exr
for sampler in bvh power; do
  "$gilt" compare lamps.json --reference lamps-ref.exr --methods path --budgets 1,4 --width 128 --height 96 \
    --threads 2 --light-sampler "$sampler" -q -o "lamps-$sampler"
done
python3 - <<'PY'
import json
print("| sampler | budget s | spp | RMSE | relMSE |")
print("|---|---|---|---|---|")
for sampler in ("bvh", "power"):
    for e in json.load(open(f"lamps-{sampler}/metrics.json"))["entries"]:
        print(f"| {sampler} | {e['budget_seconds']:g} | {e['spp_or_iterations']} | {e['rmse']:.5f} | {e['relmse']:.6f} |")
PY
