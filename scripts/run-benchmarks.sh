#!/usr/bin/env bash
# Builds the Google Benchmark programs, runs them, and prints the ray core's throughput next to
# raw Embree's on the same rays, the path tracer's samples/s, and the radiosity solver's error
# against time, form factors/s and solve cost at 1k/10k/100k elements. Figures are medians of
# REPETITIONS runs whose order is shuffled, so that a slow spell of the machine does not land on
# one side of a comparison only. See bench/README.md for how to read them.
#
#   bash scripts/run-benchmarks.sh [extra Google Benchmark flags, e.g. --benchmark_min_time=0.1]
#
# Exits 1 when the core keeps less than MIN_RATIO of raw Embree's single-thread throughput for
# any ray kind. Environment: BUILD_DIR (default build), OUT_DIR (default out/bench),
# REPETITIONS (default 5), MIN_RATIO (default 0.90), JOBS (default: number of cores),
# RADIOSITY (default 1; 0 skips bench_radiosity, which takes two to three minutes on two cores),
# PHOTON (default 1; 0 skips bench_photon_index and bench_photon: the index at one million
# photons, photon tracing rate, kd-tree against hash grid, and the race of photon, sppm and path
# on cornell-caustics, about three minutes plus a minute for its reference the first time).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build_dir=${BUILD_DIR:-$root/build}
out_dir=${OUT_DIR:-$root/out/bench}
repetitions=${REPETITIONS:-5}
min_ratio=${MIN_RATIO:-0.90}
jobs=${JOBS:-$(nproc)}
radiosity=${RADIOSITY:-1}
photon=${PHOTON:-1}

# Timings only mean something in an optimised build.
cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGILT_BUILD_BENCH=ON
cmake --build "$build_dir" --target bench -j "$jobs"

mkdir -p "$out_dir"
flags=(
  --benchmark_repetitions="$repetitions"
  --benchmark_report_aggregates_only=true
  --benchmark_enable_random_interleaving=true
  --benchmark_out_format=json
)
echo
"$build_dir/bench/bench_raycore" "${flags[@]}" --benchmark_out="$out_dir/raycore.json" "$@"
echo
"$build_dir/bench/bench_path" "${flags[@]}" --benchmark_out="$out_dir/path.json" "$@"
echo
if [[ $radiosity != 0 ]]; then
  # Its sweep and scaling parts are not Google Benchmarks: they write CSV files to out_dir (where
  # the path-traced references are cached too) and ignore the repetitions.
  "$build_dir/bench/bench_radiosity" "${flags[@]}" --benchmark_out="$out_dir/radiosity.json" \
    --out-dir="$out_dir" "$@"
  echo
fi

if [[ $photon != 0 ]]; then
  "$build_dir/bench/bench_photon_index" "${flags[@]}" --benchmark_out="$out_dir/photon_index.json" "$@"
  echo
  # Not Google Benchmarks: prints its figures and writes photon_race.csv to out_dir.
  "$build_dir/bench/bench_photon" --out-dir="$out_dir"
  echo
fi

python3 - "$out_dir/raycore.json" "$out_dir/path.json" "$min_ratio" "$radiosity" "$out_dir" <<'PYTHON'
import csv
import json
import os
import sys

raycore_path, path_path, min_ratio = sys.argv[1], sys.argv[2], float(sys.argv[3])
radiosity, out_dir = sys.argv[4] != "0", sys.argv[5]


def load(path):
    """Context and {run_name: {aggregate_name: entry}} of one Google Benchmark JSON file."""
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for entry in data["benchmarks"]:
        if entry.get("run_type") == "aggregate":
            runs.setdefault(entry["run_name"], {})[entry["aggregate_name"]] = entry
    return data["context"], runs


def median(runs, name, counter):
    if name not in runs:
        sys.exit(f"run-benchmarks: {name} is missing from the results (was it filtered out?)")
    return runs[name]["median"][counter]


def spread(runs, name, counter):
    """Coefficient of variation over the repetitions, in percent."""
    cv = runs[name].get("cv")
    return 100.0 * cv[counter] if cv else float("nan")


context, rays = load(raycore_path)
path_context, paths = load(path_path)
repetitions = next(iter(rays.values()))["median"]["repetitions"]

print(f"Ray core vs raw Embree: {int(context['triangles']):,} triangles, "
      f"{int(context['primary_rays']):,} rays per kind "
      f"({float(context['shadow_blocked_percent']):.1f} % of the shadow rays blocked); "
      f"median of {repetitions} runs, cv = spread over the runs")
