#!/usr/bin/env bash
# Speed-up of `mpirun -np N gilt render|radiosity` at 1, 2 and 4 ranks of one thread each, against
# one process of one thread, on the path tracer (cornell), SPPM (cornell-caustics) and the
# hierarchical radiosity solve (cornell at 10,000 elements); one process of two threads beside
# them. Every image and export is checked to be the one-process file, bit for bit, before its time
# counts. Medians of REPEATS interleaved runs (default 3). Needs a build with -DGILT_MPI=ON.
# Figures in bench/README.md.
#   bench/mpi_speedup.sh [REPEATS]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
gilt=$here/build/cli/gilt
repeats=${1:-3}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
declare -A jobs=(
  [path]="render cornell --method path --spp 64 --width 256 --height 256"
  [sppm]="render cornell-caustics --method sppm --spp 32 --width 256 --height 256 --photons 100000"
  [radiosity]="radiosity cornell --solver hierarchical --elements 10000"
)
declare -A ext=([path]=exr [sppm]=exr [radiosity]=ply)
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for job in path sppm radiosity; do
  e=${ext[$job]}
  quiet=-q
  [ "$job" = radiosity ] && quiet=
  "$gilt" ${jobs[$job]} --threads 1 $quiet -o "$out/$job-ref.$e" > /dev/null
  for ((i = 0; i < repeats; ++i)); do
    for ranks in 1 2 4; do
      start=$(date +%s.%N)
      mpirun -np "$ranks" --oversubscribe "$gilt" ${jobs[$job]} --threads 1 $quiet -o "$out/$job-$ranks.$e" > /dev/null
      end=$(date +%s.%N)
      cmp -s "$out/$job-ref.$e" "$out/$job-$ranks.$e" || { echo "$job at $ranks ranks: not the one-process output" >&2; exit 1; }
      echo "$end - $start" | bc >> "$out/$job-$ranks.times"
    done
    start=$(date +%s.%N)
    "$gilt" ${jobs[$job]} --threads 2 $quiet -o "$out/$job-threads.$e" > /dev/null
    end=$(date +%s.%N)
    cmp -s "$out/$job-ref.$e" "$out/$job-threads.$e" || { echo "$job at 2 threads: not the one-thread output" >&2; exit 1; }
    echo "$end - $start" | bc >> "$out/$job-threads.times"
  done
  one=$(median < "$out/$job-1.times")
  for ranks in 1 2 4; do
    t=$(median < "$out/$job-$ranks.times")
    printf '%-9s %d rank(s): %6.2f s  speed-up %.2f\n' "$job" "$ranks" "$t" "$(echo "$one / $t" | bc -l)"
  done
  t=$(median < "$out/$job-threads.times")
  printf '%-9s 1 process, 2 threads: %6.2f s  speed-up %.2f\n' "$job" "$t" "$(echo "$one / $t" | bc -l)"
done
