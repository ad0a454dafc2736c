#!/usr/bin/env bash
# scripts/package.sh [preset]: the Debian package build/<preset>/sceneviewer_<version>-1_<arch>.deb
# (default preset: release). Installs what is missing (scripts/setup.sh), builds the viewer and
# its data files, then runs CPack (packaging/CMakeLists.txt). Install it with
#   sudo apt-get install ./build/release/sceneviewer_*.deb
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"
case "$preset" in
  asan | fuzz) echo "package: warning: the $preset preset gives a sanitizer build, fit for tests only" >&2 ;;
esac
"$root/scripts/setup.sh" --packages-only
cd "$root"
builddir="build/$preset"
if [ ! -f "$builddir/CMakeCache.txt" ]; then
  cmake --preset "$preset" >/dev/null
fi
jobs="$(nproc 2>/dev/null || echo 2)"
# Only what the package holds (the tests and benchmarks are not needed for it).
cmake --build "$builddir" -j "$jobs" --target viewer packaging_files
cd "$builddir"
rm -f sceneviewer_*.deb   # one package in the folder, so that ./sceneviewer_*.deb names it
cpack -G DEB >/dev/null
deb="$(ls sceneviewer_*.deb)"
echo "package: $root/$builddir/$deb"
dpkg-deb --field "$deb" Package Version Depends
echo "install: sudo apt-get install ./$builddir/$deb   (remove: sudo apt-get remove sceneviewer)"