failures = []
for threads, suffix in ((1, ""), (2, "/threads:2/real_time")):
    gated = threads == 1
    title = "1 thread (CPU time)" if gated else "2 threads (wall time; informational, not gated)"
    print(f"\n  {title}")
    print(f"  {'rays':<8} {'core Mrays/s':>13} {'cv':>6} {'Embree Mrays/s':>15} {'cv':>6} {'core/Embree':>12}")
    for kind in ("Primary", "Shadow", "Diffuse"):
        core_name, raw_name = f"BM_Core_{kind}{suffix}", f"BM_Embree_{kind}{suffix}"
        core, raw = median(rays, core_name, "rays"), median(rays, raw_name, "rays")
        ratio = core / raw
        flag = ""
        if gated and ratio < min_ratio:
            flag = f"  < {min_ratio:.2f}"
            failures.append(f"{kind.lower()} rays: the core reaches {ratio:.3f} of raw Embree")
        print(f"  {kind.lower():<8} {core / 1e6:>13.3f} {spread(rays, core_name, 'rays'):>5.1f}% "
              f"{raw / 1e6:>15.3f} {spread(rays, raw_name, 'rays'):>5.1f}% {ratio:>12.3f}{flag}")

print(f"\nPath tracer: {path_context['scene']} at {path_context['image']}, "
      f"{path_context['spp_per_iteration']} spp per render; median of {repetitions} runs, wall time")
print(f"  {'threads':<8} {'samples/s':>12} {'cv':>6} {'Mrays/s':>9}")
for threads in (1, 2):
    name = f"BM_PathTracer_Cornell/threads:{threads}/real_time"
    print(f"  {threads:<8} {median(paths, name, 'samples'):>12,.0f} {spread(paths, name, 'samples'):>5.1f}% "
          f"{median(paths, name, 'rays') / 1e6:>9.3f}")

if radiosity:
    _, ff = load(os.path.join(out_dir, "radiosity.json"))
    print(f"\nForm factors (point_to_triangle_form_factor, 1 thread, CPU time); median of {repetitions} runs")
    print(f"  {'configurations':<16} {'M/s':>7} {'cv':>6}")
    for kind in ("Random", "Cornell"):
        name = f"BM_FormFactor_{kind}"
        print(f"  {kind.lower():<16} {median(ff, name, 'form_factors') / 1e6:>7.2f} "
              f"{spread(ff, name, 'form_factors'):>5.1f}%")

    with open(os.path.join(out_dir, "radiosity_sweep.csv")) as f:
        sweep = list(csv.DictReader(f))
    first = sweep[0]
    print(f"\nRadiosity error against time on cornell (one run, wall time, all cores); reference "
          f"{first['reference_spp']} spp, its noise {100 * float(first['reference_noise_centres']):.2f} % "
          f"(centres) / {100 * float(first['reference_noise_filtered']):.2f} % (filtered); "
          f"16-spp display noise {100 * float(first['display_noise_16spp']):.2f} %")
    print(f"  {'elements':>8} {'vertices':>8} {'shots':>7} {'seconds':>8} {'16-spp %':>9} {'centre %':>9} "
          f"{'less noise %':>12}")
    for row in sweep:
        print(f"  {int(row['elements']):>8} {int(row['vertices']):>8} {int(row['shots']):>7} "
              f"{float(row['seconds']):>8.2f} {100 * float(row['error_16spp']):>9.3f} "
              f"{100 * float(row['error_centres']):>9.3f} {100 * float(row['error_centres_less_noise']):>12.3f}")

    with open(os.path.join(out_dir, "radiosity_scaling.csv")) as f:
        scaling = list(csv.DictReader(f))
    print("\nRadiosity solve cost on cornell (one run, wall time, all cores)")
    print(f"  {'elements':>8} {'vertices':>8} {'mesh s':>7} {'shots':>7} {'shots/s':>8} {'MFF/s':>6} "
          f"{'Mrays/s':>8} {'no rays %':>9} {'residual':>9}  stopped by")
    for row in scaling:
        print(f"  {int(row['elements']):>8} {int(row['vertices']):>8} {float(row['mesh_seconds']):>7.2f} "
              f"{int(row['shots']):>7} {float(row['shots_per_second']):>8.1f} "
              f"{float(row['form_factors_per_second']) / 1e6:>6.2f} {float(row['shadow_rays_per_second']) / 1e6:>8.2f} "
              f"{100 * float(row['pairs_without_rays']):>9.1f} {float(row['residual']):>9.2e}  "
              f"{'time limit' if row['hit_time_limit'] == '1' else 'tolerance'}")

if failures:
    print(f"\nrun-benchmarks: FAILED: the core keeps less than {min_ratio:.0%} of raw Embree's throughput:")
    for failure in failures:
        print(f"  {failure}")
    sys.exit(1)
print(f"\nrun-benchmarks: the core keeps at least {min_ratio:.0%} of raw Embree's throughput for every ray kind")
PYTHON
