#!/usr/bin/env bash
# Shared by ./run and ./test: install missing Debian packages, configure, build.
# Usage: scripts/setup.sh [preset]   (default: release); scripts/setup.sh --packages-only installs and stops
# (tsan also builds TBB with ThreadSanitizer: scripts/build-tbb-tsan.sh)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-release}"

# Debian 12 packages the project needs. Keep in one place.
packages=(
  build-essential cmake pkg-config python3 python3-glad
  libglfw3-dev libimgui-dev libglm-dev libtinygltf-dev libopenmesh-dev libstb-dev zlib1g-dev
  libtbb-dev libcli11-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev libembree-dev
  libgl1-mesa-dri libegl-mesa0 libegl-dev libgl-dev libosmesa6-dev xvfb xauth fonts-dejavu-core clang-format
  # The Debian package: CPack computes Depends with dpkg-shlibdeps (dpkg-dev) and file; the
  # package test checks the desktop entry (desktop-file-validate) and the man page (groff).
  dpkg-dev file desktop-file-utils groff-base
)

# The fuzz preset also needs clang and its libFuzzer runtime.
if [ "$preset" = fuzz ]; then packages+=(clang-14 libclang-rt-14-dev); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing missing Debian packages: ${missing[*]}"
  if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
  elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
  else
    echo "setup: error: packages missing (${missing[*]}) and not root and no sudo; install them as root." >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" apt-get update -qq
  "${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

[ "$preset" = "--packages-only" ] && exit 0

cd "$root"
# The tsan preset links a TBB built with ThreadSanitizer (cached under build/tbb-tsan/).
if [ "$preset" = tsan ]; then scripts/build-tbb-tsan.sh; fi
builddir="build/$preset"
if [ ! -f "$builddir/CMakeCache.txt" ]; then
  cmake --preset "$preset" >/dev/null
fi
jobs="$(nproc 2>/dev/null || echo 2)"
if [ "$preset" = fuzz ]; then
  cmake --build "$builddir" -j "$jobs" --target fuzz_all
elif [ "$preset" = tsan ]; then
  cmake --build "$builddir" -j "$jobs" --target tsan_all
else
  cmake --build "$builddir" -j "$jobs"
fi
