"""Measures on meshes with boundaries, for tests, benchmarks and comparisons: boundary loops
and curves, distances between meshes, and :func:`measure`, a comparison's row of one surface."""
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .cloud import Cloud


def _boundary_components(faces: np.ndarray, n_vertices: int) -> Tuple[np.ndarray, np.ndarray]:
    """The boundary edges ((b, 2) vertex pairs) and, per edge, the label of its connected component."""
    border = boundary_edges(faces)
    if len(border) == 0:
        return border, np.zeros(0, dtype=np.int64)
    graph = sp.coo_matrix((np.ones(len(border)), (border[:, 0], border[:, 1])), shape=(n_vertices, n_vertices))
    _, label = connected_components(graph, directed=False)
    return border, label[border[:, 0]]


def boundary_vertex_sets(faces: np.ndarray, n_vertices: int) -> List[np.ndarray]:
    """Vertex indices of each boundary component of a triangle mesh (edges used by one face).

    faces: (f, 3) vertex indices. Returns one sorted index array per component.
    """
    border, component = _boundary_components(faces, n_vertices)
    return [np.unique(border[component == c]) for c in np.unique(component)]


def boundary_curves(vertices: np.ndarray, faces: np.ndarray, step: float) -> List[np.ndarray]:
    """Each boundary component of a triangle mesh as a curve: points along its edges at most
    `step` apart, the edges' end points included. A distance between boundaries measured on
    these does not depend on how finely each mesh happens to be divided along them (a coarse
    true boundary's vertices can be far apart where the curve itself is close).

    vertices: (n, 3); faces: (f, 3). Returns one (k, 3) point array per component.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    border, component = _boundary_components(faces, len(vertices))
    curves = []
    for c in np.unique(component):
        a, b = vertices[border[component == c, 0]], vertices[border[component == c, 1]]
        pieces = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / step)).astype(np.int64)
        edge = np.repeat(np.arange(len(a)), pieces)
        first = np.repeat(np.cumsum(pieces) - pieces, pieces)
        t = (np.arange(len(edge)) - first) / pieces[edge]
        curves.append(a[edge] + t[:, None] * (b - a)[edge])
    return curves


def match_loops(true_points: Sequence[np.ndarray], loops: Sequence[np.ndarray], tolerance: float) -> Dict[int, List[int]]:
    """Assigns each found loop (a (k, 3) point array) to the true boundary (a (m, 3) point array)
    nearest to it, when its points are on average within `tolerance` of that boundary.

    Returns {true index: [indices of the loops assigned to it]}; unassigned loops are spurious.
    """
    if not len(true_points):
        return {}
    owner = np.concatenate([[k] * len(t) for k, t in enumerate(true_points)])
    tree = cKDTree(np.concatenate(true_points))
    found: Dict[int, List[int]] = {}
    for i, loop in enumerate(loops):
        d, nearest = tree.query(loop)
        if d.mean() < tolerance:
            found.setdefault(int(owner[nearest[np.argmin(d)]]), []).append(i)
    return found


def boundary_edges(faces: np.ndarray) -> np.ndarray:
    """(b, 2) vertex index pairs (smaller first) of the edges used by exactly one of the (f, 3) faces."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    return unique[counts == 1]


def boundary_distance(truth: Sequence[np.ndarray], loops: Sequence[np.ndarray]) -> float:
    """Symmetric mean distance between the true boundary points and the found loop points
    (docs/yardsticks.md): each a list of (k, 3) point arrays, best the dense points of
    :func:`boundary_curves` (then it is the distance between the curves, to within half their
    step). 0 when neither side has a boundary, nan when only one has."""
    if not len(truth) or not len(loops):
        return float("nan") if len(truth) or len(loops) else 0.0
    t, o = np.concatenate(truth), np.concatenate(loops)
    return 0.5 * (cKDTree(o).query(t)[0].mean() + cKDTree(t).query(o)[0].mean())


