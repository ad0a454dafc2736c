#!/usr/bin/env bash
# package_test.sh STEP BUILD_DIR SOURCE_DIR [BACKEND]: the steps of the Debian package test
# (tests/packaging/CMakeLists.txt says what each checks). Environment from CTest: CPACK_COMMAND,
# VIEWER_VERSION (the CMake project version), VIEWER_SANITIZE (1 in sanitizer builds).
# Never skips: a missing tool or file is a failure, reported as one line on stderr.
set -euo pipefail
step="$1" build="$2" src="$3" backend="${4:-}"
out="$build/test-output/package"
root="$out/root"
viewer="$root/usr/bin/viewer"
label="$step${backend:+ $backend}"

fail() {
  echo "package test: $label: $*" >&2
  exit 1
}
need() { command -v "$1" >/dev/null 2>&1 || fail "$1 not found (Debian package $2; scripts/setup.sh installs it)"; }
firstline() { grep -m1 . <<<"$1" || true; }

need dpkg-deb dpkg
arch="$(dpkg --print-architecture)"
deb="$out/sceneviewer_${VIEWER_VERSION}-1_${arch}.deb"

# The package's files, besides the folders. Anything more or less is a packaging change that
# should show up here.
expected_files="./usr/bin/viewer
./usr/share/applications/sceneviewer.desktop
./usr/share/icons/hicolor/256x256/apps/sceneviewer.png
./usr/share/icons/hicolor/scalable/apps/sceneviewer.svg
./usr/share/man/man1/viewer.1.gz
./usr/share/mime/packages/sceneviewer.xml"

build_package() {
  need dpkg-shlibdeps dpkg-dev
  need file file
  [ -x "$CPACK_COMMAND" ] || fail "cpack not found at '$CPACK_COMMAND'"
  [ -x "$build/app/viewer" ] || fail "$build/app/viewer missing: build first (cmake --build $build)"
  [ -f "$build/CPackConfig.cmake" ] || fail "$build/CPackConfig.cmake missing: configure first"
  rm -rf "$out"
  mkdir -p "$out"
  # -B: the package and CPack's staging folder go to $out, not next to scripts/package.sh's.
  if ! (cd "$build" && "$CPACK_COMMAND" -G DEB -B "$out" --config "$build/CPackConfig.cmake") >"$out/cpack.log" 2>&1; then
    fail "cpack -G DEB failed: $(grep -m1 -i 'error' "$out/cpack.log" || tail -n1 "$out/cpack.log") (log: $out/cpack.log)"
  fi
  [ -f "$deb" ] || fail "cpack made no $(basename "$deb"): $(find "$out" -maxdepth 1 -name '*.deb' -printf '%f ')"
  dpkg-deb -x "$deb" "$root" || fail "dpkg-deb -x $deb failed"
  echo "package test: $deb"
  dpkg-deb --field "$deb" Depends
}

