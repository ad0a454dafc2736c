#!/usr/bin/env bash
# Re-renders the GL baseline images (tests/baselines/gl/*.png) from the current build and
# lists what changed. Look at the new images (and the diffs of a failing run in
# build/<preset>/test-output/gl-baselines/) BEFORE committing them.
# Usage: scripts/accept-baselines.sh [preset]   (default: release)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
cd "$root"
if [ ! -f "build/$preset/CMakeCache.txt" ]; then cmake --preset "$preset" >/dev/null; fi
cmake --build "build/$preset" -j2 --target gl_tests
VIEWER_ACCEPT_BASELINES=1 "build/$preset/tests/renderers/gl/gl_tests" --gtest_filter='*BaselineGLTest*' | grep '^\[baseline\]' || true
echo "accept-baselines: changed files (git status):"
git status --short -- tests/baselines/gl
