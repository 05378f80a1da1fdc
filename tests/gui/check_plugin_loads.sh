#!/usr/bin/env bash
# Scripted check that MeshLab 2025.07d (built from the same sources) starts with our plugin:
# installs the module into its plugins/ folder, starts MeshLab under Xvfb on pymeshlab's bunny,
# checks that the module stays mapped in the MeshLab process (MeshLab unloads plugins that fail
# its checks), that no error dialog opened, then opens Filters > Remeshing, Simplification and
# Reconstruction and keeps a screenshot of the menu as the test artefact.
# Usage: check_plugin_loads.sh MESHLAB_DISTRIB_DIR PLUGIN_SO [SCREENSHOT_PNG]
set -euo pipefail
distrib=$1
plugin=$2
shot=${3:-out/gui/filters_menu.png}
mkdir -p "$(dirname "$shot")"
cp "$plugin" "$distrib/plugins/"
scan=$(python3 -c 'import pymeshlab, os; print(os.path.join(os.path.dirname(pymeshlab.__file__), "tests", "sample_meshes", "bunny10k_textured.obj"))')

work=$(mktemp -d)
display=":$((90 + RANDOM % 400))"
Xvfb "$display" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
cleanup() { kill "${meshlab:-}" 2>/dev/null || true; kill "$xvfb" 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
export DISPLAY=$display XDG_CONFIG_HOME="$work/config" HOME="$work"
sleep 1
"$distrib/meshlab" "$scan" >"$work/meshlab.log" 2>&1 &
meshlab=$!

# The first start asks "Send Anonymous Statistics?" before showing the main window: answer No.
if timeout 60 xdotool search --sync --name '^Send Anonymous Statistics' >/dev/null; then
  sleep 1; xdotool key alt+n
fi
window=$(timeout 60 xdotool search --sync --onlyvisible --name '^MeshLab 20' | head -n1)
sleep 5  # let the scan finish loading
if ! grep -q libfilter_implicit_boundaries.so "/proc/$meshlab/maps"; then
  echo "FAIL: MeshLab did not keep libfilter_implicit_boundaries.so loaded"; cat "$work/meshlab.log"; exit 1
fi
for w in $(xdotool search --onlyvisible --name '.' 2>/dev/null); do
  [ "$w" = "$window" ] && continue
  name=$(xdotool getwindowname "$w" 2>/dev/null || true)
  case "$name" in *rror*|*arning*|*nable*) echo "FAIL: MeshLab showed a dialog: $name"; cat "$work/meshlab.log"; exit 1;; esac
done
# No window manager runs, so menus are opened with the mouse: the window sits at (0,0) in its
# default size, "Filters" is the third menu and "Remeshing, Simplification and Reconstruction"
# its sixth row.
xdotool mousemove 120 10 click 1; sleep 1
xdotool mousemove 200 161; sleep 0.5; xdotool mousemove 210 161 click 1; sleep 2
import -window root "$shot"
echo "MeshLab GUI started with the plugin loaded; Filters > Remeshing menu screenshot: $shot"
