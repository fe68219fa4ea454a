#!/usr/bin/env bash
# gilt's path tracer against Blender Cycles (Debian 12's blender 3.4, CPU) on the same glTF scenes,
# camera and lights, to check gilt's glTF metallic-roughness material, base-colour textures and
# rough glass (KHR_materials_transmission with roughness).
#   bash bench/cycles/compare.sh [OUT_DIR]                  (default out/cycles-compare)
# Environment: GILT (the gilt binary; default build/cli/gilt of this checkout), SPP_GILT (2048),
#   SPP_CYCLES (1024), WIDTH (320), HEIGHT (240), THREADS (2), NICE (10),
#   CASES ("plane furnace lone spheres spheres-multiggx truck glass glass-multiggx glass-furnace
#   glass-furnace-multiggx"),
#   SHARED (../shared, for the truck).
# Every render is split in two halves of different seeds, whose difference measures the noise.
# Writes OUT_DIR/results.md (all tables), *.png (gilt | Cycles | log2 luminance ratio gilt/Cycles,
# +-0.5 stops, red where gilt is brighter), *.json (compare.py), importer.txt (what Blender's glTF
# importer made of each material) and the renders. Figures and analysis: README.md here.
# Needs: apt-get install blender python3-openimageio python3-numpy.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
gilt=${GILT:-$root/build/cli/gilt}
shared=${SHARED:-$root/../shared}
out=${1:-$root/out/cycles-compare}
spp_gilt=${SPP_GILT:-2048} spp_cycles=${SPP_CYCLES:-1024}
width=${WIDTH:-320} height=${HEIGHT:-240} threads=${THREADS:-2} nice=${NICE:-10}
cases=${CASES:-plane furnace lone spheres spheres-multiggx truck glass glass-multiggx glass-furnace glass-furnace-multiggx}
py=/usr/bin/python3     # Debian's python, where python3-openimageio installs

command -v blender >/dev/null || { echo "compare.sh: needs blender (apt-get install blender)" >&2; exit 1; }
$py -c "import OpenImageIO, numpy" 2>/dev/null ||
  { echo "compare.sh: needs python3-openimageio and python3-numpy" >&2; exit 1; }
[ -x "$gilt" ] || { echo "compare.sh: no gilt at $gilt (build it, or set GILT)" >&2; exit 1; }
mkdir -p "$out"
cd "$out"
start=$(date +%s)
$py "$here/make_scenes.py" .

# One wrapper per scene, read by both renderers. A directional light's direction is the way its
# light travels; irradiance in W/m^2, environment radiance in W/(sr m^2).
lights='"lights": [{"type": "directional", "direction": [-0.4, -1, -0.6], "irradiance": 3},
            {"type": "environment", "radiance": 0.3}]'
