#!/usr/bin/env bash
# The filter used as a MeshLab user does, in MeshLab 2025.07d built from the same sources:
# installs the module into its plugins/ folder, starts MeshLab under Xvfb on a point cloud
# (pymeshlab's bunny scan, vertices and normals only), checks that the module stays mapped in
# the MeshLab process (MeshLab unloads plugins that fail its checks) and that no error dialog
# opened, opens Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction
# with boundaries, presses Apply, and checks MeshLab's log (it echoes its log window on
# stderr) for the filter's report and the new layer. Screenshots of the menu, the dialog and
# the result are kept in OUT_DIR as the test's artefacts.
# Usage: apply_filter_in_meshlab.sh MESHLAB_DISTRIB_DIR PLUGIN_SO [OUT_DIR]
set -euo pipefail
distrib=$1
plugin=$2
out=${3:-out/gui}
mkdir -p "$out"
cp "$plugin" "$distrib/plugins/"

work=$(mktemp -d)
scan="$work/bunny_points.ply"
python3 - "$scan" <<'PY'
import os, sys, pymeshlab
ms = pymeshlab.MeshSet()
ms.load_new_mesh(os.path.join(os.path.dirname(pymeshlab.__file__), "tests", "sample_meshes", "bunny10k_textured.obj"))
m = ms.current_mesh()
points = pymeshlab.MeshSet()
points.add_mesh(pymeshlab.Mesh(vertex_matrix=m.vertex_matrix(), v_normals_matrix=m.vertex_normal_matrix()), "bunny points")
points.save_current_mesh(sys.argv[1], save_vertex_color=False, save_vertex_normal=True)
PY

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
import -window root "$out/filters_menu.png"
# Our filter is the third row of that submenu; its dialog opens over the main window.
xdotool mousemove 600 211; sleep 0.5; xdotool mousemove 666 211 click 1; sleep 3
import -window root "$out/filter_dialog.png"
dialog=$(xdotool search --onlyvisible --name '^Implicit reconstruction with boundaries$' | head -n1) ||
  { echo "FAIL: the filter's dialog did not open"; exit 1; }
# Its buttons sit in its bottom row: Close on the left half, Apply on the right.
eval "$(xdotool getwindowgeometry --shell "$dialog")"
row=$((Y + HEIGHT - 21))
xdotool mousemove $((X + WIDTH * 3 / 4 - 5)) $row; sleep 0.5; xdotool mousemove $((X + WIDTH * 3 / 4)) $row click 1  # Apply
for _ in $(seq 120); do
  grep -q "Applied filter: Implicit reconstruction with boundaries" "$work/meshlab.log" && break
  sleep 1
done
xdotool mousemove $((X + WIDTH / 4)) $row click 1; sleep 2  # Close
import -window root "$out/result.png"
cp "$work/meshlab.log" "$out/meshlab.log"
if ! grep -q "Applied filter: Implicit reconstruction with boundaries" "$work/meshlab.log"; then
  echo "FAIL: the filter did not run (MeshLab's log: $out/meshlab.log)"; exit 1
fi
report=$(grep -o "Surface: [0-9]* faces.*boundary loops kept[^;]*" "$work/meshlab.log") ||
  { echo "FAIL: the filter made no surface (MeshLab's log: $out/meshlab.log)"; exit 1; }
faces=$(echo "$report" | sed 's/Surface: \([0-9]*\) faces.*/\1/')
if [ "$faces" -lt 10000 ]; then echo "FAIL: only $faces faces: $report"; exit 1; fi
echo "MeshLab ran the filter from its menu: $report"
echo "screenshots: $out/filters_menu.png $out/filter_dialog.png $out/result.png"
