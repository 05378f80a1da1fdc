"""Shared fixtures: the plugin loaded into pymeshlab, pymeshlab's sample scans, hole geometry."""
from pathlib import Path

import numpy as np
import pymeshlab
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

import implicit_boundaries

SAMPLES = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes"


@pytest.fixture(scope="session")
def plugin():
    return implicit_boundaries.load()


def point_cloud(path):
    """Vertices and normals of a mesh file (faces dropped), as MeshLab computes them on load."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    m.compact()
    return m.vertex_matrix().copy(), m.vertex_normal_matrix().copy(), m.face_matrix().copy()


def boundary_loops_of(faces, n_vertices):
    """Vertex sets of the boundary components of a triangle mesh (edges used by one face)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    border = unique[counts == 1]
    if len(border) == 0:
        return []
    graph = sp.coo_matrix((np.ones(len(border)), (border[:, 0], border[:, 1])), shape=(n_vertices, n_vertices))
    _, label = connected_components(graph, directed=False)
    return [np.unique(border[label[border[:, 0]] == c]) for c in np.unique(label[border[:, 0]])]
