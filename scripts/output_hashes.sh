#!/usr/bin/env bash
# Prints a SHA-256 for each of a fixed set of gilt outputs (exports, onto-input models, a lightmap,
# one image per method), all untimed and seeded, so that a change meant to move code and not
# behaviour can be checked byte for byte: run it before and after and diff the two listings.
#   bash scripts/output_hashes.sh BUILD_DIR > before.txt    # then again after, and: diff before.txt after.txt
# Takes about 20 s on 2 cores. Needs ../shared beside the project for the public scenes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
gilt="$build/cli/gilt"
shared="$root/../shared/scenes"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { "$gilt" "$@" -q > /dev/null 2>> "$out/warnings.txt" || { cat "$out/warnings.txt" >&2; exit 1; }; }

# Radiosity exports: both solvers, every format, each quantity.
run radiosity cornell -o "$out/cornell-progressive.ply" --solver progressive --elements 1500
run radiosity cornell -o "$out/cornell-progressive.obj" --solver progressive --elements 1500 --quantity irradiance
run radiosity cornell -o "$out/cornell-hierarchical.glb" --solver hierarchical --elements 3000 --final-gather on
run radiosity cornell -o "$out/cornell-hierarchical.ply" --solver hierarchical --elements 3000 --final-gather off \
    --linear-float --quantity radiosity
run radiosity cornell -o "$out/cornell-gather.ply" --elements 1200 --bake-gather 16
# Onto the input model, and a lightmap, on public scenes under sun and sky.
run radiosity "$shared/winding/atrium-outward.json" -o "$out/winding-outward.ply" --elements 2000
run radiosity "$shared/wrap/atten-lit.json" -o "$out/atten-onto.glb" --onto input --elements 2000
run radiosity "$shared/wrap/truck-lit.json" -o "$out/truck-lightmap.glb" --lightmap 128 --elements 2000
run radiosity "$shared/wrap/bunny-lit.json" -o "$out/bunny-onto.ply" --onto input --elements 3000 --fit point
run radiosity "$shared/wrap/bunny-lit.json" -o "$out/bunny-sun.ply" --elements 3000 --sun 60,30,3 --sky 3
# One image per method.
run render cornell -o "$out/path.exr" --method path --spp 8 --width 64 --height 48
run render cornell -o "$out/whitted.exr" --method whitted --spp 2 --width 64 --height 48
run render cornell -o "$out/photon.exr" --method photon --spp 2 --width 64 --height 48 --photons 20000
run render cornell -o "$out/sppm.exr" --method sppm --spp 4 --width 64 --height 48 --photons 20000
run render cornell -o "$out/radiosity-two-pass.exr" --method radiosity --spp 2 --width 64 --height 48 --elements 1500
run render cornell -o "$out/radiosity-mesh.exr" --method radiosity --radiosity-view mesh --spp 1 --width 64 \
    --height 48 --elements 1500
"$gilt" info cornell | grep -v "took" > "$out/info-cornell.txt"

cd "$out" && find . -type f -not -name '*.bin' -not -name warnings.txt | sort | xargs sha256sum