def loops_found(truth: Sequence[np.ndarray], loops: Sequence[np.ndarray], tolerance: float,
                min_edges: int = 10) -> Tuple[int, List[int]]:
    """How many true boundaries are found, and the sizes of the spurious loops.

    truth, loops: lists of (k, 3) point arrays. A loop belongs to the true boundary it lies
    on (:func:`match_loops` with `tolerance`); a true boundary counts as found when its largest
    loop has at least `min_edges` points. Returns (found, sizes of the loops on no boundary).
    """
    matched = match_loops(truth, loops, tolerance)
    found = sum(max(len(loops[i]) for i in ids) >= min_edges for ids in matched.values())
    assigned = {i for ids in matched.values() for i in ids}
    return found, [len(loop) for i, loop in enumerate(loops) if i not in assigned]


def triangle_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(f,) areas of the (f, 3) faces over the (m, 3) vertices."""
    v = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
    return 0.5 * np.linalg.norm(np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]), axis=1)


def sample_surface(vertices: np.ndarray, faces: np.ndarray, count: int, seed: int = 0) -> np.ndarray:
    """(count, 3) points drawn uniformly by area on the triangle mesh (same seed, same points)."""
    rng = np.random.default_rng(seed)
    areas = triangle_areas(vertices, faces)
    face = rng.choice(len(areas), size=count, p=areas / areas.sum())
    r1, r2 = rng.random(count), rng.random(count)
    # Square-root warp: uniform density over each triangle.
    s = np.sqrt(r1)
    a, b, c = (np.asarray(vertices, dtype=np.float64)[np.asarray(faces)[face, k]] for k in range(3))
    return (1 - s)[:, None] * a + (s * (1 - r2))[:, None] * b + (s * r2)[:, None] * c


def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.einsum("...i,...i", p - a, ab) / np.maximum(np.einsum("...i,...i", ab, ab), 1e-300), 0, 1)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distances from points p to triangles (a, b, c), all arrays (..., 3) broadcast together."""
    v0, v1, v2 = b - a, c - a, p - a
    d00, d01, d11 = (np.einsum("...i,...i", x, y) for x, y in [(v0, v0), (v0, v1), (v1, v1)])
    d20, d21 = np.einsum("...i,...i", v2, v0), np.einsum("...i,...i", v2, v1)
    denom = d00 * d11 - d01 * d01
    ok = denom > 1e-300  # degenerate triangles are measured by their edges only
    safe = np.where(ok, denom, 1.0)
    v, w = (d11 * d20 - d01 * d21) / safe, (d00 * d21 - d01 * d20) / safe
    inside = ok & (v >= 0) & (w >= 0) & (v + w <= 1)
    normal = np.cross(v0, v1)
    plane = np.abs(np.einsum("...i,...i", v2, normal)) / np.sqrt(np.where(ok, np.einsum("...i,...i", normal, normal), 1.0))
    edges = np.minimum(np.minimum(_segment_distance(p, a, b), _segment_distance(p, b, c)), _segment_distance(p, c, a))
    return np.where(inside, plane, edges)


