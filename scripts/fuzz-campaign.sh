#!/usr/bin/env bash
# scripts/fuzz-campaign.sh CPU_SECONDS [JOBS] [TARGET...]   (or --summary CPU_SECONDS [TARGET...])
# The long fuzzing run (docs/fuzzing.md): every target (default: all eight) runs until it has used
# CPU_SECONDS of CPU time (not wall time: the runs are niced so the machine stays usable, and
# a target that gets less CPU simply runs longer). JOBS targets run at once (default: nproc).
# A crash, timeout or out-of-memory input is kept in artifacts_TARGET and the target restarts
# (at most 20 times) until its CPU budget is spent. The corpus in the build folder is kept
# between runs. Inputs are capped at 128 KiB here (the smoke run allows 1 MiB; huge inputs are
# the unit tests' job) so each target runs many more of them. libFuzzer's -timeout is wall
# time and the runs are niced, so each timeout input is run again on its own with a 20 s CPU
# limit: only one that is still too slow counts as a hang; the others move to slow_TARGET.
# Results: build/fuzz/tests/assets/fuzz/campaign/TARGET.result, and a Markdown table in
# build/fuzz/tests/assets/fuzz/campaign/summary.md: docs/fuzzing.md quotes it between its
# campaign:begin/end markers (copied there by hand; this script never edits tracked files).
# Build first:  scripts/setup.sh fuzz   (or cmake --preset fuzz && cmake --build build/fuzz --target fuzz_all)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bindir="${FUZZ_BINDIR:-$root/build/fuzz/tests/assets/fuzz}"
data="${VIEWER_TESTDATA_DIR:-$root/../shared/testdata}"
out="$bindir/campaign"
ticks=$(getconf CLK_TCK)

cpu_of() { # user+system CPU seconds of a live process, or empty when it is gone
  local s
  s=$(cat "/proc/$1/stat" 2>/dev/null) || return 0
  s=${s##*) }  # fields after the command name
  # shellcheck disable=SC2086
  set -- $s
  echo $(( (${12} + ${13}) / ticks ))
}

one() {
  local t="$1" budget="$2" exe="$bindir/fuzz_$1"
  [ -x "$exe" ] || { echo "fuzz-campaign: $exe not built (scripts/setup.sh fuzz)" >&2; return 1; }
  # Seed corpus exactly as scripts/fuzz.sh makes it.
  "$root/scripts/fuzz.sh" "$t" 1 "$bindir" "$data" > /dev/null 2>&1 || true
  local corpus="$bindir/corpus_$t" seeds="$bindir/seeds_$t" artifacts="$bindir/artifacts_$t"
  mkdir -p "$corpus" "$seeds" "$artifacts"
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0:allocator_may_return_null=1}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
  local used=0 restarts=0 wall0 log rc pid c last a
  wall0=$(date +%s)
  rm -f "$out/$t".run*.log "$out/$t.cpu" "$out/$t.result"
  while [ "$used" -lt "$budget" ] && [ "$restarts" -le 20 ]; do
    log="$out/$t.run$restarts.log"
    nice -n 19 "$exe" "$corpus" "$seeds" -max_total_time=100000000 -timeout=120 \
      -rss_limit_mb=2048 -max_len=131072 -artifact_prefix="$artifacts/" \
      -print_final_stats=1 > "$log" 2>&1 &
    pid=$!
    last=0
    while kill -0 "$pid" 2>/dev/null; do
      sleep 5
      c=$(cpu_of "$pid"); [ -n "$c" ] && last=$c
      if [ $(( used + last )) -ge "$budget" ]; then kill -INT "$pid" 2>/dev/null || true; fi
    done
    set +e; wait "$pid"; rc=$?; set -e
    used=$(( used + last ))
    echo "run $restarts cpu_s $last rc $rc wall_s $(( $(date +%s) - wall0 ))" >> "$out/$t.cpu"
    for a in "$artifacts"/timeout-*; do
      [ -e "$a" ] || continue
      if (ulimit -t 20; "$exe" "$a" > /dev/null 2>&1); then
        mkdir -p "$bindir/slow_$t"; mv "$a" "$bindir/slow_$t/"
      fi
    done
    # 72 is libFuzzer's exit code when interrupted (our budget stop); anything else is a finding.
    if [ "$rc" -ne 72 ] && [ "$rc" -ne 0 ]; then restarts=$(( restarts + 1 )); else break; fi
  done
  summarize "$t" "$budget"
}

