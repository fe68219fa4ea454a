#!/usr/bin/env bash
# Speed-up of `mpirun -np N gilt render` at 1, 2 and 4 ranks of one thread each, against one
# process of one thread, on the path tracer (cornell) and SPPM (cornell-caustics). Every image is
# checked to be the one-process image, bit for bit, before its time counts. Medians of REPEATS
# interleaved runs (default 3). Needs a build with -DGILT_MPI=ON. Figures in bench/README.md.
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
)
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for job in path sppm; do
  "$gilt" ${jobs[$job]} --threads 1 -q -o "$out/$job-ref.exr" > /dev/null
  for ((i = 0; i < repeats; ++i)); do
    for ranks in 1 2 4; do
      start=$(date +%s.%N)
      mpirun -np "$ranks" --oversubscribe "$gilt" ${jobs[$job]} --threads 1 -q -o "$out/$job-$ranks.exr" > /dev/null
      end=$(date +%s.%N)
      cmp -s "$out/$job-ref.exr" "$out/$job-$ranks.exr" || { echo "$job at $ranks ranks: not the one-process image" >&2; exit 1; }
      echo "$end - $start" | bc >> "$out/$job-$ranks.times"
    done
  done
  one=$(median < "$out/$job-1.times")
  for ranks in 1 2 4; do
    t=$(median < "$out/$job-$ranks.times")
    printf '%-5s %d rank(s): %6.2f s  speed-up %.2f\n' "$job" "$ranks" "$t" "$(echo "$one / $t" | bc -l)"
  done
done