spheres_camera='"camera": {"look_from": [0, 2.6, 5.6], "look_at": [0, 0.3, 0], "up": [0, 1, 0], "vfov": 42}'
cat > plane-scene.json <<JSON
{"meshes": [{"file": "ground.gltf"}],
 $lights,
 "camera": {"look_from": [0, 5, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "vfov": 40}}
JSON
cat > furnace-scene.json <<JSON
{"meshes": [{"file": "furnace.gltf"}],
 $lights,
 "camera": {"look_from": [0, 8, 13.5], "look_at": [0, 0.4, 0], "up": [0, 1, 0], "vfov": 40}}
JSON
cat > lone-scene.json <<JSON
{"meshes": [{"file": "lone.gltf"}],
 $lights,
 $spheres_camera}
JSON
cat > spheres-scene.json <<JSON
{"meshes": [{"file": "spheres.gltf"}],
 $lights,
 $spheres_camera}
JSON
# Three solid glass spheres, roughness 0 / 0.3 / 0.6 left to right, on the ground; and the same
# spheres alone under a uniform sky of radiance 1 (a white furnace: an energy-conserving glass
# sphere is as bright as the sky, so a sphere's mean radiance is the fraction of energy it keeps).
glass_camera='"camera": {"look_from": [0, 1.4, 4.6], "look_at": [0, 0.45, 0], "up": [0, 1, 0], "vfov": 34}'
cat > glass-scene.json <<JSON
{"meshes": [{"file": "glass.gltf"}],
 $lights,
 $glass_camera}
JSON
cat > glass-furnace-scene.json <<JSON
{"meshes": [{"file": "glass-furnace.gltf"}],
 "lights": [{"type": "environment", "radiance": 1}],
 $glass_camera}
JSON
# The truck: the lights of $shared/scenes/wrap/truck-lit.json, on the ground square; and the truck
# alone, whose Cycles alpha marks the truck's pixels.
truck='{"file": "'$shared'/scenes/milk-truck/CesiumMilkTruck.gltf"}'
truck_camera='"camera": {"look_from": [5.5, 3.0, 7.0], "look_at": [0, 1.0, 0], "up": [0, 1, 0], "vfov": 36}'
cat > truck-scene.json <<JSON
{"meshes": [$truck, {"file": "ground.gltf"}],
 "lights": [{"type": "directional", "direction": [-0.4, -1, -0.6], "irradiance": 2},
            {"type": "environment", "radiance": 0.3}],
 $truck_camera}
JSON
cat > truck-body-scene.json <<JSON
{"meshes": [$truck], "lights": [], $truck_camera}
JSON

# render_gilt NAME SCENE SPP: two half renders; prints the seconds spent.
render_gilt() {
  local total=0 s
  for seed in 1 2; do
    s=$(nice -n "$nice" "$gilt" render "$2" --method path --spp $(($3 / 2)) --width "$width" --height "$height" \
          --seed "$seed" --threads "$threads" --json -o "gilt-$1-$seed.exr" |
        $py -c "import json, sys; print(json.load(sys.stdin)['seconds'])")
    total=$($py -c "print($total + $s)")
  done
  echo "$total"
}

# render_cycles NAME SCENE SPP DISTRIBUTION: the same with Cycles; prints the seconds spent rendering
# (Blender's start-up and the glTF import not included).
render_cycles() {
  local total=0 s
  for seed in 1 2; do
    nice -n "$nice" blender -b --factory-startup -P "$here/cycles_render.py" -- "$2" "cycles-$1-$seed.exr" \
      $(($3 / 2)) "$width" "$height" --threads "$threads" --seed "$seed" --distribution "$4" \
      > "cycles-$1-$seed.log" 2>&1 || { tail -20 "cycles-$1-$seed.log" >&2; exit 1; }
    s=$(sed -n 's/^RENDER_SECONDS \([0-9.]*\).*/\1/p' "cycles-$1-$seed.log")
    total=$($py -c "print($total + $s)")
  done
  echo "$total"
}

{
  echo "$("$gilt" --version) ($gilt, sha256 $(sha256sum "$gilt" | cut -c1-12); checkout" \
       "$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')), $(blender --version | head -1);" \
       "${width}x${height}; gilt $spp_gilt spp, Cycles $spp_cycles spp (plane: an eighth, lone and glass-furnace*:" \
       "a quarter)," \
       "each as two halves; $threads threads"
  echo
  echo "| case | region | pixels | mean ratio gilt/Cycles R / G / B (±1σ noise) | relMSE | relMSE of noise alone |" \
       "pixel noise gilt / Cycles | seconds gilt / Cycles |"
  echo "|---|---|---|---|---|---|---|---|"
} > table.md
: > models.md

declare -A gilt_seconds
for case in $cases; do
  div=1 layout=()
  case $case in
    plane) scene=plane-scene.json dist=import div=8 ;;
    furnace) scene=furnace-scene.json dist=import layout=(--spheres furnace-layout.json) ;;
    lone) scene=lone-scene.json dist=import div=4 layout=(--spheres lone-layout.json) ;;
    spheres) scene=spheres-scene.json dist=import layout=(--spheres spheres-layout.json) ;;
    spheres-multiggx) scene=spheres-scene.json dist=MULTI_GGX layout=(--spheres spheres-layout.json) ;;
    glass) scene=glass-scene.json dist=GGX layout=(--spheres glass-layout.json) ;;
    glass-multiggx) scene=glass-scene.json dist=MULTI_GGX layout=(--spheres glass-layout.json) ;;
    glass-furnace) scene=glass-furnace-scene.json dist=GGX div=4 layout=(--spheres glass-furnace-layout.json) ;;
    glass-furnace-multiggx) scene=glass-furnace-scene.json dist=MULTI_GGX div=4
      layout=(--spheres glass-furnace-layout.json) ;;
    truck) scene=truck-scene.json dist=import layout=(--mask truck=truck-mask.exr)
      nice -n "$nice" blender -b --factory-startup -P "$here/cycles_render.py" -- truck-body-scene.json truck-mask.exr \
        16 "$width" "$height" --threads "$threads" > truck-mask.log 2>&1 || { tail -20 truck-mask.log >&2; exit 1; } ;;
    *) echo "compare.sh: unknown case $case" >&2; exit 1 ;;
  esac
  base=${scene%-scene.json}
  if [ -z "${gilt_seconds[$base]:-}" ]; then     # the gilt render does not depend on Cycles' variant
    echo "== $base: gilt, $((spp_gilt / div)) spp" >&2
    gilt_seconds[$base]=$(render_gilt "$base" "$scene" $((spp_gilt / div)))
  fi
  echo "== $case: Cycles ($dist), $((spp_cycles / div)) spp" >&2
  cycles_seconds=$(render_cycles "$case" "$scene" $((spp_cycles / div)) "$dist")
  $py "$here/compare.py" --label "$case" --wrapper "$scene" --gilt "gilt-$base-1.exr" "gilt-$base-2.exr" \
    --cycles "cycles-$case-1.exr" "cycles-$case-2.exr" "${layout[@]}" --out-png "$case.png" --json "$case.json" \
    --seconds-gilt "${gilt_seconds[$base]}" --seconds-cycles "$cycles_seconds" | tee -a table.md
