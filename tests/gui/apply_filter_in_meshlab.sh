#!/usr/bin/env bash
# The filter used as a MeshLab user does, in MeshLab 2025.07 or 2025.07d (the plugin of its precision) built from the same sources:
# installs the module into its plugins/ folder, starts MeshLab under Xvfb on a point cloud
# (pymeshlab's bunny scan, vertices and normals only), checks that the module stays mapped in
# the MeshLab process (MeshLab unloads plugins that fail its checks) and that no error dialog
# opened, opens Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction
# with boundaries, presses Apply, and checks MeshLab's log (it echoes its log window on
# stderr) for the filter's report and the new layer, then exports the new layer as
# OUT_DIR/result.ply (File > Export Mesh As: tests/gui/same_surface.py compares the float and
# the double MeshLab's). Screenshots of the menu, the dialog and the result are kept in OUT_DIR
# as the test's artefacts.
# Usage: apply_filter_in_meshlab.sh MESHLAB_DISTRIB_DIR PLUGIN_SO [OUT_DIR]
set -euo pipefail
. "$(dirname "$0")/common.sh"
gui_init "$1" "$2" "${3:-out/gui}"

scan="$work/bunny_points.ply"
python3 - "$scan" <<'PY'
# Written as float32 by hand: the float and the double MeshLab then read the same values (a
# double PLY would reach the float one rounded), which tests/gui/same_surface.py also uses.
import os, sys, numpy as np, pymeshlab
ms = pymeshlab.MeshSet()
ms.load_new_mesh(os.path.join(os.path.dirname(pymeshlab.__file__), "tests", "sample_meshes", "bunny10k_textured.obj"))
m = ms.current_mesh()
rows = np.hstack([m.vertex_matrix(), m.vertex_normal_matrix()]).astype("<f4")
with open(sys.argv[1], "wb") as f:
    f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(rows)}\n" +
             "".join(f"property float {c}\n" for c in ("x", "y", "z", "nx", "ny", "nz")) + "end_header\n").encode())
    f.write(rows.tobytes())
PY

gui_start "$scan"
gui_check_loaded
gui_open_filter_dialog
gui_apply_and_close
report=$(gui_surface_report)
faces=$(echo "$report" | gui_surface_field 1)
if [ "$faces" -lt 10000 ]; then echo "FAIL: only $faces faces: $report"; exit 1; fi
gui_export_current "$(cd "$out" && pwd)/result.ply"
echo "MeshLab ran the filter from its menu: $report"
echo "screenshots: $out/filters_menu.png $out/filter_dialog.png $out/result.png; surface: $out/result.ply"
