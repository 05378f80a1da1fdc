"""compare(): the metrics on known answers, and the comparison with its report end to end."""
import numpy as np
import pytest
from PIL import Image

import implicit_boundaries
from implicit_boundaries import metrics
from implicit_boundaries.cloud import Cloud
from implicit_boundaries.methods import METHODS, Surface, density_trim, poisson_depth

from scipy.spatial import ConvexHull

from shapes import cylinder, fibonacci_sphere

FILTER = "implicit with boundaries"  # our filter's row


def grid(nx, ny, size=1.0):
    """A flat square (size x size, z = 0) of (nx - 1) x (ny - 1) quads split into triangles:
    vertices (nx * ny, 3), faces (2 (nx - 1) (ny - 1), 3)."""
    x, y = np.meshgrid(np.linspace(0, size, nx), np.linspace(0, size, ny))
    vertices = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    i = (np.arange(ny - 1)[:, None] * nx + np.arange(nx - 1)).ravel()
    faces = np.concatenate([np.column_stack([i, i + 1, i + nx + 1]), np.column_stack([i, i + nx + 1, i + nx])])
    return vertices, faces


def cylinder_mesh(radius=1.0, height=2.0, around=96, up=33):
    """Open cylinder around z, z in [-height/2, height/2], as a triangle mesh (two rims)."""
    theta, z = np.meshgrid(np.arange(around) * 2 * np.pi / around, np.linspace(-height / 2, height / 2, up))
    vertices = np.column_stack([radius * np.cos(theta).ravel(), radius * np.sin(theta).ravel(), z.ravel()])
    ring = lambda r, a: r * around + a % around
    r, a = np.meshgrid(np.arange(up - 1), np.arange(around), indexing="ij")
    r, a = r.ravel(), a.ravel()
    faces = np.concatenate([np.column_stack([ring(r, a), ring(r, a + 1), ring(r + 1, a + 1)]),
                            np.column_stack([ring(r, a), ring(r + 1, a + 1), ring(r + 1, a)])])
    return vertices, faces


def test_point_triangle_distance_inside_at_an_edge_and_at_a_corner():
    a, b, c = np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    points = np.array([[0.2, 0.2, 0.5], [0.5, -2.0, 0.0], [-3.0, -4.0, 0.0], [1.0, 1.0, 0.0]])
    expected = [0.5, 2.0, 5.0, np.sqrt(0.5)]
    assert np.allclose(metrics.point_triangle_distance(points, a, b, c), expected)


def test_a_mesh_against_itself_is_at_distance_zero():
    vertices, faces = cylinder_mesh()
    d = metrics.surface_distances(vertices, faces, vertices, faces, tolerance=1e-6, samples=5000)
    assert d["chamfer"] < 1e-12 and d["spurious"] == 0 and d["missing"] == 0
    loops = [vertices[h] for h in metrics.boundary_vertex_sets(faces, len(vertices))]
    assert metrics.boundary_distance(loops, loops) == 0


def test_a_shifted_mesh_is_at_the_shift():
    vertices, faces = grid(21, 21)
    shifted = vertices + [0, 0, 0.03]
    near = metrics.surface_distances(shifted, faces, vertices, faces, tolerance=0.05, samples=5000)
    far = metrics.surface_distances(shifted, faces, vertices, faces, tolerance=0.02, samples=5000)
    assert near["chamfer"] == pytest.approx(0.03, rel=1e-9)
    assert near["spurious"] == near["missing"] == 0
    assert far["spurious"] == far["missing"] == 1
    rim = [v[h] for v in (vertices, shifted) for h in metrics.boundary_vertex_sets(faces, len(v))]
    assert metrics.boundary_distance(rim[:1], rim[1:]) == pytest.approx(0.03, rel=1e-9)


def test_sliding_a_plane_in_its_own_plane_spurs_and_misses_the_slid_off_strip():
    vertices, faces = grid(41, 41)
    slid = vertices + [0.25, 0, 0]  # a quarter of the square leaves the original
    d = metrics.surface_distances(slid, faces, vertices, faces, tolerance=0.01, samples=20000)
    assert d["spurious"] == pytest.approx(0.24, abs=0.02)  # the strip beyond the tolerance
    assert d["missing"] == pytest.approx(0.24, abs=0.02)


def test_loop_counts_of_generated_meshes():
    vertices, faces = cylinder_mesh()
    assert len(metrics.boundary_vertex_sets(faces, len(vertices))) == 2
    assert len(metrics.boundary_edges(faces)) == 2 * 96
    vertices, faces = grid(5, 5)
    assert len(metrics.boundary_vertex_sets(faces, len(vertices))) == 1
    assert len(metrics.boundary_edges(faces)) == 16


def test_density_trim_drops_faces_touching_the_least_dense_vertices():
    faces = np.array([[0, 1, 2], [1, 2, 3], [2, 3, 4]])
    density = np.array([0.0, 5, 5, 5, 5])
    assert density_trim(faces, density, 0.1).tolist() == [[1, 2, 3], [2, 3, 4]]
    assert len(density_trim(faces, density, 0.0)) == 3


def test_poisson_depth_matches_the_resolution():
    assert [poisson_depth(r) for r in (64, 78, 100, 212, 256)] == [6, 6, 7, 8, 8]


CAP = 0.6  # radius (radians) of the two caps cut out of the sphere


