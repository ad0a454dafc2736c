#!/usr/bin/env bash
# check_layering.sh SOURCE_DIR - the one-way dependencies between the libraries, read from the
# sources' #include lines and the folders' target_link_libraries:
#   scenegraph -> nothing of ours (and never GL, ImGui or GLFW)
#   assets     -> scenegraph
#   renderers  -> scenegraph (never assets or ui; never ImGui)
#   ui         -> renderers, assets, scenegraph (never app)
#   app        -> anything
# Prints every violation (file and line) and fails when there is one.
set -euo pipefail
root="${1:?usage: check_layering.sh SOURCE_DIR}"
cd "$root"
bad=0
# forbid FOLDER PATTERN WHY: no #include in FOLDER's sources matches PATTERN.
forbid() {
  local folder=$1 pattern=$2 why=$3 hits
  hits="$(grep -rnE --include='*.h' --include='*.cpp' --include='*.inl' "^[[:space:]]*#[[:space:]]*include[[:space:]]*[<\"]($pattern)" "$folder" || true)"
  if [ -n "$hits" ]; then
    echo "layering: $folder must not include $why:"
    printf '  %s\n' "$hits"
    bad=1
  fi
}
# forbidLink FOLDER PATTERN WHY: FOLDER's CMakeLists link no library matching PATTERN.
forbidLink() {
  local folder=$1 pattern=$2 why=$3 hits
  hits="$(find "$folder" -name CMakeLists.txt -print0 | xargs -0 grep -nE "target_link_libraries\([^)]*\b($pattern)\b" || true)"
  if [ -n "$hits" ]; then
    echo "layering: $folder must not link $why:"
    printf '  %s\n' "$hits"
    bad=1
  fi
}
forbid scenegraph 'assets/|renderers/|ui/|app/|imgui|GLFW/|glad/|backends/|EGL/|GL/' "the other libraries, GL, ImGui or GLFW"
forbid assets 'renderers/|ui/|app/|imgui|GLFW/|glad/' "renderers, ui, app, GL, ImGui or GLFW"
forbid renderers 'assets/|ui/|app/|imgui|backends/' "assets, ui, app or ImGui"
forbid ui 'app/|cli\.h|camera_jobs\.h' "app"
forbidLink scenegraph 'assets|renderers[a-z_]*|ui[a-z_]*|glfw|imgui' "the other libraries, ImGui or GLFW"
forbidLink assets 'renderers[a-z_]*|ui[a-z_]*|glfw' "renderers, ui or GLFW"
forbidLink renderers 'assets|ui[a-z_]*' "assets or ui"
if [ "$bad" -ne 0 ]; then exit 1; fi
echo "layering: scenegraph <- assets, renderers <- ui <- app: no include or link against the grain"
