"""Shared fixtures: the plugin loaded into pymeshlab, pymeshlab's sample scans."""
from pathlib import Path

import pymeshlab
import pytest

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