def two_holed_sphere(n=4000):
    """The unit sphere without two caps (around +z and +x): samples (= outward normals) and a
    true mesh (vertices, faces) over the same points."""
    points = fibonacci_sphere(n)
    keep = (points[:, 2] < np.cos(CAP)) & (points[:, 0] < np.cos(CAP))
    hull = ConvexHull(points).simplices  # triangulates points on a sphere
    faces = hull[np.all(keep[hull], axis=1)]
    index = np.cumsum(keep) - 1
    return points[keep], index[faces]


@pytest.fixture(scope="module")
def holed_sphere(tmp_path_factory, plugin):
    """A comparison on a sphere with two holes, against its true mesh, report written."""
    points, faces = two_holed_sphere()
    folder = tmp_path_factory.mktemp("report")
    steps = []
    table = implicit_boundaries.compare((points, points), (points, faces), resolution=40, report=folder,
                                        samples=4000, progress=lambda done, total, what: steps.append((done, total)))
    return table, folder, steps


def test_compare_runs_every_method_at_matched_resolution(holed_sphere):
    table, _, steps = holed_sphere
    rows = {row["method"]: row for row in table.rows}
    assert list(rows) == list(METHODS)
    assert table.settings.resolution == 40 and table.settings.depth == 5
    assert steps[0] == (0, steps[-1][1]) and steps[-1][0] == steps[-1][1]


def test_ours_keeps_the_holes_and_poisson_fills_them(holed_sphere):
    rows = {row["method"]: row for row in holed_sphere[0].rows}
    ours, poisson = rows[FILTER], rows["screened Poisson"]
    assert ours["loops"] == 2 and ours["loops_found"] == "2/2" and ours["boundary_distance_pct"] < 2
    # Poisson runs the surface on through the holes: its loops (where its domain cuts it) are
    # not at the holes, and the two caps' area (2 pi (1 - cos 0.6) each, 9.3% of the sphere's)
    # is surface the samples do not support.
    assert poisson["loops_found"] == "0/2" and poisson["boundary_distance_pct"] > 3
    assert poisson["spurious_pct"] > 6 and ours["spurious_pct"] < 1
    assert poisson["unsupported_pct"] > 2 and ours["unsupported_pct"] < 0.5
    assert ours["chamfer_pct"] < 0.5 and ours["missing_pct"] < 1


def test_report_has_its_files_and_pictures_that_show_something(holed_sphere):
    table, folder, _ = holed_sphere
    assert table.report == folder / "report.html"
    page = table.report.read_text()
    for name in ("side_by_side.png", "metrics.png", "implicit_with_boundaries.ply", "screened_poisson.ply",
                 "screened_poisson_density_trim.ply"):
        assert (folder / name).is_file() and name in page
    assert "screened Poisson + density trim" in page and "trim_quantile" in page
    for name in ("side_by_side.png", "metrics.png"):
        pixels = np.asarray(Image.open(folder / name).convert("RGB"))
        assert pixels.std() > 20
        packed = (pixels[..., 0].astype(np.int32) << 16) | (pixels[..., 1].astype(np.int32) << 8) | pixels[..., 2]
        assert len(np.unique(packed)) > 50  # distinct colours


def colour_counts(pixels):
    """Pixels of the boundary colour (strong red), of our hole triangles (blue over the
    surface) and of unsupported faces (orange)."""
    r, g, b = (pixels[..., k].astype(int) for k in range(3))
    return {"red": int(np.sum((r > 150) & (g < 80) & (b < 90))),
            "blue": int(np.sum(b > r + 30)),
            "orange": int(np.sum((r > 150) & (g > 60) & (g < r - 50) & (b < g - 30)))}


def test_pictures_show_boundaries_hole_triangles_and_unsupported_faces(holed_sphere):
    _, folder, _ = holed_sphere
    pixels = np.asarray(Image.open(folder / "side_by_side.png").convert("RGB"))
    views = np.array_split(pixels[:int(pixels.shape[0] * 2 / 2.2)], 2, axis=0)  # above the legend strip
    (ours, poisson, *_), (ours_back, *_) = (np.array_split(v, len(METHODS), axis=1) for v in views)
    front, back = colour_counts(ours), colour_counts(ours_back)
    assert front["red"] > 300 and front["blue"] > 2000 and front["orange"] == 0
    # The holes face the first view: from the back, at most a pixel or two of a rim's edge.
    assert back["red"] < 0.02 * front["red"] and back["blue"] < 0.02 * front["blue"]
    assert colour_counts(poisson)["orange"] > 1000


def test_a_method_is_added_in_one_place(plugin):
    points, normals = cylinder(spacing=0.1)

    def top_half(cloud: Cloud, settings) -> Surface:
        ours = METHODS[FILTER](cloud, settings)
        centroids = ours.vertices[ours.faces].mean(axis=1)
        return Surface(ours.vertices, ours.faces[centroids[:, 2] > 0])

    table = implicit_boundaries.compare((points, normals), resolution=30,
                                        methods={FILTER: METHODS[FILTER], "top half": top_half})
    rows = {row["method"]: row for row in table.rows}
    assert rows["top half"]["loops"] == 2
    assert rows["top half"]["faces"] < rows[FILTER]["faces"]
    assert "chamfer_pct" not in rows[FILTER]  # no ground truth, no truth metrics
    assert table.report is None


def test_bad_trim_quantile_is_refused():
    with pytest.raises(ValueError, match="quantile"):
        implicit_boundaries.compare((np.zeros((20, 3)), np.ones((20, 3))), trim_quantile=1.5)
