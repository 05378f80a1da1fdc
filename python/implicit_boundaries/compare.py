"""Side by side with MeshLab's screened Poisson: the same point cloud, matched resolution.

    table = implicit_boundaries.compare("scan.ply", ground_truth="truth.ply", report="out/report")
    for row in table.rows: print(row)

Each method is a function ``(cloud, settings) -> Surface`` in :data:`METHODS`; adding a
method there adds a row, a picture and a bar to every comparison.
"""
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree

from . import metrics
from .poisson import poisson_with_boundaries
from ._plugin import apply, load

Progress = Callable[[int, int, str], None]  # (steps done, steps in all, what comes next)


@dataclass
class Cloud:
    """The input: (n, 3) points and (n, 3) unit normals (oriented outwards)."""
    points: np.ndarray
    normals: np.ndarray

    @property
    def diagonal(self) -> float:
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0)))

    @property
    def spacing(self) -> float:
        """Median distance from a sample to its nearest other sample."""
        return float(np.median(cKDTree(self.points).query(self.points, k=2)[0][:, 1]))


@dataclass
class Settings:
    """What every method is run with.

    resolution: our marching cubes cells along the longest side (0: the filter chooses, and
    the comparison then uses the resolution it chose); depth: screened Poisson's octree depth
    (None: the one whose 2^depth is nearest our resolution, 8 without one); trim_quantile: Poisson vertices
    whose density is below this quantile are removed; poisson_threads: screened Poisson's
    threads; params: our filter's other parameters by their pymeshlab names.
    """
    resolution: int = 0
    depth: Optional[int] = None
    trim_quantile: float = 0.05
    poisson_threads: int = 1
    params: Dict[str, object] = field(default_factory=dict)


@dataclass
class Surface:
    """A method's output: (m, 3) vertices, (f, 3) faces; holes: the triangles that would close
    its kept holes, as (vertices, faces), when the method gives them (pictures show them
    tinted); info: numbers the method reports (ours: the filter's result dictionary)."""
    vertices: np.ndarray
    faces: np.ndarray
    holes: Optional[Tuple[np.ndarray, np.ndarray]] = None
    info: Dict[str, object] = field(default_factory=dict)


def _meshset(cloud: Cloud) -> pymeshlab.MeshSet:
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=cloud.points, v_normals_matrix=cloud.normals), "points")
    return ms


def _copy(mesh: pymeshlab.Mesh) -> Tuple[np.ndarray, np.ndarray]:
    mesh.compact()
    return mesh.vertex_matrix().copy(), mesh.face_matrix().copy()


def run_ours(cloud: Cloud, settings: Settings) -> Surface:
    """Our filter, its kept holes in their own layer."""
    load()
    ms = _meshset(cloud)
    info = dict(apply(ms, resolution=settings.resolution, hole_layer=True, **settings.params))
    vertices, faces = _copy(ms.mesh(1))
    holes = _copy(ms.mesh(2)) if ms.mesh_number() > 2 else None
    return Surface(vertices, faces, holes, info)


def poisson_depth(resolution: int) -> int:
    """The octree depth whose 2^depth is nearest `resolution` cells (in log scale)."""
    return int(round(np.log2(resolution)))


def _poisson(cloud: Cloud, settings: Settings) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    ms = _meshset(cloud)
    depth = settings.depth or (poisson_depth(settings.resolution) if settings.resolution else 8)
    ms.generate_surface_reconstruction_screened_poisson(depth=depth, threads=settings.poisson_threads)
    mesh = ms.current_mesh()
    # Poisson stores the sample density around each vertex as its quality.
    density = mesh.vertex_scalar_array().copy()
    return mesh.vertex_matrix().copy(), mesh.face_matrix().copy(), density


def density_trim(faces: np.ndarray, density: np.ndarray, quantile: float) -> np.ndarray:
    """The faces of the (f, 3) `faces` none of whose vertices has a `density` (per vertex)
    below its `quantile`: the usual clean-up of screened Poisson (deleting those vertices)."""
    return faces[np.all(density[faces] >= np.quantile(density, quantile), axis=1)]


