"""The comparison report: report.html beside its pictures and each method's mesh."""
import html
import re
from importlib import metadata
from pathlib import Path
from typing import Callable

import numpy as np
import pymeshlab

from . import metrics, render
from .table import html_table

PICTURE = "side_by_side.png"
CHART = "metrics.png"


def slug(name: str) -> str:
    """A file name from a method name: 'screened Poisson + density trim' -> 'screened_poisson_density_trim'."""
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")


def _save_mesh(vertices: np.ndarray, faces: np.ndarray, path: Path) -> None:
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces.reshape(-1, 3)))
    ms.save_current_mesh(str(path))


def write_report(comparison, folder: Path, progress: Callable[[str], None] = lambda what: None) -> Path:
    """Writes folder/report.html, its two pictures and a PLY per method; returns the HTML path.

    comparison: a :class:`implicit_boundaries.compare.Comparison` (not imported here: compare
    imports this module). progress(next step) is called before each step.
    """
    folder.mkdir(parents=True, exist_ok=True)
    cloud = comparison.cloud
    progress("rendering")
    panels = []
    for name, surface in comparison.surfaces.items():
        supported = metrics.supported_faces(surface.vertices, surface.faces, cloud.points,
                                            metrics.unsupported_tolerance(cloud))
        panels.append((name, surface.vertices, surface.faces, supported, surface.holes))
        _save_mesh(surface.vertices, surface.faces, folder / f"{slug(name)}.ply")
    render.side_by_side(panels, cloud.points, folder / PICTURE)
    progress("charting")
    render.metrics_chart(comparison.rows, folder / CHART)

    parameters = dict(comparison.sources)
    parameters.update({"samples": len(cloud.points), "bounding-box diagonal": f"{cloud.diagonal:.4g}",
                       "median sample spacing": f"{cloud.spacing:.4g}", "pymeshlab": metadata.version("pymeshlab")})
    parameters.update(comparison.settings.as_dict())
    meshes = " · ".join(f'<a href="{slug(n)}.ply">{html.escape(n)}</a>' for n in comparison.surfaces)
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Implicit reconstruction with boundaries vs screened Poisson</title>
<style>body{{font-family:sans-serif;margin:2em;max-width:1600px}} table{{border-collapse:collapse;margin:1em 0}}
td,th{{border:1px solid #bbb;padding:4px 8px;text-align:left}} th{{background:#eee}} img{{max-width:100%}}</style>
</head><body>
<h1>Implicit reconstruction with boundaries vs screened Poisson</h1>
<p>The same {len(cloud.points)} samples, matched resolution: our {comparison.settings.resolution} cells along the
longest side, Poisson octree depth {comparison.settings.depth}. Distances and areas are relative to the input's
bounding-box diagonal; an area is spurious (missing) when farther than 1% of it from the truth (from the result),
unsupported when farther than 2 sample spacings ({2 * cloud.spacing:.3g}) from every sample.</p>
<h2>Results</h2>
{html_table(comparison.rows)}
<p>Meshes: {meshes}</p>
<h2>Pictures</h2>
<p>Same camera for every method; top row from the side of our boundaries, bottom row from the opposite side.
Red: boundary edges. Blue, translucent: the triangles that would close our kept holes (not part of our output).
Orange: faces farther than 2 sample spacings from every sample (surface the samples do not support).</p>
<img src="{PICTURE}" alt="side by side renders">
<h2>Metrics</h2>
<img src="{CHART}" alt="bar charts of the metrics">
<h2>Parameters</h2>
<table>{"".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>" for k, v in parameters.items())}</table>
</body></html>
"""
    path = folder / "report.html"
    path.write_text(page, encoding="utf-8")
    return path
