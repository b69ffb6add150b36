#!/usr/bin/env bash
# Fuzzing at scale: every libFuzzer harness of tests/fuzz for M minutes, J at a time, then
#   - new coverage merged into tests/fuzz/corpus/<t>/ (libFuzzer -merge=1: only inputs that add coverage,
#     named by their SHA-1),
#   - every finding (crash, abort, leak, timeout, out of memory) copied into tests/fuzz/crashes/<t>/, where
#     test_fuzz_inputs replays it (and fails until it is fixed),
#   - per harness: executions, coverage (cov: edges, ft: features, from libFuzzer's last status line) and
#     findings, also written to FUZZ_WORK/summary.txt.
# Harnesses are found, not listed: every tests/fuzz/corpus/<t>/ with an executable BUILD/tests/fuzz/fuzz_<t>
# (a corpus without its harness, or a harness without a corpus, is an error).
#
#   scripts/fuzz.sh [--minutes M] [--jobs J] [--build DIR] [--configure] [--only t1,t2,...] [--no-merge]
#
# --minutes: per harness (default 10); --jobs: harnesses fuzzed at once (default: the number of cores);
# --build: the clang -DMS_FUZZ=ON build (default build-clang); --configure: configure and build it first (as
# .ci/run does); --only: these harnesses; --no-merge: leave tests/fuzz untouched (findings stay in the work
# folder). A harness that finds something is restarted for the rest of its time (a plain libFuzzer run stops
# at its first finding); the findings of its earlier runs are not in its corpus, so it does not stop there
# again. Work folder: FUZZ_WORK (default BUILD/fuzz-campaign).
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=10 jobs=$(nproc) build=build-clang configure=0 only="" merge=1
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --configure) configure=1; shift ;;
    --only) only=$2; shift 2 ;;
    --no-merge) merge=0; shift ;;
    -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fuzz.sh: unknown argument '$1' (--help)" >&2; exit 2 ;;
  esac
done
case "$minutes" in ''|*[!0-9.]*) echo "fuzz.sh: --minutes wants a number" >&2; exit 2 ;; esac
case "$jobs" in ''|*[!0-9]*|0) echo "fuzz.sh: --jobs wants a positive integer" >&2; exit 2 ;; esac

if [ $configure = 1 ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMS_FUZZ=ON -DMS_WERROR=ON
  cmake --build "$build" -j "$jobs"
fi

# The harnesses: corpus folders with their executables.
harnesses=()
for d in tests/fuzz/corpus/*/; do
  t=$(basename "$d")
  if [ ! -x "$build/tests/fuzz/fuzz_$t" ]; then
    echo "fuzz.sh: tests/fuzz/corpus/$t has no harness $build/tests/fuzz/fuzz_$t (build with -DMS_FUZZ=ON, or --configure)" >&2
    exit 2
  fi
  harnesses+=("$t")
done
for exe in "$build"/tests/fuzz/fuzz_*; do
  [ -x "$exe" ] || continue
  t=${exe##*/fuzz_}
  [ -d "tests/fuzz/corpus/$t" ] || { echo "fuzz.sh: $exe has no seeds in tests/fuzz/corpus/$t" >&2; exit 2; }
done
if [ -n "$only" ]; then
  sel=()
  for t in ${only//,/ }; do
    [ -d "tests/fuzz/corpus/$t" ] || { echo "fuzz.sh: no harness '$t'" >&2; exit 2; }
    sel+=("$t")
  done
  harnesses=("${sel[@]}")
fi

work=${FUZZ_WORK:-$build/fuzz-campaign}
mkdir -p "$work"
secs=$(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')
common=(-timeout=10 -rss_limit_mb=2048 -max_len=65536)

dict_of() {   # libFuzzer dictionaries where the project has one
  case "$1" in gltf) [ -f third_party/cgltf/fuzz/gltf.dict ] && echo "-dict=third_party/cgltf/fuzz/gltf.dict" ;; esac
  [ -f "tests/fuzz/$1.dict" ] && echo "-dict=tests/fuzz/$1.dict"
  return 0
}

# One harness for secs seconds, restarted after each finding; its log and findings in work/<t>/.
run_one() {
  local t=$1 exe="$build/tests/fuzz/fuzz_$1" w="$work/$1" start end left run=0
  rm -rf "$w"
  mkdir -p "$w/new" "$w/findings" "$w/kept"
  # the kept crash inputs, but those known to fail still (tests/fuzz/known_failing.txt): a run would stop there
  for f in tests/fuzz/crashes/$t/*; do
    [ -f "$f" ] || continue
    grep -q "^crashes/$t/${f##*/}[[:space:]]" tests/fuzz/known_failing.txt 2>/dev/null || cp "$f" "$w/kept/"
  done
  start=$(date +%s)
  end=$((start + secs))
  mapfile -t dict < <(dict_of "$t")
  while :; do
    left=$((end - $(date +%s)))
    [ $left -ge 5 ] || break
    run=$((run + 1))
    "$exe" -max_total_time=$left "${common[@]}" "${dict[@]}" -print_final_stats=1 \
      -artifact_prefix="$w/findings/" "$w/new" "tests/fuzz/corpus/$t" "$w/kept" \
      > "$w/run$run.log" 2>&1 || true
    # a clean end of the time budget: done; a finding: go on with the rest of the time
    grep -q '^Done [0-9]* runs' "$w/run$run.log" && ! grep -q 'Test unit written to' "$w/run$run.log" && break
  done
  echo "$run" > "$w/runs"
}

