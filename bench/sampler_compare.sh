#!/usr/bin/env bash
# Error against time for the two samplers, --sampler sobol and independent, on the Cornell box
# (path tracer) and cornell-caustics (path tracer, photon method, SPPM), each against one cached
# reference rendered with Sobol samples (gilt compare subtracts the reference's own noise).
#   bench/sampler_compare.sh [BUDGETS [REFERENCE_SECONDS [OUT_DIR]]]   (defaults: 1,4,16, 120, out/sampler-compare)
# About 8 minutes on two cores with the defaults (the references are cached for later runs).
# Figures in bench/README.md, "The Sobol sampler".
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
budgets=${1:-1,4,16} ref=${2:-120} out=${3:-$here/out/sampler-compare}
mkdir -p "$out"
run() {  # scene methods
  for sampler in sobol independent; do
    "$gilt" compare "$1" --methods "$2" --budgets "$budgets" --reference-time "$ref" --width 256 --height 256 \
      --threads 2 --sampler "$sampler" -q -o "$out/$1-$sampler"
  done
}
run cornell path
run cornell-caustics path,photon,sppm
python3 - "$out" <<'PY'
import json, math, sys
out = sys.argv[1]
print("| scene | method | sampler | budget s | spp | RMSE | relMSE | MSE × time | relMSE slope |")
print("|---|---|---|---|---|---|---|---|---|")
for scene in ("cornell", "cornell-caustics"):
    rows = {}
    for sampler in ("sobol", "independent"):
        for e in json.load(open(f"{out}/{scene}-{sampler}/metrics.json"))["entries"]:
            rows.setdefault((e["method"], sampler), []).append(e)
    for (method, sampler), es in sorted(rows.items()):
        # Least-squares slope of log relMSE against log time (-1 for an unbiased estimator whose
        # variance per sample stays the same).
        pts = [(math.log(e["seconds"]), math.log(e["relmse"])) for e in es if e["relmse"] > 0]
        slope = float("nan")
        if len(pts) > 1:
            mx = sum(p[0] for p in pts) / len(pts); my = sum(p[1] for p in pts) / len(pts)
            slope = sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts)
        for e in es:
            print(f"| {scene} | {method} | {sampler} | {e['budget_seconds']:g} | {e['spp_or_iterations']} | "
                  f"{e['rmse']:.5f} | {e['relmse']:.6f} | {e['rmse']**2 * e['seconds']:.2e} | {slope:.2f} |")
PY
