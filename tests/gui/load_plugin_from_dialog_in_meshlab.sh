#!/usr/bin/env bash
# Installing the plugin the GUI way, as a MeshLab user without a build tree does: with the
# module absent from MeshLab's plugins/ folder, starts MeshLab under Xvfb, opens Help > Plugin
# Info, presses "Load Plugins" and gives the module's path in the file dialog. MeshLab checks
# it (a plugin of the other precision is refused there), copies it into its extra plugins
# folder (~/.local/share/VCG/<MeshLab>/MeshLabExtraPlugins/<version>/) and lists it. Then
# MeshLab is restarted: the module must be loaded from that folder, and the filter must open
# from the Filters menu and run. Screenshots in OUT_DIR.
# Usage: load_plugin_from_dialog_in_meshlab.sh MESHLAB_DISTRIB_DIR PLUGIN_SO [OUT_DIR]
set -euo pipefail
. "$(dirname "$0")/common.sh"
plugin=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
gui_init "$1" "" "${3:-out/gui-load-plugin}"

scan="$work/sphere_points.ply"
python3 - "$scan" <<'PY'
import sys, numpy as np, pymeshlab
i = np.arange(3000) + 0.5  # a Fibonacci sphere without its top: one boundary loop
z = 1 - 2 * i / 3000; r = np.sqrt(1 - z * z); phi = np.pi * (1 + 5 ** 0.5) * i
p = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])[z < 0.7]
ms = pymeshlab.MeshSet()
ms.add_mesh(pymeshlab.Mesh(vertex_matrix=p, v_normals_matrix=p), "open sphere")
ms.save_current_mesh(sys.argv[1], save_vertex_color=False, save_vertex_normal=True)
PY

gui_start "$scan"
# Help is the eighth menu; Plugin Info its second row. The dialog opens over the main window.
xdotool mousemove 395 10 click 1; sleep 1
xdotool mousemove 440 59; sleep 0.5; xdotool mousemove 445 59 click 1; sleep 2
info=$(xdotool search --onlyvisible --name '^Plugin Information$' | head -n1) ||
  { echo "FAIL: Help > Plugin Info did not open"; exit 1; }
eval "$(xdotool getwindowgeometry --shell "$info")"
import -window root "$out/plugin_info.png"
# "Load Plugins" is the dialog's bottom-left button; its file dialog starts in the name field.
xdotool mousemove $((X + 54)) $((Y + HEIGHT - 24)); sleep 0.5; xdotool mousemove $((X + 56)) $((Y + HEIGHT - 24)) click 1
timeout 30 xdotool search --sync --onlyvisible --name '^Load Plugins$' >/dev/null ||
  { echo "FAIL: the Load Plugins file dialog did not open"; exit 1; }
sleep 1
xdotool type --delay 20 "$plugin"; sleep 0.5; xdotool key Return; sleep 3
import -window root "$out/plugin_loaded.png"
installed=$(find "$work/.local/share" -path '*MeshLabExtraPlugins*' -name libfilter_implicit_boundaries.so | head -n1)
if [ -z "$installed" ]; then
  echo "FAIL: MeshLab did not copy the plugin into its extra plugins folder"; cat "$work/meshlab.log"; exit 1
fi
gui_check_loaded

gui_restart "$scan"
if ! grep -q "$installed" "/proc/$meshlab/maps"; then
  echo "FAIL: after a restart MeshLab did not load $installed"; cat "$work/meshlab.log"; exit 1
fi
gui_open_filter_dialog
gui_apply_and_close
report=$(gui_surface_report)
loops=$(echo "$report" | gui_surface_field 3)
if [ "$loops" -ne 1 ]; then echo "FAIL: $loops boundary loops where the open sphere has 1: $report"; exit 1; fi
echo "MeshLab installed the plugin from Plugin Info > Load Plugins ($installed) and, restarted, ran it: $report"
echo "screenshots: $out/plugin_info.png $out/plugin_loaded.png $out/filter_dialog.png $out/result.png"
