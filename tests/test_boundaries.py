"""Boundaries on generated shapes with known boundaries: loop counts, positions, topology."""
import numpy as np
import pytest

import implicit_boundaries
from scipy.spatial import cKDTree

from shapes import check_oriented_manifold, cylinder, fibonacci_sphere, moebius, torus


def test_open_cylinder_has_two_loops_at_its_rims():
    points, normals = cylinder()
    rec = implicit_boundaries.reconstruct(points, normals)
    assert len(rec.loops) == 2
    cell = rec.info["cell_size"]
    for loop in rec.loops:
        rim = rec.vertices[loop]
        z = np.sign(rim[:, 2].mean())
        assert np.all(np.abs(rim[:, 2] - z) < 1.5 * cell)
        assert np.all(np.abs(np.hypot(rim[:, 0], rim[:, 1]) - 1) < 0.5 * cell)
    check_oriented_manifold(rec.vertices, rec.faces)


def test_plane_cut_torus_has_two_loops_on_the_cut():
    points, normals = torus()
    keep = points[:, 0] < 0.3
    rec = implicit_boundaries.reconstruct(points[keep], normals[keep])
    assert len(rec.loops) == 2
    cell = rec.info["cell_size"]
    for loop in rec.loops:
        assert np.all(np.abs(rec.vertices[loop][:, 0] - 0.3) < 1.5 * cell)
    assert sorted(np.sign(rec.vertices[l][:, 1].mean()) for l in rec.loops) == [-1, 1]
    check_oriented_manifold(rec.vertices, rec.faces)


@pytest.fixture(scope="module")
def punched_sphere():
    """20,000 samples of the unit sphere without 5 caps (0.25 to 0.35 rad) and 3 tiny gaps
    (2.8 sample spacings), centred on 8 well-separated directions."""
    points = fibonacci_sphere(20000)
    spacing = np.sqrt(4 * np.pi / len(points))
    centres = fibonacci_sphere(8)
    radii = np.array([0.35, 0.3, 0.25, 0.3, 0.35] + [2.8 * spacing] * 3)
    angle = np.arccos(np.clip(points @ centres.T, -1, 1))
    keep = np.all(angle > radii, axis=1)
    return points[keep], centres, radii


def loops_at_holes(rec, centres, radii):
    """For each loop: the hole it surrounds, and the largest distance (in cells) of its
    vertices from that hole's rim circle."""
    out = []
    for loop in rec.loops:
        v = rec.vertices[loop]
        hole = int(np.argmax(centres @ v.mean(0)))
        angle = np.arccos(np.clip(v @ centres[hole] / np.linalg.norm(v, axis=1), -1, 1))
        rim = np.hypot(angle - radii[hole], np.linalg.norm(v, axis=1) - 1)  # near the unit sphere
        out.append((hole, rim.max() / rec.info["cell_size"]))
    return out


def test_sphere_keeps_five_holes_and_fills_three_gaps(punched_sphere):
    points, centres, radii = punched_sphere
    rec = implicit_boundaries.reconstruct(points, points, min_boundary_edges=25)
    holes = loops_at_holes(rec, centres, radii)
    assert sorted(h for h, _ in holes) == [0, 1, 2, 3, 4]
    assert all(error < 1.5 for _, error in holes), holes
    assert rec.info["holes_filled"] == 3
    check_oriented_manifold(rec.vertices, rec.faces)


def test_sphere_keeps_all_eight_with_threshold_zero(punched_sphere):
    points, centres, radii = punched_sphere
    rec = implicit_boundaries.reconstruct(points, points, min_boundary_edges=0)
    assert sorted(h for h, _ in loops_at_holes(rec, centres, radii)) == list(range(8))
    check_oriented_manifold(rec.vertices, rec.faces)


def test_smoothing_shortens_the_boundary_and_keeps_it_on_the_rim(punched_sphere):
    points, centres, radii = punched_sphere
    rough = implicit_boundaries.reconstruct(points, points, min_boundary_edges=25, boundary_smoothing=0)
    smooth = implicit_boundaries.reconstruct(points, points, min_boundary_edges=25)
    assert smooth.info["boundary_loop_lengths"].sum() < 0.8 * rough.info["boundary_loop_lengths"].sum()
    error = lambda rec: np.mean([e for _, e in loops_at_holes(rec, centres, radii)])
    assert error(smooth) <= error(rough) + 0.1
    # On the implicit surface (the unit sphere here): smoothing does not pull vertices inside.
    v = smooth.vertices[np.concatenate(smooth.loops)]
    assert np.abs(np.linalg.norm(v, axis=1) - 1).max() < 0.2 * smooth.info["cell_size"]


def test_moebius_strip_has_one_loop_and_one_seam():
    """A signed implicit function cannot represent a one-sided surface: the estimated normals
    must flip somewhere, and the surface is cut there across the strip. What remains is one
    oriented 2-manifold with a single boundary loop: the strip's boundary plus the two sides of
    that one cut, which lies at a single place along the strip."""
    points, u, w = moebius()
    rec = implicit_boundaries.reconstruct(points, None)
    assert len(rec.loops) == 1
    cell = rec.info["cell_size"]
    d, nearest = cKDTree(points[np.abs(w) > 0.29]).query(rec.vertices[rec.loops[0]])
    seam = d > 3 * cell
    assert seam.sum() < 0.15 * len(d)
    _, on_strip = cKDTree(points).query(rec.vertices[rec.loops[0]][seam])
    angles = u[on_strip]
    spread = np.angle(np.exp(1j * (angles - angles[0])))  # around the circle
    assert np.ptp(spread) < 0.2  # one cut, not several
    check_oriented_manifold(rec.vertices, rec.faces)
