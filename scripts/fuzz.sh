#!/usr/bin/env bash
# scripts/fuzz.sh TARGET SECONDS|smoke [BUILD_TESTS_FUZZ_DIR] [TESTDATA_DIR]
# Runs one libFuzzer target for SECONDS (seed corpus from shared/testdata, a corpus kept in the
# build folder); crashes are saved as crash-* files in artifacts_TARGET and make the script
# fail. `smoke` (what CI runs) is deterministic: a fresh corpus, seed 1 and a fixed number of
# inputs, so a green smoke run here is green in CI; longer runs find new inputs.
# Build first:  cmake --preset fuzz && cmake --build build/fuzz -j2
# Targets: scene_json gltf glb obj ply off stl image
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
t="$1"; secs="${2:-60}"
bindir="${3:-$root/build/fuzz/tests/assets/fuzz}"
data="${4:-$root/../shared/testdata}"
exe="$bindir/fuzz_$t"
[ -x "$exe" ] || { echo "fuzz.sh: $exe not built (cmake --preset fuzz && cmake --build build/fuzz)" >&2; exit 1; }
corpus="$bindir/corpus_$t"; seeds="$bindir/seeds_$t"; artifacts="$bindir/artifacts_$t"
mkdir -p "$corpus" "$seeds" "$artifacts"
case "$t" in
  scene_json) cp "$root"/tests/assets/fuzz/seeds/*.json "$seeds/" ;;
  gltf) pat='*.gltf' ;; glb) pat='*.glb' ;; obj) pat='*.obj' ;; ply) pat='*.ply' ;;
  off) pat='*.off' ;; stl) pat='*.[sS][tT][lL]' ;; image) pat='*.png' ;;
esac
if [ -n "${pat:-}" ] && [ -d "$data" ]; then
  # Sorted, for a deterministic seed set; with pipefail the pipeline may report SIGPIPE once
  # head has its 200 names, which is not an error.
  { find "$data" -iname "$pat" -size -300k 2>/dev/null | sort | head -200 |
      while read -r f; do cp "$f" "$seeds/" 2>/dev/null || true; done; } || true
fi
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0:allocator_may_return_null=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
if [ "$secs" = smoke ]; then
  corpus="$bindir/smoke_corpus_$t"
  rm -rf "$corpus"
  mkdir -p "$corpus"
  limits=(-runs=4000 -seed=1)
else
  limits=(-max_total_time="$secs")
fi
set +e
"$exe" "$corpus" "$seeds" "${limits[@]}" -timeout=10 -rss_limit_mb=2048 -max_len=1048576 \
  -artifact_prefix="$artifacts/" -print_final_stats=1 > "$bindir/last_run_$t.log" 2>&1
rc=$?
set -e
tail -n 25 "$bindir/last_run_$t.log"
exit $rc
