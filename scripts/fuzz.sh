#!/usr/bin/env bash
# Fuzzes every scene loader with libFuzzer (Debian's clang, AddressSanitizer + UBSan).
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET]    default 30 seconds per target
# Installs clang and its runtime if missing, builds the fuzz targets in build-fuzz/ (BUILD_DIR
# overrides), then runs fuzz_obj, fuzz_gltf, fuzz_glb, fuzz_ply and fuzz_json in turn, each from
# its seed corpus (tests/fuzz/corpus/<format>/). New interesting inputs go to
# build-fuzz/fuzz-corpus/<format>/ and crashing inputs to build-fuzz/fuzz-artifacts/; the script
# fails when any target found one. Environment: JOBS (build jobs, default 1), TARGETS (subset,
# e.g. "obj ply").
set -euo pipefail

seconds=${1:-30}
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "fuzz.sh: SECONDS_PER_TARGET must be a positive whole number, got '$seconds'" >&2
  exit 2
fi
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build-fuzz}
jobs=${JOBS:-1}
targets=${TARGETS:-"obj gltf glb ply json"}

missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "fuzz.sh: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# -O1 with line tables only, as libFuzzer's documentation builds its targets: the sanitizers make
# -O2 -g builds several times slower to compile, and a stack trace needs only files and lines.
CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DGILT_FUZZ=ON -DGILT_BUILD_BENCH=OFF -DGILT_WERROR=OFF -DGILT_PYTHON=OFF >/dev/null
fuzzers=()
for t in $targets; do fuzzers+=("fuzz_$t"); done
cmake --build "$build_dir" -j "$jobs" --target "${fuzzers[@]}"

# Third-party leaks by design (OpenMesh, OpenImageIO): see tests/lsan.supp.
export LSAN_OPTIONS="suppressions=$root/tests/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# new_delete_type_mismatch=0, as in the sanitizer stage of scripts/setup.sh: OpenImageIO 2.4's
# TextureSystem::destroy deletes its 184-byte implementation through a pointer to the 1-byte
# interface (its bug, not gilt's). An OBJ whose MTL names a file that is not an image reaches it:
# TextureSet throws InputError and its TextureSystem is destroyed.
export ASAN_OPTIONS="new_delete_type_mismatch=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
artifacts="$build_dir/fuzz-artifacts"
mkdir -p "$artifacts"
failed=()
for t in $targets; do
  corpus="$build_dir/fuzz-corpus/$t"
  mkdir -p "$corpus"
  echo "fuzz.sh: fuzz_$t for ${seconds} s"
  if ! "$build_dir/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$artifacts/fuzz_$t-" "$corpus" "$root/tests/fuzz/corpus/$t" \
      2>"$build_dir/fuzz_$t.log"; then
    failed+=("fuzz_$t")
    grep -E "^==[0-9]+==ERROR|SUMMARY|Test unit written|uncaught|terminate" "$build_dir/fuzz_$t.log" | head -20 >&2 || true
  fi
  grep -E "^stat::number_of_executed_units|^stat::new_units_added" "$build_dir/fuzz_$t.log" | sed "s/^/  /" || true
done
if ((${#failed[@]})); then
  echo "fuzz.sh: FAILED: ${failed[*]} (logs: $build_dir/fuzz_<format>.log; inputs: $artifacts/)" >&2
  exit 1
fi
echo "fuzz.sh: no crash in ${targets// /, } at ${seconds} s each"
