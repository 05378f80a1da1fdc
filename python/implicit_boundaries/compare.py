"""Side by side with MeshLab's screened Poisson: the same point cloud, matched resolution.

    table = implicit_boundaries.compare("scan.ply", ground_truth="truth.ply", report="out/report")
    for row in table.rows: print(row)

This module runs the methods of :mod:`.methods` on one :class:`~.cloud.Cloud`, measures each
result with :func:`.metrics.measure`, and writes the report (:mod:`.report`) when asked.
"""
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Union

import numpy as np

from . import metrics
from .cloud import Cloud, read_cloud, read_mesh
from .methods import METHODS, Method, Settings, Surface, poisson_depth
from .table import Row, markdown

Progress = Callable[[int, int, str], None]  # (steps done, steps in all, what comes next)


@dataclass
class Comparison:
    """What :func:`compare` measured.

    rows: one dict per method (see :data:`.table.COLUMNS` for the keys and their meaning; truth-based
    keys are missing without a ground truth); surfaces: each method's output by name;
    settings: what the methods ran with (resolution and depth resolved); sources: where the
    input and the ground truth came from; report: report.html, when one was written.
    """
    rows: List[Row]
    surfaces: Dict[str, Surface]
    cloud: Cloud
    settings: Settings
    sources: Dict[str, str] = field(default_factory=dict)
    report: Optional[Path] = None

    def table(self) -> str:
        """The rows as a Markdown table."""
        return markdown(self.rows)


def _as_cloud(input) -> Cloud:
    if isinstance(input, Cloud):
        return input
    if isinstance(input, (str, Path)):
        return read_cloud(input)
    return Cloud(*(np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 3) for a in input))


def compare(input, ground_truth=None, *, resolution: int = 0, depth: Optional[int] = None,
            trim_quantile: float = 0.05, poisson_threads: int = 1, params: Optional[Dict[str, object]] = None,
            methods: Optional[Dict[str, Method]] = None,
            report: Union[str, Path, None] = None, samples: int = 20000,
            progress: Optional[Progress] = None) -> Comparison:
    """Runs each method on the same point cloud and measures the results.

    input: a file pymeshlab reads (its vertices and normals are the samples), a
    :class:`Cloud`, or a (points, normals) pair of (n, 3) arrays. ground_truth: a mesh file or
    (vertices, faces) arrays; adds chamfer, spurious and missing area, loops found and boundary
    distance. resolution, depth, trim_quantile, poisson_threads, params: see :class:`Settings`
    (poisson_threads is 1 by default: pymeshlab's OpenMP threads spin when the cores are
    shared, which took 2 threads from 2 s to 50-90 s on a small bunny). methods: name ->
    function, default :data:`METHODS`. report: a folder to write report.html, the pictures and
    each method's mesh into. samples: area samples per mesh for the surface distances.
    progress(done, total, next step) is called before each step.
    """
    cloud = _as_cloud(input)
    truth = read_mesh(ground_truth) if isinstance(ground_truth, (str, Path)) else ground_truth
    if not 0 <= trim_quantile < 1:
        raise ValueError(f"trim quantile {trim_quantile} is outside [0, 1)")
    methods = METHODS if methods is None else methods
    settings = Settings(resolution, depth, trim_quantile, poisson_threads, dict(params or {}))
    steps = 2 * len(methods) + (2 if report is not None else 0)
    tell = progress or (lambda done, total, what: None)

    surfaces: Dict[str, Surface] = {}
    rows: List[Row] = []
    for name, method in methods.items():
        tell(len(surfaces), steps, f"running {name}")
        start = time.perf_counter()
        surface = method(cloud, settings)
        surface.info["seconds"] = time.perf_counter() - start
        surfaces[name] = surface
        if "resolution" in surface.info and settings.resolution == 0:
            settings.resolution = int(surface.info["resolution"])
        if settings.depth is None and settings.resolution:
            settings.depth = poisson_depth(settings.resolution)

    truth_loops, loop_tolerance = None, 0.0
    if truth is not None:
        truth = (np.asarray(truth[0], dtype=np.float64), np.asarray(truth[1], dtype=np.int64))
        truth_loops = [truth[0][h] for h in metrics.boundary_vertex_sets(truth[1], len(truth[0]))]
        filter_run = next((s.info for s in surfaces.values() if "sample_spacing" in s.info), None)
        # As the benchmark: a loop is on a true boundary within a few sample spacings and cells.
        loop_tolerance = 2.5 * filter_run["sample_spacing"] + 2 * filter_run["cell_size"] if filter_run \
            else 0.01 * cloud.diagonal
    for k, (name, surface) in enumerate(surfaces.items()):
        tell(len(methods) + k, steps, f"measuring {name}")
        row = {"method": name, "seconds": surface.info["seconds"]}
        row.update(metrics.measure(surface.vertices, surface.faces, cloud, truth, truth_loops, loop_tolerance, samples))
        rows.append(row)

    sources = {"input": str(input) if isinstance(input, (str, Path)) else f"{len(cloud.points)} points given as arrays",
               "ground truth": "none" if truth is None else str(ground_truth)
               if isinstance(ground_truth, (str, Path)) else "given as arrays"}
    result = Comparison(rows, surfaces, cloud, settings, sources)
    if report is not None:
        from .report import write_report  # pyvista and matplotlib only when pictures are asked for
        stage = iter(range(steps - 2, steps))
        result.report = write_report(result, Path(report), lambda what: tell(next(stage), steps, what))
        tell(steps, steps, "done")
    return result
