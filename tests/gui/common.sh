# Steps shared by the GUI tests, sourced by them (not run on its own): MeshLab 2025.07 (float)
# or 2025.07d (double), whichever folder is given, under
# Xvfb, driven with xdotool. No window manager runs, so windows sit where MeshLab puts them and
# menus are opened with the mouse. MeshLab echoes its log window on stderr: $work/meshlab.log.

# gui_init DISTRIB PLUGIN_SO OUT_DIR: installs the module into MeshLab's plugins/ folder (an
# empty PLUGIN_SO: removes it from there), makes OUT_DIR and a temporary $work folder (removed
# on exit, with the processes started here).
gui_init() {
  distrib=$1
  out=$3
  mkdir -p "$out"
  if [ -n "$2" ]; then cp "$2" "$distrib/plugins/"; else rm -f "$distrib/plugins/libfilter_implicit_boundaries.so"; fi
  work=$(mktemp -d)
  trap gui_cleanup EXIT
}

gui_cleanup() {
  kill "${meshlab:-}" 2>/dev/null || true
  kill "${xvfb:-}" 2>/dev/null || true
  rm -rf "$work"
}

# gui_start FILE: Xvfb on a free display, then MeshLab on FILE (a mesh, or a project such as
# .aln); answers the first-start dialog, waits for the main window ($window) and lets the file
# load. $meshlab is MeshLab's pid.
gui_start() {
  display=":$((90 + RANDOM % 400))"
  Xvfb "$display" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
  xvfb=$!
  export DISPLAY=$display XDG_CONFIG_HOME="$work/config" HOME="$work"
  sleep 1
  "$distrib/meshlab" "$1" >"$work/meshlab.log" 2>&1 &
  meshlab=$!
  # The first start asks "Send Anonymous Statistics?" before showing the main window: answer No.
  if timeout 60 xdotool search --sync --name '^Send Anonymous Statistics' >/dev/null; then
    sleep 1; xdotool key alt+n
  fi
  gui_wait_for_window
}

# gui_restart FILE: closes MeshLab and starts it again on FILE, same display and settings
# (the first-start question was answered).
gui_restart() {
  kill "$meshlab"; wait "$meshlab" 2>/dev/null || true
  "$distrib/meshlab" "$1" >"$work/meshlab.log" 2>&1 &
  meshlab=$!
  gui_wait_for_window
}

gui_wait_for_window() {
  window=$(timeout 60 xdotool search --sync --onlyvisible --name '^MeshLab 20' | head -n1)
  sleep 5  # let the file finish loading
}

# gui_check_loaded: the module stays mapped in the MeshLab process (MeshLab unloads plugins
# that fail its checks) and no error or warning dialog opened.
gui_check_loaded() {
  if ! grep -q libfilter_implicit_boundaries.so "/proc/$meshlab/maps"; then
    echo "FAIL: MeshLab did not keep libfilter_implicit_boundaries.so loaded"; cat "$work/meshlab.log"; exit 1
  fi
  local w name
  for w in $(xdotool search --onlyvisible --name '.' 2>/dev/null); do
    [ "$w" = "$window" ] && continue
    name=$(xdotool getwindowname "$w" 2>/dev/null || true)
    case "$name" in *rror*|*arning*|*nable*) echo "FAIL: MeshLab showed a dialog: $name"; cat "$work/meshlab.log"; exit 1;; esac
  done
}

# gui_open_filter_dialog: Filters > Remeshing, Simplification and Reconstruction > Implicit
# reconstruction with boundaries; screenshots filters_menu.png and filter_dialog.png. Sets
# $dialog and its geometry (X, Y, WIDTH, HEIGHT).
gui_open_filter_dialog() {
  # The main window sits at (0,0) in its default size, "Filters" is the third menu and
  # "Remeshing, Simplification and Reconstruction" its sixth row.
  xdotool mousemove 120 10 click 1; sleep 1
  xdotool mousemove 200 161; sleep 0.5; xdotool mousemove 210 161 click 1; sleep 2
  import -window root "$out/filters_menu.png"
  # Our filter is the third row of that submenu; its dialog opens over the main window.
  xdotool mousemove 600 211; sleep 0.5; xdotool mousemove 666 211 click 1; sleep 3
  import -window root "$out/filter_dialog.png"
  dialog=$(xdotool search --onlyvisible --name '^Implicit reconstruction with boundaries$' | head -n1) ||
    { echo "FAIL: the filter's dialog did not open"; exit 1; }
  eval "$(xdotool getwindowgeometry --shell "$dialog")"
}

# gui_tick_merge_visible_layers: ticks the open dialog's "Merge visible layers" box; screenshot
# merge_ticked.png. MeshLab gives the dialog's Apply button the keyboard focus. The focus chain
# then runs through the parameters' scroll area and the "Copy PyMeshLab call" button (both made
# before the parameter widgets) to the parameters in order: Resolution, Implicit function,
# Implicit mesh layer, SODS occupancy, Min boundary edges, Boundary smoothing, Merge visible
# layers. So the ninth Tab reaches the check box, whatever the fonts and the description's
# height; space ticks it. (A wrong count ticks another box or none: check the log's "Merged".)
gui_tick_merge_visible_layers() {
  xdotool windowfocus --sync "$dialog"; sleep 0.5
  for _ in $(seq 9); do xdotool key Tab; sleep 0.2; done
  xdotool key space; sleep 1
  import -window root "$out/merge_ticked.png"
}

# gui_apply_and_close: presses the dialog's Apply, waits (up to 2 minutes) for MeshLab to log
# the filter as applied, presses Close; screenshot result.png, MeshLab's log in OUT_DIR.
gui_apply_and_close() {
  # The buttons sit in the dialog's bottom row: Close on the left half, Apply on the right.
  local row=$((Y + HEIGHT - 21))
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
}

# gui_export_current FILE: File > Export Mesh As..., FILE typed into the file dialog, the saving
# options accepted as they are (binary PLY); fails when FILE was not written.
gui_export_current() {
  rm -f "$1"  # else MeshLab asks whether to overwrite it
  # "Export Mesh As..." is the File menu's ninth row.
  xdotool mousemove 35 10 click 1; sleep 1
  xdotool mousemove 100 211; sleep 0.5; xdotool mousemove 105 211 click 1
  timeout 30 xdotool search --sync --onlyvisible --name '^Save .* Layer$' >/dev/null ||
    { echo "FAIL: the export dialog did not open"; exit 1; }
  sleep 1; xdotool type --delay 20 "$1"; xdotool key Return
  timeout 30 xdotool search --sync --onlyvisible --name '^Choose Saving Options' >/dev/null ||
    { echo "FAIL: the saving options did not open"; exit 1; }
  sleep 1; xdotool key Return; sleep 2
  [ -s "$1" ] || { echo "FAIL: MeshLab did not write $1"; exit 1; }
}

# gui_surface_report: the filter's "Surface: F faces, V vertices; L boundary loops kept ..."
# line from MeshLab's log (fails when there is none); gui_surface_field N picks a number of it
# (1 faces, 2 vertices, 3 loops).
gui_surface_report() {
  grep -o "Surface: [0-9]* faces.*boundary loops kept[^;]*" "$work/meshlab.log" ||
    { echo "FAIL: the filter made no surface (MeshLab's log: $out/meshlab.log)" >&2; exit 1; }
}
gui_surface_field() {
  sed -n "s/^Surface: \([0-9]*\) faces, \([0-9]*\) vertices; \([0-9]*\) boundary loops kept.*/\\$1/p"
}
