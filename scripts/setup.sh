#!/usr/bin/env bash
# gilt set-up on Debian 12: installs what is missing, builds, then runs one job.
#   bash scripts/setup.sh demo   install, build, compare every method on the built-in cornell-caustics
#                                scene: the report is out/compare/index.html (about 4 minutes)
#   bash scripts/setup.sh test   install, build with warnings as errors, run the whole test suite
#                                (the clients label opens exports in headless Blender),
#                                then build the unit tests with AddressSanitizer + UBSan and run them
#                                (what CI runs; SANITIZE=0 skips the sanitizer stage), then
#                                fuzzes every scene loader for 10 s with clang's libFuzzer
#                                (scripts/fuzz.sh; FUZZ=0 skips it)
#   bash scripts/setup.sh build  install and build only (the gilt tool and the Python module)
#   bash scripts/setup.sh python install, build, then install the module `gilt` for the system's
#                                python3 (/usr/bin/python3): `python3 -c "import gilt"`
# Environment: BUILD_DIR (default build), JOBS (default: number of cores).
set -euo pipefail

job=${1:-demo}
# Each stage says how long it took, so a slow CI run shows where its time went.
stage_start=$SECONDS
stage_done() {
  echo "setup: $1 took $((SECONDS - stage_start)) s"
  stage_start=$SECONDS
}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
jobs=${JOBS:-$(nproc)}

packages=(
  cmake g++ ninja-build pkg-config
  libglm-dev libembree-dev libtbb-dev libopenimageio-dev
  libcgal-dev libeigen3-dev libgmp-dev libmpfr-dev libboost-dev libopenmesh-dev libflann-dev liblz4-dev
  nlohmann-json3-dev libcli11-dev libtinyobjloader-dev libtinygltf-dev libdraco-dev libstb-dev
  libgtest-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy
)
# The report test looks at index.html in a real browser; the clients tests open gilt's exports in
# headless Blender (scripts/blender_check.py, which needs Blender's numpy).
# The Python module's tests run under Debian's pytest and read the tool's images with
# OpenImageIO's bindings.
[ "$job" = test ] && packages+=(chromium blender python3-pytest python3-openimageio)
# CI builds the tool with MPI and runs the mpi label (mpirun -np 2 against one process).
[ "$job" = test ] && packages+=(libopenmpi-dev openmpi-bin)
# The glTF tests run the Khronos glTF-Validator, an npm package (scripts/gltf_validate.js).
if [ "$job" = test ] && ! command -v npm >/dev/null; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
stage_done "installing packages"

extra=()
[ "$job" = test ] && extra+=(-DGILT_WERROR=ON -DGILT_MPI=ON)
# The module is built for the system's interpreter, whatever python3 comes first on the PATH.
[ -x /usr/bin/python3 ] && extra+=(-DPython3_EXECUTABLE=/usr/bin/python3)
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${extra[@]}" ${CMAKE_ARGS:-}
# The demo runs the gilt tool alone: it builds that target and what it links, not the tests,
# benchmarks and Python module (on a fresh 2-core machine those were 6.5 of its 11 minutes).
targets=()
[ "$job" = demo ] && targets+=(--target gilt)
cmake --build "$build_dir" -j "$jobs" "${targets[@]}"
stage_done "the release build"

case "$job" in
  demo)
    mkdir -p "$root/out"
    "$build_dir/cli/gilt" compare cornell-caustics -o "$root/out/compare"
    echo "setup: open $root/out/compare/index.html"
    ;;
  test)
    export GILT_REQUIRE_CHROMIUM=1
    # The validator goes into the build folder; without it (no npm registry) its test is skipped.
    if [ ! -d "$build_dir/gltf-validator/node_modules/gltf-validator" ]; then
      npm install --silent --no-audit --no-fund --prefix "$build_dir/gltf-validator" gltf-validator ||
        echo "setup: could not install gltf-validator from npm; the glTF validation test will be skipped"
    fi
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    stage_done "the test suite"
    if [ "${SANITIZE:-1}" != 0 ]; then
      # The fast label again, under AddressSanitizer and UndefinedBehaviorSanitizer.
      # -O1 -g1, not RelWithDebInfo's -O2 -g: under both sanitizers GCC took 9 minutes over the
      # CGAL repair file alone at -O2 -g, and 2.6 times longer than -O1 -g1 over a loader; -g1
      # keeps the file and line of every frame in a sanitizer's stack trace.
      asan_dir=${build_dir}-asan
      cmake -S "$root" -B "$asan_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
        -DGILT_SANITIZE=ON -DGILT_BUILD_BENCH=OFF -DGILT_PYTHON=OFF ${CMAKE_ARGS:-}
      # Only what the unit label runs: the CLI (its tests call it) and the unit test programs.
      unit_targets=(gilt)
      for t in "$root"/tests/unit/test_*.cpp; do unit_targets+=("$(basename "$t" .cpp)"); done
      cmake --build "$asan_dir" -j "$jobs" --target "${unit_targets[@]}"
      stage_done "the sanitizer build"
      # new_delete_type_mismatch=0: OpenImageIO 2.4's TextureSystem::destroy deletes its 184-byte
      # implementation through a pointer to the 1-byte interface (its bug, not gilt's).
      UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1:new_delete_type_mismatch=0 \
        LSAN_OPTIONS=suppressions=$root/tests/lsan.supp \
        ctest --test-dir "$asan_dir" --output-on-failure -j "$jobs" -L unit
      stage_done "the unit label under the sanitizers"
    fi
    if [ "${FUZZ:-1}" != 0 ]; then
      # A short libFuzzer run of every scene loader (longer runs: bash scripts/fuzz.sh 600).
      JOBS=$jobs bash "$root/scripts/fuzz.sh" 10
      stage_done "fuzzing (build and runs)"
    fi
    ;;
  build) ;;
  python)
    cmake --install "$build_dir" --component python
    echo "setup: installed the module gilt for /usr/bin/python3"
    ;;
  *)
    echo "setup: unknown job '$job' (expected demo, test, build or python)" >&2
    exit 2
    ;;
esac
