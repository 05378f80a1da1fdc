#!/usr/bin/env bash
# The merged range scans through the MeshLab GUI, as a user does it (issue: the MeshLab scanning
# workflow): writes a MeshLab .aln project for the scans of a Stanford .conf (default: the 9 bunny
# scans of ../shared/data), opens it in MeshLab (float 2025.07 by default, or the folder given),
# runs the filter with "Merge visible layers" from its dialog, exports the surface and measures it
# against the zippered truth with bench/merged.py's yardsticks.
# Usage: bench/merged_gui.sh [CONF] [MESHLAB_DISTRIB_DIR PLUGIN_SO]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
conf=$(realpath "${1:-$root/../shared/data/bunny_scans/bun.conf}")
distrib=${2:-$("$root/.ci/meshlab-gui" float)}
plugin=${3:-$root/build-float/meshlab-2025.07/libfilter_implicit_boundaries.so}
. "$root/tests/gui/common.sh"
gui_init "$distrib" "$plugin" "$root/out/merged-gui"

# MeshLab reads an .aln's file names relative to its folder: the scans are linked beside it.
python3 - "$conf" "$work" <<'PY'
import os, sys
from implicit_boundaries.alignment import read_alignment
scans = read_alignment(sys.argv[1])
with open(os.path.join(sys.argv[2], "scans.aln"), "w") as f:
    f.write(f"{len(scans)}\n")
    for path, m in scans:
        os.symlink(path.resolve(), os.path.join(sys.argv[2], path.name))
        f.write(f"{path.name}\n#\n" + "".join(" ".join("%.17g" % v for v in row) + "\n" for row in m))
    f.write("0\n")
PY

gui_start "$work/scans.aln"
sleep 10  # nine range scans to load
gui_check_loaded
gui_open_filter_dialog
gui_tick_merge_visible_layers
gui_apply_and_close
grep -o "Merged [0-9]* visible layers: [0-9]* samples" "$work/meshlab.log" ||
  { echo "FAIL: the layers were not merged (MeshLab's log: $out/meshlab.log)"; exit 1; }
gui_surface_report
gui_export_current "$out/result.ply"
python3 "$root/bench/merged.py" "$conf" --surface "$out/result.ply"