check_contents() {
  [ -f "$deb" ] || fail "$deb missing (package_build failed?)"
  local f v
  for f in Package:sceneviewer "Version:${VIEWER_VERSION}-1" "Architecture:$arch" Section:graphics; do
    v="$(dpkg-deb --field "$deb" "${f%%:*}")"
    [ "$v" = "${f#*:}" ] || fail "control field ${f%%:*} is '$v', expected '${f#*:}'"
  done
  for f in Maintainer Description; do
    [ -n "$(dpkg-deb --field "$deb" "$f")" ] || fail "control field $f is empty"
  done
  # Depends: computed by dpkg-shlibdeps (libc6, libstdc++6, libglfw3, libtbb12 are linked) plus
  # the two that glad dlopen()s.
  local depends
  depends="$(dpkg-deb --field "$deb" Depends)"
  for f in libc6 libstdc++6 libglfw3 libtbb12 libegl1 libgl1; do
    grep -Eq "(^|, )${f//+/\\+}( |,|$)" <<<"$depends" || fail "Depends lacks $f: $depends"
  done

  local listed
  listed="$(dpkg-deb -c "$deb" | grep -v '^d' | awk '{print $6}' | sort)"
  [ "$listed" = "$(printf '%s\n' "$expected_files" | sort)" ] ||
    fail "files differ from the expected list: $(diff <(printf '%s\n' "$expected_files" | sort) <(printf '%s\n' "$listed") | grep '^[<>]' | tr '\n' ' ')"
  [ -x "$viewer" ] || fail "$viewer is not executable after dpkg -x"

  need desktop-file-validate desktop-file-utils
  local desktop="$root/usr/share/applications/sceneviewer.desktop" msg
  msg="$(desktop-file-validate "$desktop" 2>&1)" || fail "desktop-file-validate: $(firstline "$msg")"
  [ -z "$msg" ] || fail "desktop-file-validate: $(firstline "$msg")"
  grep -qx 'Exec=viewer %f' "$desktop" || fail "sceneviewer.desktop: Exec is not 'viewer %f'"
  grep -qx 'Icon=sceneviewer' "$desktop" || fail "sceneviewer.desktop: Icon is not 'sceneviewer'"

  need python3 python3
  for f in usr/share/mime/packages/sceneviewer.xml usr/share/icons/hicolor/scalable/apps/sceneviewer.svg; do
    msg="$(python3 -c 'import sys, xml.etree.ElementTree as E; E.parse(sys.argv[1])' "$root/$f" 2>&1)" ||
      fail "$f is not well-formed XML: $(printf '%s\n' "$msg" | tail -n1)"
  done
  grep -q 'PNG image data, 256 x 256, 8-bit/color RGBA' <<<"$(file "$root/usr/share/icons/hicolor/256x256/apps/sceneviewer.png")" ||
    fail "sceneviewer.png is not a 256x256 RGBA PNG: $(file -b "$root/usr/share/icons/hicolor/256x256/apps/sceneviewer.png")"

  # The man page: no groff warnings, and every option and command of --help-all documented.
  need groff groff-base
  local page help word
  page="$(gzip -dc "$root/usr/share/man/man1/viewer.1.gz")" || fail "viewer.1.gz does not decompress"
  msg="$(LC_ALL=C.UTF-8 groff -man -Tutf8 -ww -z <<<"$page" 2>&1)"
  [ -z "$msg" ] || fail "viewer.1: groff: $(firstline "$msg")"
  help="$("$viewer" --help-all 2>&1)" || fail "viewer --help-all failed: $(firstline "$help")"
  while read -r word; do
    grep -qF -- "${word//-/\\-}" <<<"$page" || fail "viewer.1 does not mention $word (viewer --help-all lists it)"
  done < <(grep -oE -- '--[a-z][a-z-]*' <<<"$help" | sort -u)
  for word in render compare inspect demo-shots convert; do
    grep -qF -- "${word//-/\\-}" <<<"$page" || fail "viewer.1 does not mention the command $word"
  done

  # Nothing installed may point back into the source or build folder. The executable may name
  # source files (sanitizer builds keep them for their reports) but no other path there;
  # debug info is left out of the look.
  msg="$(grep -rlF -- "$src/" "$root/usr/share" || true)"
  [ -z "$msg" ] || fail "$(firstline "$msg") mentions $src/"
  need objcopy binutils
  need strings binutils
  local stripped="$out/viewer.nodebug" paths
  objcopy --strip-debug "$viewer" "$stripped" || fail "objcopy --strip-debug failed"
  paths="$(strings -a "$stripped" | grep -F -- "$src/" | grep -vE '\.(c|cc|cpp|h|hpp|inl)$' || true)"
  [ -z "$paths" ] || fail "usr/bin/viewer refers to the source/build folder: $(firstline "$paths")"
  echo "package test: contents ok (${VIEWER_SANITIZE:+sanitize=$VIEWER_SANITIZE, }Depends: $depends)"
}

check_version() {
  [ -x "$viewer" ] || fail "$viewer missing (package_build failed?)"
  local v
  v="$("$viewer" --version 2>&1)" || fail "viewer --version failed: $(firstline "$v")"
  grep -Eqx "viewer ${VIEWER_VERSION//./\\.} \(git ([0-9a-f]{7,}(-dirty)?|unknown)\)" <<<"$v" ||
    fail "viewer --version printed '$v', expected 'viewer $VIEWER_VERSION (git <revision>|unknown)'"
  echo "package test: $v"
}

render() {
  [ -n "$backend" ] || fail "no backend given"
  [ -x "$viewer" ] || fail "$viewer missing (package_build failed?)"
  need file file
  local dir="$out/render-$backend" log
  rm -rf "$dir"
  mkdir -p "$dir"
  # From an empty folder, so that nothing of the source or build tree can be found by accident.
  log="$(cd "$dir" && timeout -k 5 100 "$viewer" render demo --out demo.png --backend "$backend" --size 320x180 2>&1)" ||
    fail "viewer render demo --backend $backend failed (exit $?): $(printf '%s\n' "$log" | tail -n1)"
  grep -q 'PNG image data, 320 x 180' <<<"$(file "$dir/demo.png")" || fail "demo.png is not a 320x180 PNG: $(file -b "$dir/demo.png")"
  # The demo scene at this size compresses to tens of KB; a blank or flat image to under 1 KB.
  local bytes
  bytes="$(stat -c %s "$dir/demo.png")"
  [ "$bytes" -gt 4096 ] || fail "demo.png has only $bytes bytes: blank image?"
  printf '%s\n' "$log"
}

case "$step" in
  build) build_package ;;
  contents) check_contents ;;
  version) check_version ;;
  render) render ;;
  *) fail "unknown step (build, contents, version, render BACKEND)" ;;
esac
