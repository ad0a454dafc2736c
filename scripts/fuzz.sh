#!/usr/bin/env bash
# scripts/fuzz.sh TARGET SECONDS [BUILD_TESTS_FUZZ_DIR] [TESTDATA_DIR]
# Runs one libFuzzer target for SECONDS (seed corpus from shared/testdata); crashes are saved
# as crash-* files in the corpus folder and make the script fail.
# Build first:  cmake --preset fuzz && cmake --build build/fuzz -j2
# Targets: scene_json gltf glb obj ply off stl image
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
t="$1"; secs="${2:-60}"
bindir="${3:-$root/build/fuzz/tests/fuzz}"
data="${4:-$root/../shared/testdata}"
exe="$bindir/fuzz_$t"
[ -x "$exe" ] || { echo "fuzz.sh: $exe not built (cmake --preset fuzz && cmake --build build/fuzz)" >&2; exit 1; }
corpus="$bindir/corpus_$t"; seeds="$bindir/seeds_$t"; artifacts="$bindir/artifacts_$t"
mkdir -p "$corpus" "$seeds" "$artifacts"
case "$t" in
  scene_json) # seeds: the demo scene written by the viewer itself, plus small hand-made files
              for v in "$bindir/../../app/viewer" "$root/build/release/app/viewer"; do
                [ -x "$v" ] && { "$v" convert demo --out "$seeds/demo.json" --overwrite >/dev/null 2>&1 || true; break; }
              done
              echo '{"nodes":[{},{"parent":0,"implicit":{"type":"sphere"}}]}' > "$seeds/min.json" ;;
  gltf) pat='*.gltf' ;; glb) pat='*.glb' ;; obj) pat='*.obj' ;; ply) pat='*.ply' ;;
  off) pat='*.off' ;; stl) pat='*.[sS][tT][lL]' ;; image) pat='*.png' ;;
esac
if [ -n "${pat:-}" ] && [ -d "$data" ]; then
  find "$data" -iname "$pat" -size -300k 2>/dev/null | head -200 | while read -r f; do cp "$f" "$seeds/" 2>/dev/null || true; done
fi
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0:allocator_may_return_null=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
"$exe" "$corpus" "$seeds" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=1048576 \
  -artifact_prefix="$artifacts/" -print_final_stats=1 2>&1 | tail -n 25