done
grep -h "^MATERIAL\|^TEXTURE" cycles-*-1.log | sort -u > importer.txt

echo "== models (brdf_albedo.py, sphere_model.py)" >&2
ran() { [[ " $cases " == *" $1 "* ]]; }
if ran plane; then   # the Lambertian ground alone has a closed form: 0.5 (E cos / pi + L)
  $py - >> models.md <<'PY'
import json, math
s = json.load(open("plane-scene.json"))
sun = next(l for l in s["lights"] if l["type"] == "directional")
sky = next(l for l in s["lights"] if l["type"] == "environment")["radiance"]
d = sun["direction"]
exact = 0.5 * (sun["irradiance"] * -d[1] / math.sqrt(sum(x * x for x in d)) / math.pi + sky)
r = next(x for x in json.load(open("plane.json")) if x["region"] == "objects")
print("### plane: Lambertian ground, closed form %.5f\n" % exact)
print("| renderer | mean (R) | ±1σ | / closed form |\n|---|---|---|---|")
for who in ("gilt", "cycles"):
    m, s_ = r["mean_" + who][0], r["sigma_" + who][0]
    print("| %s | %.5f | %.5f | %.5f |" % (who, m, s_, m / exact))
print()
PY
fi
if ran furnace; then
  { echo "### furnace: spheres 2.5 units apart, no ground, predicted from the BRDF models"; echo
    $py "$here/sphere_model.py" furnace-scene.json furnace-layout.json "$width" "$height" GGX=furnace.json \
      --no-ground --absolute
    echo; } >> models.md
fi
if ran lone; then
  { echo "### lone: the rough metal sphere alone on the ground"; echo
    $py "$here/sphere_model.py" lone-scene.json lone-layout.json "$width" "$height" GGX=lone.json
    echo; } >> models.md
fi
if ran spheres; then
  multi=(); ran spheres-multiggx && multi=(MULTI_GGX=spheres-multiggx.json)
  { echo "### spheres: the grid on the ground, predicted ratios from the BRDF models"; echo
    $py "$here/sphere_model.py" spheres-scene.json spheres-layout.json "$width" "$height" GGX=spheres.json \
      "${multi[@]}"
    echo; } >> models.md
fi
if ran glass-furnace || ran glass-furnace-multiggx; then   # a sphere's radiance over the sky's: energy kept
  { echo "### glass-furnace: each glass sphere's mean radiance / the sky's (1 for energy-conserving glass)"; echo
    $py - glass-furnace.json glass-furnace-multiggx.json <<'PY'
import json, os, sys
runs = [(f, json.load(open(f))) for f in sys.argv[1:] if os.path.exists(f)]
sky = next(l for l in json.load(open("glass-furnace-scene.json"))["lights"] if l["type"] == "environment")["radiance"]
heads = ["gilt"] + ["Cycles " + ("MULTI_GGX" if "multiggx" in f else "GGX") for f, _ in runs]
print("| sphere | " + " | ".join(heads) + " |\n|---|" + "---|" * len(heads))
for i, r in enumerate(runs[0][1]):
    if not r["region"].startswith("glass"):
        continue
    cells = ["%.4f ± %.4f" % (r["mean_gilt"][1] / sky, r["sigma_gilt"][1] / sky)]
    cells += ["%.4f ± %.4f" % (x[i]["mean_cycles"][1] / sky, x[i]["sigma_cycles"][1] / sky) for _, x in runs]
    print("| %s | %s |" % (r["region"], " | ".join(cells)))
print()
PY
  } >> models.md
fi
if ran glass || ran glass-multiggx || ran glass-furnace || ran glass-furnace-multiggx; then
  furnace=()   # with a furnace case, also trace perfect spheres through both models
  if ran glass-furnace || ran glass-furnace-multiggx; then
    furnace=(--furnace glass-furnace-scene.json glass-furnace-layout.json "$width" "$height")
  fi
  { echo "### one rough glass interface: reflected and transmitted energy in the two models (no renderer)"; echo
    $py "$here/glass_albedo.py" "${furnace[@]}"; echo; } >> models.md
fi
{ echo "### directional albedo of the two BRDF models (no renderer)"; echo
  $py "$here/brdf_albedo.py"; } >> models.md
{ cat table.md; echo; cat models.md; echo; echo "wall time of the whole run: $(( $(date +%s) - start )) s"; } > results.md
echo "wrote $out/results.md and $out/*.png; $(( $(date +%s) - start )) s" >&2
