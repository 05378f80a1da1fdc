"""Shared fixtures: the plugin loaded into pymeshlab, pymeshlab's sample scans."""
from pathlib import Path

import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.cloud import read_cloud

SAMPLES = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes"


@pytest.fixture(scope="session")
def plugin():
    return implicit_boundaries.load()


def point_cloud(path):
    """(points (n, 3), normals (n, 3)) of a mesh file, faces dropped, by the package's loader."""
    cloud = read_cloud(path)
    return cloud.points, cloud.normals
