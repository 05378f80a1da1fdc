"""Measures on meshes with boundaries, for tests, benchmarks and comparisons."""
from typing import Dict, List, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


def boundary_vertex_sets(faces: np.ndarray, n_vertices: int) -> List[np.ndarray]:
    """Vertex indices of each boundary component of a triangle mesh (edges used by one face).

    faces: (f, 3) vertex indices. Returns one sorted index array per component.
    """
    faces = np.asarray(faces, dtype=np.int64)
    if len(faces) == 0:
        return []
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    border = unique[counts == 1]
    if len(border) == 0:
        return []
    graph = sp.coo_matrix((np.ones(len(border)), (border[:, 0], border[:, 1])), shape=(n_vertices, n_vertices))
    _, label = connected_components(graph, directed=False)
    component = label[border[:, 0]]
    return [np.unique(border[component == c]) for c in np.unique(component)]


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