def run_poisson(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson (closed)."""
    vertices, faces, _ = _poisson(cloud, settings)
    return Surface(vertices, faces)


def run_poisson_trimmed(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson, then its least dense vertices removed."""
    vertices, faces, density = _poisson(cloud, settings)
    return Surface(vertices, density_trim(faces, density, settings.trim_quantile))


def run_poisson_with_boundaries(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson surface as our filter's implicit function: Poisson's
    surface where the samples are, with the scan's boundaries."""
    ms = _meshset(cloud)
    depth = settings.depth or (poisson_depth(settings.resolution) if settings.resolution else 8)
    info = dict(poisson_with_boundaries(ms, depth=depth, poisson_threads=settings.poisson_threads,
                                        resolution=settings.resolution, hole_layer=True, **settings.params))
    vertices, faces = _copy(ms.mesh(2))
    holes = _copy(ms.mesh(3)) if ms.mesh_number() > 3 else None
    return Surface(vertices, faces, holes, info)


# Ours first: the others run at the resolution it chose.
METHODS: Dict[str, Callable[[Cloud, Settings], Surface]] = {
    "ours": run_ours,
    "screened Poisson": run_poisson,
    "screened Poisson + density trim": run_poisson_trimmed,
    "screened Poisson + our boundaries": run_poisson_with_boundaries,
}


@dataclass
class Comparison:
    """What :func:`compare` measured.

    rows: one dict per method (see :data:`COLUMNS` for the keys and their meaning; truth-based
    keys are missing without a ground truth); surfaces: each method's output by name;
    settings: what the methods ran with (resolution and depth resolved); sources: where the
    input and the ground truth came from; report: report.html, when one was written.
    """
    rows: List[Dict[str, object]]
    surfaces: Dict[str, Surface]
    cloud: Cloud
    settings: Settings
    sources: Dict[str, str] = field(default_factory=dict)
    report: Optional[Path] = None

    def table(self) -> str:
        """The rows as a Markdown table."""
        keys = [k for k in COLUMNS if any(k in row for row in self.rows)]
        lines = ["| " + " | ".join(COLUMNS[k] for k in keys) + " |", "|" + "---|" * len(keys)]
        lines += ["| " + " | ".join(format_value(row.get(k)) for k in keys) + " |" for row in self.rows]
        return "\n".join(lines)


COLUMNS = {
    "method": "method",
    "seconds": "seconds",
    "faces": "faces",
    "loops": "boundary loops",
    "loop_sizes": "loop sizes (edges, largest first)",
    "unsupported_pct": "unsupported area % (>2 spacings from every sample)",
    "loops_found": "true boundaries found",
    "chamfer_pct": "chamfer (% diag)",
    "spurious_pct": "spurious area %",
    "missing_pct": "missing area %",
    "boundary_distance_pct": "boundary distance (% diag)",
}


def format_value(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return "n/a" if np.isnan(value) else f"{value:.3g}"
    if isinstance(value, list):
        shown = ", ".join(str(v) for v in value[:8])
        return shown + (f", … ({len(value)} in all)" if len(value) > 8 else "") if value else "none"
    return str(value)


def read_cloud(path: Union[str, Path]) -> Cloud:
    """The vertices and normals of any file pymeshlab reads (faces ignored); normals are
    estimated (10 neighbours) when the file has none."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    mesh = ms.current_mesh()
    mesh.compact()
    if mesh.vertex_number() == 0:
        raise ValueError(f"{path}: no vertices")
    if not np.any(mesh.vertex_normal_matrix()):
        ms.compute_normal_for_point_clouds(k=10)
        mesh = ms.current_mesh()
    return Cloud(mesh.vertex_matrix().copy(), mesh.vertex_normal_matrix().copy())


def read_mesh(path: Union[str, Path]) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of a triangle mesh file pymeshlab reads."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    vertices, faces = _copy(ms.current_mesh())
    if len(faces) == 0:
        raise ValueError(f"{path}: the ground truth has no faces")
    return vertices, faces


def supported_faces(surface: Surface, cloud: Cloud, tolerance: float) -> np.ndarray:
    """(f,) bool: the faces with a point within `tolerance` of some sample (centroid or a vertex)."""
    if len(surface.faces) == 0:
        return np.zeros(0, dtype=bool)
    tree = cKDTree(cloud.points)
    tri = surface.vertices[surface.faces]
    near = np.stack([tree.query(p)[0] for p in [tri.mean(axis=1), tri[:, 0], tri[:, 1], tri[:, 2]]])
    return near.min(axis=0) <= tolerance


def unsupported_tolerance(cloud: Cloud) -> float:
    """Faces farther than this from every sample are unsupported: 2 sample spacings."""
    return 2 * cloud.spacing


def _boundary_loops(surface: Surface) -> List[np.ndarray]:
    """Vertex indices of each boundary component, largest first."""
    loops = metrics.boundary_vertex_sets(surface.faces, len(surface.vertices))
    return sorted(loops, key=len, reverse=True)


def measure(surface: Surface, cloud: Cloud, truth=None, truth_loops=None, loop_tolerance: float = 0.0,
            samples: int = 20000) -> Dict[str, object]:
    """The row of one surface: faces, boundary loops, unsupported area (farther than 2 sample
    spacings from every sample: what the method made up) and, with a ground truth
    ((vertices, faces) and its boundary point arrays), the DESIGN.md section 5 yardsticks.
    Distances are % of the input's bounding-box diagonal; their area tolerance is 1% of it."""
    diagonal = cloud.diagonal
    loops = _boundary_loops(surface)
    row: Dict[str, object] = {"faces": int(len(surface.faces)), "loops": len(loops),
                              "loop_sizes": [int(len(loop)) for loop in loops]}
    areas = metrics.triangle_areas(surface.vertices, surface.faces)
    supported = supported_faces(surface, cloud, unsupported_tolerance(cloud))
    row["unsupported_pct"] = 100 * float(areas[~supported].sum() / areas.sum()) if len(areas) else 0.0
    if truth is not None:
        points = [surface.vertices[loop] for loop in loops]
        found, _ = metrics.loops_found(truth_loops, points, loop_tolerance)
        row["loops_found"] = f"{found}/{len(truth_loops)}"
        d = metrics.surface_distances(surface.vertices, surface.faces, *truth, 0.01 * diagonal, samples)
        row["chamfer_pct"] = 100 * d["chamfer"] / diagonal
        row["spurious_pct"] = 100 * d["spurious"]
        row["missing_pct"] = 100 * d["missing"]
        # Between the boundary curves, sampled every 0.05% of the diagonal (within 0.025%).
        curves = [metrics.boundary_curves(*mesh, 0.0005 * diagonal) for mesh in (truth, (surface.vertices, surface.faces))]
        row["boundary_distance_pct"] = 100 * metrics.boundary_distance(*curves) / diagonal
    return row


def compare(input, ground_truth=None, *, resolution: int = 0, depth: Optional[int] = None,
            trim_quantile: float = 0.05, poisson_threads: int = 1, params: Optional[Dict[str, object]] = None,
            methods: Optional[Dict[str, Callable[[Cloud, Settings], Surface]]] = None,
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
    cloud = input if isinstance(input, Cloud) else read_cloud(input) if isinstance(input, (str, Path)) \
        else Cloud(*(np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 3) for a in input))
    truth = read_mesh(ground_truth) if isinstance(ground_truth, (str, Path)) else ground_truth
    if not 0 <= trim_quantile < 1:
        raise ValueError(f"trim quantile {trim_quantile} is outside [0, 1)")
    methods = METHODS if methods is None else methods
    settings = Settings(resolution, depth, trim_quantile, poisson_threads, dict(params or {}))
    steps = 2 * len(methods) + (2 if report is not None else 0)
    tell = progress or (lambda done, total, what: None)

    surfaces: Dict[str, Surface] = {}
    rows: List[Dict[str, object]] = []
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
        ours = next((s.info for s in surfaces.values() if "sample_spacing" in s.info), None)
        # As the benchmark: a loop is on a true boundary within a few sample spacings and cells.
        loop_tolerance = 2.5 * ours["sample_spacing"] + 2 * ours["cell_size"] if ours else 0.01 * cloud.diagonal
    for k, (name, surface) in enumerate(surfaces.items()):
        tell(len(methods) + k, steps, f"measuring {name}")
        row = {"method": name, "seconds": surface.info["seconds"]}
        row.update(measure(surface, cloud, truth, truth_loops, loop_tolerance, samples))
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


def settings_dict(settings: Settings) -> Dict[str, object]:
    """The settings as a flat dict, for the report."""
    flat = asdict(settings)
    flat.update({f"ours: {k}": v for k, v in flat.pop("params").items()})
    return flat
