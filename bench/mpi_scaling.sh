#!/usr/bin/env bash
# The MPI mode's measurements (docs/mpi.md): a benchmark, never run by the tests.
#   1. efficiency of 1, 2 and 4 ranks with one thread each: T_R is the distributed phase (stats "mpi".
#      distribute_s: every tile's primary and shadow rays on all ranks until rank 0 has them all; loading and
#      the BVH build are every rank's and not divided), efficiency = T_1 / (R T_R); also the whole command's
#      wall time (mpirun's start-up, loading, building, writing included);
#   2. the schedules (queue, counter, static) on the same frame with CHUNK tiles a hand-out (default 1): the
#      distributed phase and the busiest rank's rendering seconds over the mean (1 = perfect balance);
#   and for each, the CPU seconds of the whole command (user + system of mpirun and the ranks): on a shared
#   machine the ranks' wall times say how much of it they got, the CPU seconds what the work cost.
# Runs alternate between the configurations, ROUNDS rounds; the median of each is printed (the machine may
# be shared). usage: bench/mpi_scaling.sh BUILD_DIR SCENE.json [W H SAMPLES ROUNDS CHUNK]
set -euo pipefail
build=${1:?usage: mpi_scaling.sh BUILD_DIR SCENE.json [W H SAMPLES ROUNDS CHUNK]} scene=${2:?}
W=${3:-256} H=${4:-256} N=${5:-1024} rounds=${6:-3} chunk=${7:-1}
ms=$build/microshadow
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
one() {   # one RANKS SCHEDULE TAG: appends "distribute_s busy_max_over_mean wall_s cpu_s" to $tmp/TAG
    local r=$1 sched=$2 tag=$3 t0 t1
    t0=$(date +%s.%N)
    /usr/bin/time -f "%U %S" -o "$tmp/cpu" mpirun --quiet --oversubscribe -n "$r" "$ms" "$scene" --width "$W" \
        --height "$H" --samples "$N" --threads 1 --quiet --mpi-schedule "$sched" --mpi-chunk "$chunk" -o "$tmp/o.png" \
        --stats "$tmp/s.json"
    t1=$(date +%s.%N)
    python3 -c "import json,sys; m=json.load(open('$tmp/s.json'))['mpi']; u,s=open('$tmp/cpu').read().split()[-2:]; print(m['distribute_s'], m['busy_max_over_mean'], $t1-$t0, float(u)+float(s))" >> "$tmp/$tag"
}
median() { sort -n -k"$2" "$1" | awk -v k="$2" '{ a[NR] = $k } END { print a[int((NR + 1) / 2)] }'; }
configs=("1 queue" "2 queue" "4 queue" "2 counter" "4 counter" "2 static" "4 static")
for ((i = 0; i < rounds; i++)); do
    for c in "${configs[@]}"; do set -- $c; one "$1" "$2" "$1-$2"; done
done
echo "scene $scene, ${W}x${H}, $N samples, one thread per rank, $chunk tiles a hand-out, $rounds rounds (median), $(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg)"
t1=$(median "$tmp/1-queue" 1)
printf "%-6s %-8s %12s %10s %14s %10s %8s\n" ranks schedule distribute_s efficiency busy_max/mean command_s cpu_s
for c in "${configs[@]}"; do
    set -- $c
    d=$(median "$tmp/$1-$2" 1) b=$(median "$tmp/$1-$2" 2) w=$(median "$tmp/$1-$2" 3) c=$(median "$tmp/$1-$2" 4)
    printf "%-6s %-8s %12.3f %10.2f %14.3f %10.2f %8.2f\n" "$1" "$2" "$d" "$(echo "$t1 / ($1 * $d)" | bc -l)" "$b" "$w" "$c"
done
