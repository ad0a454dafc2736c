#!/usr/bin/env bash
# scripts/compare-builds.sh OLD_VIEWER NEW_VIEWER [BACKEND [EXTRA...]]: renders a fixed set of
# scenes and settings with two builds of the viewer (default backend: raster; EXTRA options are
# added to every case, e.g. --shadows on) and compares the images and the --aov files byte for byte. For changes that must not change a pixel (a faster loop, a
# refactor). Prints one line per case and a summary; exit 1 when any case differs.
# Needs the shared test data (VIEWER_TESTDATA, default ../shared/testdata).
set -uo pipefail
old="$1" new="$2" backend="${3:-raster}"
shift $(($# < 3 ? $# : 3))
extra=("$@")
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data="${VIEWER_TESTDATA:-$root/../shared/testdata}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
g="$data/gltf"
m="$data/meshes/common-3d-test-models"
cases=(
  "demo-phong|demo"
  "demo-flat|demo --shading flat"
  "demo-gouraud|demo --shading gouraud"
  "demo-fog-linear|demo --fog linear"
  "demo-fog-exp2|demo --fog exp2"
  "demo-blinn|demo --reflection blinn"
  "demo-msaa4|demo --aa msaa4"
  "demo-ssaa2|demo --aa ssaa2"
  "demo-ortho|demo --projection orthographic"
  "demo-cabinet|demo --projection cabinet"
  "demo-cull-off|demo --culling off"
  "demo-wire|demo --wireframe on"
  "demo-aov|demo --aov depth,normal,id"
  "demo-overdraw|demo --view overdraw"
  "bunny|$m/stanford-bunny/stanford-bunny.obj"
  "bunny-flat|$m/stanford-bunny/stanford-bunny.obj --shading flat --fog linear"
  "igea|$m/igea/igea.ply"
  "spot-textured|$m/spot/spot.obj --aa ssaa2"
  "teapot|$m/teapot/teapot.obj --aa msaa4"
  "box-textured|$g/BoxTextured/glTF/BoxTextured.gltf"
  "milk-truck|$g/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf"
  "spec-gloss|$g/SpecGlossVsMetalRough/glTF/SpecGlossVsMetalRough.gltf"
  "multi-uv|$g/MultiUVTest/glTF/MultiUVTest.gltf"
  "texture-transform|$g/TextureTransformTest/glTF/TextureTransformTest.gltf"
  "unlit|$g/UnlitTest/glTF/UnlitTest.gltf"
  "sheen|$g/SheenCloth/glTF/SheenCloth.gltf"
  "cesium-man|$g/CesiumMan/glTF/CesiumMan.gltf --time 0.5"
  "clearcoat-alpha|$g/ClearCoatTest/glTF/ClearCoatTest.gltf"
)
same=0 differ=0 skipped=0
for c in "${cases[@]}"; do
  name="${c%%|*}" args="${c#*|}"
  scene="${args%% *}"
  if [ "$scene" != demo ] && [ ! -e "$scene" ]; then
    echo "skip   $name (no $scene)"; skipped=$((skipped + 1)); continue
  fi
  failed=""
  for side in old new; do
    bin="$old"; [ "$side" = new ] && bin="$new"
    mkdir -p "$out/$side"
    # shellcheck disable=SC2086
    "$bin" render $args --backend "$backend" "${extra[@]}" --size 640x360 --out "$out/$side/$name.png" >/dev/null 2>"$out/$name.$side.err" || failed="$failed $side"
  done
  if [ -n "$failed" ]; then
    # Both builds refusing with the same message (a view this backend cannot make) is no difference.
    if [ "$failed" = " old new" ] && cmp -s "$out/$name.old.err" "$out/$name.new.err"; then
      echo "same   $name (both: $(tail -1 "$out/$name.new.err"))"; same=$((same + 1))
    else
      for side in $failed; do echo "error  $name ($side): $(tail -1 "$out/$name.$side.err")"; done
      differ=$((differ + 1))
    fi
    continue
  fi
  diffs=""
  for f in "$out/old/$name".*; do
    cmp -s "$f" "$out/new/$(basename "$f")" || diffs="$diffs $(basename "$f")"
  done
  if [ -z "$diffs" ]; then echo "same   $name"; same=$((same + 1)); else echo "DIFFER $name:$diffs"; differ=$((differ + 1)); fi
done
echo "compare-builds: $same same, $differ differ, $skipped skipped ($backend)"
[ $differ = 0 ]
