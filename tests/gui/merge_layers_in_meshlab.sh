#!/usr/bin/env bash
# Several aligned range scans merged in the MeshLab GUI, in MeshLab 2025.07 or 2025.07d built from the same
# sources: makes two overlapping scans of the unit sphere (a Fibonacci sphere's points, normals
# outward), "upper" z > -0.2 and "lower" z < 0.2, the lower one stored in its own scanner frame
# and placed by its matrix M in a MeshLab .aln project (upper: the identity). Starts MeshLab
# under Xvfb on the project (two layers, each with its matrix), checks that the module stays
# loaded, opens Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction
# with boundaries, ticks "Merge visible layers" (merge_visible_layers), presses Apply and checks
# MeshLab's log: both layers merged, every sample counted, and no boundary loop (the two caps
# make one closed sphere; the current layer alone would leave one loop, so would a layer read
# without its matrix). Screenshots of the dialog as opened, with the box ticked and the result
# are kept in OUT_DIR as the test's artefacts.
# Usage: merge_layers_in_meshlab.sh MESHLAB_DISTRIB_DIR PLUGIN_SO [OUT_DIR]
set -euo pipefail
here=$(dirname "$0")
. "$here/common.sh"
gui_init "$1" "$2" "${3:-out/gui-merge}"

# Prints the number of samples written (both scans).
samples=$(python3 - "$work" "$here/.." <<'PY'
import os, sys
import numpy as np
import pymeshlab
sys.path.insert(0, sys.argv[2])
from shapes import fibonacci_sphere

folder = sys.argv[1]
u = fibonacci_sphere(6000)
upper, lower = u[u[:, 2] > -0.2], u[u[:, 2] < 0.2]
# Where the lower scan's scanner stood: 90 degrees about x, then a translation.
M = np.array([[1.0, 0, 0, 0.3], [0, 0, -1, -0.2], [0, 1, 0, 0.5], [0, 0, 0, 1]])
R, t = M[:3, :3], M[:3, 3]


def save(name, points, normals):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), name)
    ms.save_current_mesh(os.path.join(folder, name + ".ply"), save_vertex_color=False,
                         save_vertex_quality=False, save_vertex_normal=True)


save("upper", upper, upper)
save("lower", (lower - t) @ R, lower @ R)  # inverse(M): R^T (p - t), normals R^T n (row vectors)
with open(os.path.join(folder, "project.aln"), "w") as f:
    f.write("2\n")
    for name, m in (("upper.ply", np.eye(4)), ("lower.ply", M)):
        f.write(name + "\n#\n" + "".join(" ".join("%.17g" % v for v in row) + "\n" for row in m))
    f.write("0\n")
print(len(upper) + len(lower))
PY
)

gui_start "$work/project.aln"
gui_check_loaded
gui_open_filter_dialog
gui_tick_merge_visible_layers
gui_apply_and_close

merged=$(grep -o "Merged [0-9]* visible layers: [0-9]* samples" "$work/meshlab.log") ||
  { echo "FAIL: the filter did not merge the layers: was 'Merge visible layers' ticked? (see $out/merge_ticked.png; MeshLab's log: $out/meshlab.log)"; exit 1; }
if [ "$merged" != "Merged 2 visible layers: $samples samples" ]; then
  echo "FAIL: expected 'Merged 2 visible layers: $samples samples', MeshLab logged '$merged'"; exit 1
fi
report=$(gui_surface_report)
faces=$(echo "$report" | gui_surface_field 1)
loops=$(echo "$report" | gui_surface_field 3)
if [ "$faces" -lt 10000 ]; then echo "FAIL: only $faces faces: $report"; exit 1; fi
if [ "$loops" -ne 0 ]; then
  echo "FAIL: the merged caps should make a closed sphere (0 boundary loops), got $loops: $report"
  echo "(a layer's matrix not applied, or only one layer used; MeshLab's log: $out/meshlab.log)"; exit 1
fi
echo "MeshLab merged both scans of the .aln project from its dialog: $merged; $report"
echo "screenshots: $out/filter_dialog.png $out/merge_ticked.png $out/result.png"
