"""Pictures of a comparison: off-screen pyvista renders side by side, and a bar chart of the metrics."""
import os
from pathlib import Path
from typing import Dict, List, Sequence, Tuple

# Without an X display, VTK's wheels try X first and warn; go straight to EGL (Mesa's
# software renderer on a headless machine). Must be set before VTK creates a window.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np
import pyvista as pv

from . import metrics

SURFACE = "#d8c9a8"      # faces near the samples
UNSUPPORTED = "#e07b39"  # faces farther than 2 sample spacings from every sample
HOLES = "#3d85c6"        # our hole triangles (a separate layer, not part of the output)
BOUNDARY = "#c0162c"
PANEL = (520, 480)       # pixels per view
LEGEND_ROW = 0.2         # height of the legend strip, in views


def _polydata(vertices: np.ndarray, faces: np.ndarray) -> pv.PolyData:
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    return pv.PolyData(np.asarray(vertices, dtype=np.float64), cells)


def _edges(vertices: np.ndarray, edges: np.ndarray) -> pv.PolyData:
    lines = np.hstack([np.full((len(edges), 1), 2), edges]).ravel()
    return pv.PolyData(np.asarray(vertices, dtype=np.float64), lines=lines)


def view_directions(points: np.ndarray, boundary: np.ndarray) -> List[np.ndarray]:
    """Two unit directions from the centre of the (n, 3) points towards the eye: one facing the
    side where the (k, 3) boundary points are (a corner view when there are none), and the
    opposite one."""
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    corner = np.array([1.0, 0.6, 0.8]) / np.linalg.norm([1.0, 0.6, 0.8])
    side = boundary.mean(axis=0) - centre if len(boundary) else np.zeros(3)
    # Tilted towards a corner so the boundary side is seen in perspective, not edge-on.
    d = side / np.linalg.norm(side) + 0.7 * corner if np.linalg.norm(side) > 1e-12 else corner
    d /= np.linalg.norm(d)
    return [d, -d]


def _up(direction: np.ndarray) -> np.ndarray:
    """y (scans are often y-up), or z when looking along y; made perpendicular to the direction."""
    up = np.array([0.0, 1.0, 0.0]) if abs(direction[1]) < 0.8 else np.array([0.0, 0.0, 1.0])
    up = up - (up @ direction) * direction
    return up / np.linalg.norm(up)


def _frame(plotter: pv.Plotter, shown: np.ndarray, direction: np.ndarray, aspect: float) -> None:
    """Points the active camera along -direction with a parallel projection that just holds the
    (k, 3) points `shown` (of every panel): the same framing in every panel, whatever the shape."""
    up = _up(direction)
    right = np.cross(up, direction)
    x, y = shown @ right, shown @ up
    centre = shown.mean(axis=0)
    centre = centre + right * (0.5 * (x.max() + x.min()) - centre @ right) + up * (0.5 * (y.max() + y.min()) - centre @ up)
    reach = float(np.ptp(shown @ direction)) + float(np.linalg.norm(np.ptp(shown, axis=0)))
    camera = plotter.camera
    camera.enable_parallel_projection()
    camera.focal_point = centre
    camera.position = centre + reach * direction
    camera.up = up
    # Room for the title above, 4% margin elsewhere.
    camera.parallel_scale = 1.08 * max(0.5 * np.ptp(y) / 0.88, 0.5 * np.ptp(x) / aspect)
    camera.clipping_range = (1e-3 * reach, 3 * reach)


