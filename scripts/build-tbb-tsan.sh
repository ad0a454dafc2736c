#!/usr/bin/env bash
# scripts/build-tbb-tsan.sh: build oneTBB with ThreadSanitizer from Debian's own source package
# (the version of the installed libtbb-dev) and install it under build/tbb-tsan/, where the tsan
# preset's TBB_DIR points. Debian's libtbb is not instrumented, so TSan cannot see its
# synchronisation and reports hundreds of false races inside TBB's task scheduler; an
# instrumented TBB makes a TSan run mean something. Nothing of TBB is committed: the source is
# fetched with apt-get source (hashes checked against Debian's signed Sources index) and the
# build is cached: a second run with the same version does nothing.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$root/build/tbb-tsan"
prefix="$out/prefix"

version="$(dpkg-query -W -f='${source:Version}' libtbb-dev)"
stamp="$prefix/.built-from"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "onetbb $version" ]; then
  echo "build-tbb-tsan: $prefix already holds onetbb $version built with TSan"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then SUDO=(); else SUDO=(sudo); fi
# apt-get source needs a deb-src entry; add one for the same suites as the binary packages.
srclist=/etc/apt/sources.list.d/viewer-deb-src.sources
if ! apt-get source --download-only --print-uris "onetbb=$version" >/dev/null 2>&1; then
  if [ ! -f "$srclist" ]; then
    echo "build-tbb-tsan: adding deb-src entries ($srclist)"
    "${SUDO[@]}" tee "$srclist" >/dev/null <<'EOF'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb-src
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  fi
  "${SUDO[@]}" apt-get update -qq
fi

rm -rf "$out"
mkdir -p "$out/src"
cd "$out/src"
# --download-only + dpkg-source -x: unpack and apply Debian's patches without needing the
# package's build dependencies; the download is verified against the signed index.
apt-get source --download-only -qq "onetbb=$version"
dpkg-source --no-check -x ./*.dsc tbb >/dev/null
rm -f ./*.tar.* ./*.dsc

# Only libtbb (what TBB::tbb links); no tbbmalloc, tests or examples. TBB_SANITIZE adds
# -fsanitize=thread to TBB's own compile and link flags. GCC warns (-Wtsan, silenced: 400 lines)
# that TSan does not model TBB's few atomic_thread_fence calls; the planted-race tests' clean
# runs show no report coming from that.
cmake -S tbb -B "$out/obj" -G "Unix Makefiles" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS=-Wno-tsan -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib \
  -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF -DTBB_STRICT=OFF \
  -DTBBMALLOC_BUILD=OFF -DTBBMALLOC_PROXY_BUILD=OFF -DTBB4PY_BUILD=OFF >/dev/null
jobs="${TBB_JOBS:-$(nproc 2>/dev/null || echo 2)}"
cmake --build "$out/obj" -j "$jobs"
cmake --install "$out/obj" >/dev/null
echo "onetbb $version" >"$stamp"
rm -rf "$out/src" "$out/obj"
echo "build-tbb-tsan: installed onetbb $version (TSan) in $prefix"