def point_mesh_distance(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                        candidates: int = 16, chunk: int = 20000) -> np.ndarray:
    """(n,) distance from each of the (n, 3) points to the triangle mesh.

    Exact point-to-triangle distances to the `candidates` triangles with the nearest
    centroids: exact wherever the nearest triangle is among them, which holds on meshes of
    even-sized triangles (scans, marching cubes output); an overestimate elsewhere.
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    tri = vertices[faces]
    k = min(candidates, len(faces))
    tree = cKDTree(tri.mean(axis=1))
    out = np.empty(len(points))
    for start in range(0, len(points), chunk):
        p = np.asarray(points[start:start + chunk], dtype=np.float64)
        _, near = tree.query(p, k=k)
        near = near.reshape(len(p), k)
        t = tri[near]
        d = point_triangle_distance(p[:, None, :], t[..., 0, :], t[..., 1, :], t[..., 2, :])
        out[start:start + chunk] = d.min(axis=1)
    return out


def surface_distances(vertices, faces, truth_vertices, truth_faces, tolerance: float,
                      samples: int = 20000) -> Dict[str, float]:
    """Distances between a result mesh and a true mesh (docs/yardsticks.md), in the units of
    the vertices, from `samples` area-uniform points on each:

    chamfer: the mean of the two mean sample-to-other-mesh distances; spurious: fraction of
    the result's area farther than `tolerance` from the truth; missing: fraction of the
    truth's area farther than `tolerance` from the result. A result without faces misses
    everything (chamfer nan).
    """
    truth_points = sample_surface(truth_vertices, truth_faces, samples, seed=1)
    if len(faces) == 0:
        return {"chamfer": float("nan"), "spurious": 0.0, "missing": 1.0}
    points = sample_surface(vertices, faces, samples, seed=2)
    to_truth = point_mesh_distance(points, truth_vertices, truth_faces)
    to_result = point_mesh_distance(truth_points, vertices, faces)
    return {"chamfer": 0.5 * (to_truth.mean() + to_result.mean()),
            "spurious": float(np.mean(to_truth > tolerance)),
            "missing": float(np.mean(to_result > tolerance))}


def supported_faces(vertices: np.ndarray, faces: np.ndarray, samples: np.ndarray, tolerance: float) -> np.ndarray:
    """(f,) bool: the (f, 3) faces over the (m, 3) vertices with a point (centroid or a vertex)
    within `tolerance` of one of the (n, 3) samples."""
    if len(faces) == 0:
        return np.zeros(0, dtype=bool)
    tree = cKDTree(samples)
    tri = vertices[faces]
    near = np.stack([tree.query(p)[0] for p in [tri.mean(axis=1), tri[:, 0], tri[:, 1], tri[:, 2]]])
    return near.min(axis=0) <= tolerance


def unsupported_tolerance(cloud: Cloud) -> float:
    """Faces farther than this from every sample are unsupported: 2 sample spacings."""
    return 2 * cloud.spacing


def measure(vertices: np.ndarray, faces: np.ndarray, cloud: Cloud, truth: Optional[Tuple[np.ndarray, np.ndarray]] = None,
            truth_loops: Optional[Sequence[np.ndarray]] = None, loop_tolerance: float = 0.0,
            samples: int = 20000) -> Dict[str, object]:
    """The comparison row (see :data:`implicit_boundaries.table.COLUMNS`) of the surface with
    (m, 3) `vertices` and (f, 3) `faces` made from `cloud`: faces, boundary loops, unsupported
    area (farther than 2 sample spacings from every sample: what the method made up) and, with
    a ground truth ((vertices, faces) and its boundaries as (k, 3) point arrays, `truth_loops`),
    the yardsticks: true boundaries found (loops within `loop_tolerance`), chamfer, spurious
    and missing area, boundary distance. Distances are % of the input's bounding-box
    diagonal; the area tolerance is 1% of it. samples: area samples per mesh."""
    diagonal = cloud.diagonal
    loops = sorted(boundary_vertex_sets(faces, len(vertices)), key=len, reverse=True)
    row: Dict[str, object] = {"faces": int(len(faces)), "loops": len(loops),
                              "loop_sizes": [int(len(loop)) for loop in loops]}
    areas = triangle_areas(vertices, faces)
    supported = supported_faces(vertices, faces, cloud.points, unsupported_tolerance(cloud))
    row["unsupported_pct"] = 100 * float(areas[~supported].sum() / areas.sum()) if len(areas) else 0.0
    if truth is not None:
        found, _ = loops_found(truth_loops, [vertices[loop] for loop in loops], loop_tolerance)
        row["loops_found"] = f"{found}/{len(truth_loops)}"
        d = surface_distances(vertices, faces, *truth, 0.01 * diagonal, samples)
        row["chamfer_pct"] = 100 * d["chamfer"] / diagonal
        row["spurious_pct"] = 100 * d["spurious"]
        row["missing_pct"] = 100 * d["missing"]
        # Between the boundary curves, sampled every 0.05% of the diagonal (within 0.025%).
        curves = [boundary_curves(*mesh, 0.0005 * diagonal) for mesh in (truth, (vertices, faces))]
        row["boundary_distance_pct"] = 100 * boundary_distance(*curves) / diagonal
    return row