count() { # number of files matching find arguments, 0 when the folder is missing
  if [ -d "$1" ]; then find "$@" -type f 2>/dev/null | wc -l; else echo 0; fi
}

# The result row of one target, from what its runs left: campaign/TARGET.cpu (CPU seconds per
# run), the run logs (inputs, coverage), the corpus and the artifacts.
summarize() {
  local t="$1" budget="$2" cpu wall execs cov logs
  local corpus="$bindir/corpus_$t" artifacts="$bindir/artifacts_$t"
  logs=("$out/$t".run*.log)
  if [ -f "$out/$t.cpu" ]; then
    cpu=$(awk '{s+=$4} END {print s+0}' "$out/$t.cpu")
    wall=$(tail -n 1 "$out/$t.cpu" | awk '{print $8}')
  else   # runs from before .cpu files existed: a budget stop means the budget was used
    cpu="?"; wall="?"
    grep -q 'run interrupted' "${logs[-1]}" 2>/dev/null && cpu=">=$budget"
  fi
  execs=$(cat "${logs[@]}" 2>/dev/null | grep -o 'number_of_executed_units: [0-9]*' | awk '{s+=$2} END {print s+0}' || true)
  cov=$(cat "${logs[@]}" 2>/dev/null | grep -o 'cov: [0-9]* ft: [0-9]*' | tail -n 1 || true)
  printf '| %s | %s | %s | %s | %s | %s | %s | %s (+%s slow) | %s |\n' "$t" "$cpu" "$wall" "$execs" "${cov:-?}" \
    "$(count "$corpus")" "$(count "$artifacts" -name 'crash-*')" "$(count "$artifacts" -name 'timeout-*')" \
    "$(count "$bindir/slow_$t")" "$(count "$artifacts" \( -name 'oom-*' -o -name 'leak-*' \))" > "$out/$t.result"
  cat "$out/$t.result"
}

table() { # Markdown summary of the given targets
  local budget="$1"; shift
  echo "Fuzzing campaign $(date -u +%Y-%m-%d), $budget CPU-seconds per target, clang $(clang-14 --version | head -n 1 | grep -o '[0-9][0-9.]*' | head -n 1), -fsanitize=fuzzer,address,undefined, inputs up to 128 KiB"
  echo
  echo "| target | CPU s | wall s | inputs run | coverage (edges, features) | corpus files | crashes | hangs (+ slow, not hangs) | OOM/leaks |"
  echo "|---|---|---|---|---|---|---|---|---|"
  local t
  for t in "$@"; do summarize "$t" "$budget"; done
}

if [ "${1:-}" = --one ]; then mkdir -p "$out"; one "$2" "$3"; exit; fi
# --summary CPU_SECONDS [TARGET...]: only (re)write the table from what the runs left.
if [ "${1:-}" = --summary ]; then
  budget="$2"; shift 2
  targets=("$@"); [ ${#targets[@]} -gt 0 ] || targets=(scene_json gltf glb obj ply off stl image)
  table "$budget" "${targets[@]}" | tee "$out/summary.md"
  exit
fi

budget="${1:?usage: fuzz-campaign.sh CPU_SECONDS [JOBS] [TARGET...] | --summary CPU_SECONDS [TARGET...]}"
jobs="${2:-$(nproc)}"
shift; [ $# -gt 0 ] && shift
targets=("$@"); [ ${#targets[@]} -gt 0 ] || targets=(scene_json gltf glb obj ply off stl image)
mkdir -p "$out"
printf '%s\n' "${targets[@]}" | xargs -P "$jobs" -I{} "$0" --one {} "$budget" || true
table "$budget" "${targets[@]}" | tee "$out/summary.md"