def side_by_side(panels: Sequence[Tuple[str, np.ndarray, np.ndarray, np.ndarray, object]],
                 points: np.ndarray, path: Path) -> Path:
    """Writes one PNG: a column per method, a row per view, the same camera everywhere.

    panels: (title, vertices (m, 3), faces (f, 3), supported (f,) bool, holes) per method,
    holes being (vertices, faces) of the triangles closing the kept holes, or None.
    points: (n, 3) input samples (they set the framing).
    """
    boundaries = [(v, metrics.boundary_edges(f)) for _, v, f, _, _ in panels]
    first = next((v[np.unique(e)] for v, e in boundaries if len(e)), np.zeros((0, 3)))
    directions = view_directions(points, first)
    shown = np.concatenate([points] + [v[np.unique(f)] for _, v, f, _, _ in panels if len(f)]
                           + [h[0][np.unique(h[1])] for *_, h in panels if h is not None and len(h[1])])

    # A row per view, then a strip across all columns for the legend.
    rows = len(directions)
    plotter = pv.Plotter(shape=(rows + 1, len(panels)), row_weights=[1] * rows + [LEGEND_ROW],
                         groups=[(rows, np.s_[:])], off_screen=True, border=False,
                         window_size=(PANEL[0] * len(panels), int(PANEL[1] * (rows + LEGEND_ROW))))
    plotter.set_background("white")
    for row, direction in enumerate(directions):
        for column, ((title, vertices, faces, supported, holes), (_, edges)) in enumerate(zip(panels, boundaries)):
            plotter.subplot(row, column)
            if len(faces):
                mesh = _polydata(vertices, faces)
                mesh.cell_data["supported"] = supported.astype(np.uint8)
                plotter.add_mesh(mesh, scalars="supported", cmap=[UNSUPPORTED, SURFACE], clim=[0, 1],
                                 show_scalar_bar=False, smooth_shading=False)
            if holes is not None and len(holes[1]):
                plotter.add_mesh(_polydata(*holes), color=HOLES, opacity=0.55)
            if len(edges):
                plotter.add_mesh(_edges(vertices, edges), color=BOUNDARY, line_width=5, render_lines_as_tubes=True)
            if row == 0:
                loops = len(metrics.boundary_vertex_sets(faces, len(vertices)))
                plotter.add_text(f"{title}\n{len(faces)} faces, {loops} boundary loops", font_size=11, color="black")
            _frame(plotter, shown, direction, PANEL[0] / PANEL[1])
    plotter.subplot(rows, 0)
    plotter.add_legend([["our hole triangles (a separate layer, not in the output)", HOLES],
                        ["faces farther than 2 sample spacings from every sample", UNSUPPORTED],
                        ["boundary edges", BOUNDARY]], bcolor="white", border=False, size=(0.34, 0.7),
                       loc="center", face="rectangle")
    plotter.screenshot(str(path))
    plotter.close()
    return path


BARS = {"seconds": "seconds", "faces": "faces", "loops": "boundary loops",
        "unsupported_pct": "unsupported area %", "chamfer_pct": "chamfer (% diag)",
        "spurious_pct": "spurious area %", "missing_pct": "missing area %",
        "boundary_distance_pct": "boundary distance (% diag)"}


def metrics_chart(rows: Sequence[Dict[str, object]], path: Path) -> Path:
    """Writes a PNG with one bar chart per numeric column of the rows (a bar per method)."""
    import matplotlib
    matplotlib.use("Agg")  # files only, no display
    import matplotlib.pyplot as plt

    keys = [k for k in BARS if any(k in row for row in rows)]
    names = [str(row["method"]) for row in rows]
    colours = plt.get_cmap("tab10").colors
    columns = min(4, len(keys))
    n_rows = -(-len(keys) // columns)
    fig, axes = plt.subplots(n_rows, columns, figsize=(3.6 * columns, 2.9 * n_rows), squeeze=False)
    for ax, key in zip(axes.ravel(), keys):
        values = np.array([float(row.get(key, np.nan)) for row in rows])
        shown = np.nan_to_num(values, nan=0.0)
        bars = ax.bar(range(len(rows)), shown, color=colours[:len(rows)])
        for bar, value in zip(bars, values):
            label = "n/a" if np.isnan(value) else f"{value:.0f}" if value == round(value) else f"{value:.3g}"
            ax.annotate(label, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom",
                        fontsize=8, xytext=(0, 2), textcoords="offset points")
        ax.set_title(BARS[key], fontsize=10)
        ax.set_xticks([])
        ax.margins(y=0.18)
        ax.spines[["top", "right"]].set_visible(False)
    for ax in axes.ravel()[len(keys):]:
        ax.axis("off")
    fig.legend([plt.Rectangle((0, 0), 1, 1, color=c) for c in colours[:len(rows)]], names,
               loc="lower center", ncol=len(rows), frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
