"""Screened Poisson's surface as the implicit function: the mesh-layer implicit and
poisson_with_boundaries()."""
import numpy as np
import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.metrics import point_mesh_distance
from implicit_boundaries.options import Implicit
from implicit_boundaries.poisson import poisson_with_boundaries
from shapes import check_oriented_manifold, fibonacci_sphere


@pytest.fixture(scope="module")
def hemisphere():
    d = fibonacci_sphere(8000)
    return d[d[:, 2] > 0]


def test_poisson_on_a_hemisphere_keeps_one_loop_and_no_bulge(hemisphere):
    """Poisson alone closes the hemisphere with a bulge far below its rim; on top of it, our
    filter keeps the Poisson surface where the samples are and one loop at the rim."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=hemisphere, v_normals_matrix=hemisphere), "hemisphere")
    info = poisson_with_boundaries(ms).info
    assert ms.mesh_number() == 3 and ms.current_mesh_id() == 2
    poisson = ms.mesh(1)
    assert poisson.vertex_matrix()[:, 2].min() < -0.3  # the bulge
    ours = ms.current_mesh()
    vertices, faces = ours.vertex_matrix(), ours.face_matrix()
    cell = info["cell_size"]
    assert info["boundary_loops"] == 1
    rim = vertices[implicit_boundaries.loops_from_result(info)[0]]
    assert np.abs(rim[:, 2]).max() < 2 * cell
    assert vertices[:, 2].min() > -2 * cell  # no bulge left
    # On the Poisson surface: within a small fraction of a cell.
    distance = point_mesh_distance(vertices, poisson.vertex_matrix(), poisson.face_matrix())
    assert distance.max() < 0.1 * cell
    check_oriented_manifold(vertices, faces)


def test_points_in_reconstruction_out(hemisphere):
    out = poisson_with_boundaries(hemisphere, hemisphere, depth=7, resolution=60)
    assert len(out.loops) == 1 and out.info["resolution"] == 60
    assert np.abs(np.linalg.norm(out.vertices, axis=1) - 1).max() < 0.02
    with pytest.raises(ValueError, match="normal"):
        poisson_with_boundaries(hemisphere)


def test_mesh_implicit_needs_a_layer_with_faces(hemisphere):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=hemisphere, v_normals_matrix=hemisphere), "hemisphere")
    with pytest.raises(pymeshlab.PyMeshLabException, match="has no faces"):
        implicit_boundaries.apply(ms, implicit=Implicit.MESH_LAYER, implicit_mesh=0)
    assert ms.mesh_number() == 1


def test_the_mesh_implicit_defaults_to_the_layer_poisson_made(hemisphere):
    """After Screened Poisson on the points, with the points layer current again, the mesh
    implicit needs no layer chosen: it defaults to the most recent layer with faces."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=hemisphere, v_normals_matrix=hemisphere), "hemisphere")
    ms.generate_surface_reconstruction_screened_poisson(depth=7)
    ms.set_current_mesh(0)
    info = implicit_boundaries.apply(ms, implicit=Implicit.MESH_LAYER)
    assert info["boundary_loops"] == 1 and ms.mesh_number() == 3