echo "fuzz.sh: ${#harnesses[@]} harnesses (${harnesses[*]}), $minutes min each, $jobs at a time, work in $work"
t0=$(date +%s)
running=0
for t in "${harnesses[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ $running -ge "$jobs" ]; then wait -n || true; running=$((running - 1)); fi
done
wait || true
t1=$(date +%s)

# Per harness: executions (summed over its runs), cov and ft of its last status line, findings.
summary="$work/summary.txt"
{
  printf '%-8s %12s %9s %8s %8s %9s %s\n' harness executions budget_s cov ft corpus+ findings
  for t in "${harnesses[@]}"; do
    w="$work/$t"
    execs=$(cat "$w"/run*.log 2>/dev/null | awk '/^stat::number_of_executed_units:/ { s += $2 } END { print s + 0 }')
    # runs that ended in a finding print no final stats: their last "#N" status line counts instead
    for f in "$w"/run*.log; do
      [ -f "$f" ] || continue
      grep -q '^stat::number_of_executed_units' "$f" && continue
      n=$(grep -o '^#[0-9]*' "$f" | tail -1 | tr -d '#' || true)
      execs=$((execs + ${n:-0}))
    done
    last=$(cat "$w"/run*.log 2>/dev/null | grep -E '^#[0-9]+.*cov: ' | tail -1 || true)
    cov=$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<< "$last")
    ft=$(sed -n 's/.*ft: \([0-9]*\).*/\1/p' <<< "$last")
    newn=$(find "$w/new" -type f | wc -l)
    nf=$(find "$w/findings" -type f | wc -l)
    printf '%-8s %12s %9s %8s %8s %9s %s\n' "$t" "$execs" "$secs" "${cov:-?}" "${ft:-?}" "$newn" "$nf"
  done
  echo "wall time $((t1 - t0)) s"
} | tee "$summary"

[ $merge = 1 ] || { echo "fuzz.sh: --no-merge: corpus and crashes left as they were; findings in $work/*/findings"; exit 0; }
total_findings=0
for t in "${harnesses[@]}"; do
  w="$work/$t"
  # new coverage into the corpus, minimised: only inputs that add coverage to what is there
  if [ -n "$(ls -A "$w/new")" ]; then
    before=$(ls "tests/fuzz/corpus/$t" | wc -l)
    "$build/tests/fuzz/fuzz_$t" -merge=1 "${common[@]}" "tests/fuzz/corpus/$t" "$w/new" > "$w/merge.log" 2>&1 ||
      echo "fuzz.sh: merging $t failed (see $w/merge.log)" >&2
    echo "$t: $(( $(ls "tests/fuzz/corpus/$t" | wc -l) - before )) inputs merged into tests/fuzz/corpus/$t"
  fi
  for f in "$w"/findings/*; do
    [ -f "$f" ] || continue
    mkdir -p "tests/fuzz/crashes/$t"
    cp "$f" "tests/fuzz/crashes/$t/"
    echo "$t: finding kept: tests/fuzz/crashes/$t/${f##*/}"
    total_findings=$((total_findings + 1))
  done
done
echo "fuzz.sh: $total_findings findings (each replayed by test_fuzz_inputs until fixed)"
