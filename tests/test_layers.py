"""How MeshLab hands scans to the filter: a layer's transformation matrix (what the Align tool
and "Set matrix" change) and layers whose normals are only partly given (MeshLab's import of a
range scan leaves zero normals on grid points no triangle uses)."""
import numpy as np
import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.options import Normals
from shapes import fibonacci_sphere, overlapping_caps


def open_scan():
    """The unit sphere above z = -0.5: one boundary; outward normals."""
    u = fibonacci_sphere(6000)
    u = u[u[:, 2] > -0.5]
    return u, u.copy()


def rotation_about_z(degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def test_the_surface_lies_where_the_layer_matrix_puts_the_scan(plugin):
    """The layer's vertices stay put and its matrix turns the scan upside down and moves it:
    the surface is made where the user sees the scan (before: where the raw vertices are, with
    the boundary at the bottom instead of the top), and the new layer's matrix is the identity."""
    points, normals = open_scan()
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_about_z(30) @ np.diag([1.0, -1, -1])  # upside down, turned
    matrix[:3, 3] = [5, -2, 1]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "scan")
    ms.set_matrix(transformmatrix=matrix, freeze=False)
    out = implicit_boundaries.apply(ms)
    surface = ms.current_mesh()
    np.testing.assert_allclose(surface.transform_matrix(), np.eye(4))
    local = (surface.vertex_matrix() - matrix[:3, 3]) @ matrix[:3, :3]  # back to the scan's frame
    spacing = out["sample_spacing"]
    assert np.abs(np.linalg.norm(local, axis=1) - 1).max() < 0.5 * spacing
    assert out["boundary_loops"] == 1
    loop = surface.vertex_matrix()[np.asarray(out["boundary_loop_vertices"]).astype(int)]
    assert np.abs(loop[:, 2] - (1 + 0.5)).max() < 2 * spacing  # z = -0.5 turned upside down, moved up 1
    # Outward: the face normals point away from the moved centre.
    faces = surface.face_matrix()
    v = surface.vertex_matrix()
    normal = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
    assert (np.sum(normal * (v[faces].mean(axis=1) - matrix[:3, 3]), axis=1) > 0).mean() > 0.99


def test_zero_normals_among_given_ones_are_estimated(plugin):
    """11 of the layer's normals are zero and the others given (inward, as a scanner facing the
    inside of a bowl would give them): the run no longer stops with "choose to estimate
    normals"; the 11 are estimated facing like their neighbours, the given ones are kept (the
    surface is inside out, as they say), and the log and result say how many."""
    points, normals = open_scan()
    normals = -normals
    zero = np.arange(100, 1100, 91)[:11]
    normals[zero] = 0
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "scan")
    out = implicit_boundaries.apply(ms)
    assert out["normals_filled"] == 11 and not out["normals_estimated"]
    assert out["boundary_loops"] == 1
    m = ms.current_mesh()
    v, faces = m.vertex_matrix(), m.face_matrix()
    normal = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
    assert (np.sum(normal * v[faces].mean(axis=1), axis=1) < 0).mean() > 0.999


def test_visible_layers_are_merged_each_through_its_matrix(plugin):
    """A sphere scanned as two overlapping caps, the second stored in its scanner's frame with the
    matrix that aligns it (as the Align tool leaves it), and a hidden layer of strays: merging
    the visible layers gives the closed sphere, in a layer "Merged layers with boundaries";
    the current layer alone gives its cap, with one loop."""
    u = fibonacci_sphere(8000)
    upper, lower = u[u[:, 2] > -0.2], u[u[:, 2] < 0.2]
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_about_z(70)
    matrix[:3, 3] = [0.5, 0, 0]
    lower_local = (lower - matrix[:3, 3]) @ matrix[:3, :3]  # the inverse of the matrix
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.random.default_rng(0).uniform(-3, 3, (50, 3))), "strays")
    ms.set_current_mesh_visibility(False)
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=lower_local, v_normals_matrix=lower_local), "lower")
    ms.set_matrix(transformmatrix=matrix, freeze=False)
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=upper, v_normals_matrix=upper), "upper")
    alone = implicit_boundaries.apply(ms)
    assert alone["boundary_loops"] == 1
    ms.set_current_mesh(2)
    merged = implicit_boundaries.apply(ms, merge_visible_layers=True)
    assert merged["boundary_loops"] == 0
    assert ms.current_mesh().label() == "Merged layers with boundaries"
    v = ms.current_mesh().vertex_matrix()
    assert np.abs(np.linalg.norm(v, axis=1) - 1).max() < 0.5 * merged["sample_spacing"]


@pytest.mark.parametrize("seed", [3, 4])
def test_overlapping_scans_with_registration_error_give_one_sheet(plugin, seed):
    """An open cap (the unit sphere above z = -0.5) scanned from four sides, each scan a
    hemisphere sampled on its own and overlapping its neighbours, registered with an error of
    0.8 of a scan's spacing (a shift, as the Align tool leaves between scans). Merged, the
    density grows but the detail does not: the spacing is measured within each scan, and the
    surface is one sheet with the cap's one loop (measured over all samples, the sheets lay
    apart by more than a spacing and tore: 4 and 12 loops)."""
    ms, spacing = overlapping_caps(seed, shift_spacings=0.8)
    out = implicit_boundaries.apply(ms, merge_visible_layers=True)
    assert out["boundary_loops"] == 1
    assert abs(out["sample_spacing"] - spacing) < 0.2 * spacing
    radius = np.linalg.norm(ms.current_mesh().vertex_matrix(), axis=1)
    assert np.quantile(np.abs(radius - 1), 0.99) < spacing  # between the sheets, up to their rims


def test_curled_scan_edges_over_other_scans_leave_no_holes(plugin):
    """The four registered scans of the cap, each with the edge curl of a real range scan: its
    samples seen at grazing angles pulled up to 3 spacings off the surface (mixed pixels at the
    silhouette). Where another scan covers them, those edge samples are left out of the
    implicit function's fit (scan_edges.h), so its zero set follows the well-seen sheets: the
    cap's one loop in at least 11 of 12 draws (fitted to every sample: 9 of 12)."""
    exact = 0
    for seed in range(3, 15):
        ms, spacing = overlapping_caps(seed, shift_spacings=0.8, edge_curl=3)
        out = implicit_boundaries.apply(ms, merge_visible_layers=True)
        assert out["covered_scan_edges"] > 0
        exact += out["boundary_loops"] == 1
    assert exact >= 11


def test_turned_normals_at_one_scans_border_do_not_cut_the_merged_surface(plugin):
    """Two overlapping scans of a cap; towards its border, where it sees the surface at a
    grazing angle, the second scan's normals turn steadily away from the true ones, up to 140
    degrees at its edge (consistent within the scan). Neighbouring samples of different scans
    with opposite normals are not an orientation seam (a registration error cannot flip a
    normal): the merged surface keeps the cap's one loop, not cut there (the same samples in one
    layer: cut, 3 loops)."""
    rng = np.random.default_rng(0)
    first, second = (fibonacci_sphere(8000, jitter=0.3, rng=rng) for _ in range(2))  # sampled apart
    first = first[(first[:, 2] > -0.5) & (first[:, 0] > -0.2)]
    second = second[(second[:, 2] > -0.5) & (second[:, 0] < 0.2)]
    toward_edge = np.array([1.0, 0, 0]) - second[:, [0]] * second  # tangent, towards +x
    toward_edge /= np.linalg.norm(toward_edge, axis=1, keepdims=True)
    turn = np.radians(140) * np.clip((second[:, [0]] - 0.05) / 0.15, 0, 1)
    normals = np.cos(turn) * second + np.sin(turn) * toward_edge
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=first, v_normals_matrix=first), "first")
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=second, v_normals_matrix=normals), "second")
    out = implicit_boundaries.apply(ms, merge_visible_layers=True)
    assert out["seam_points"] == 0
    assert out["boundary_loops"] == 1


def test_reconstruct_scans_from_arrays(plugin):
    """The Python API for several scans: (points, normals, matrix) per scan, the second stored
    in its scanner's frame; one closed sphere. A scan whose normals do not match is refused."""
    u = fibonacci_sphere(6000)
    upper, lower = u[u[:, 2] > -0.2], u[u[:, 2] < 0.2]
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_about_z(40)
    lower_local = lower @ matrix[:3, :3]  # the inverse rotation
    rec = implicit_boundaries.reconstruct_scans([(upper, upper), (lower_local, lower_local, matrix)])
    assert rec.loops == [] and rec.info["boundary_loops"] == 0
    assert np.abs(np.linalg.norm(rec.vertices, axis=1) - 1).max() < 0.5 * rec.info["sample_spacing"]
    with pytest.raises(ValueError, match="scan 1: normals"):
        implicit_boundaries.reconstruct_scans([(upper, upper), (lower, lower[:5])])


def height(x, y):
    """The known surface of the two-scan test: a wavy sheet z = height(x, y)."""
    return 0.1 * np.sin(3 * x) * np.cos(2 * y)


def strip_scan(x_range, spacing, rng):
    """Jittered grid samples of the wavy sheet over x_range × [-1, 1], with their normals."""
    x, y = np.meshgrid(np.arange(x_range[0], x_range[1], spacing), np.arange(-1, 1, spacing))
    x = x.ravel() + rng.uniform(-0.3, 0.3, x.size) * spacing
    y = y.ravel() + rng.uniform(-0.3, 0.3, y.size) * spacing
    normals = np.column_stack([-0.3 * np.cos(3 * x) * np.cos(2 * y), 0.2 * np.sin(3 * x) * np.sin(2 * y), np.ones_like(x)])
    return np.column_stack([x, y, height(x, y)]), normals / np.linalg.norm(normals, axis=1, keepdims=True)


def test_two_scans_offset_and_turned_give_one_sheet(plugin):
    """Two overlapping scans of a wavy sheet (x < 0.3 and x > -0.3), the second registered with
    an error: moved 0.5 of a spacing along the normal and turned 0.2 degrees. Merged: one sheet
    (the area of the truth, not the 1.3 times a doubled overlap would have), the sheet's one
    loop and no slit where the scans overlap, and every vertex within a spacing of the truth."""
    spacing = 0.02
    rng = np.random.default_rng(1)
    first, first_normals = strip_scan((-1, 0.3), spacing, rng)
    second, second_normals = strip_scan((-0.3, 1), spacing, rng)
    turn = np.radians(0.2)
    matrix = np.eye(4)
    matrix[:3, :3] = [[np.cos(turn), 0, np.sin(turn)], [0, 1, 0], [-np.sin(turn), 0, np.cos(turn)]]
    matrix[:3, 3] = [0, 0, 0.5 * spacing]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=first, v_normals_matrix=first_normals), "first")
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=second, v_normals_matrix=second_normals), "second")
    ms.set_matrix(transformmatrix=matrix, freeze=False)
    out = implicit_boundaries.apply(ms, merge_visible_layers=True)
    assert out["boundary_loops"] == 1
    v, f = ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()
    assert np.abs(v[:, 2] - height(v[:, 0], v[:, 1])).max() < spacing  # vertical: at least the distance
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum()
    x, y = np.meshgrid(np.linspace(-1, 1, 401), np.linspace(-1, 1, 401))
    gx, gy = 0.3 * np.cos(3 * x) * np.cos(2 * y), -0.2 * np.sin(3 * x) * np.sin(2 * y)
    truth = 4 * np.mean(np.sqrt(1 + gx ** 2 + gy ** 2))
    assert abs(area / truth - 1) < 0.05


@pytest.mark.parametrize("matrix", [
    [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0.3, 0, 0, 1]],  # projective (a transposed translation)
    [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]],  # flattens the layer onto z = 0
])
def test_a_layer_matrix_that_is_not_affine_or_invertible_is_refused(plugin, matrix):
    """Merged or alone, a layer whose matrix projects or flattens it is named in the refusal,
    with the filters that fix the matrix."""
    points, normals = open_scan()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "good")
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "tilted")
    ms.set_matrix(transformmatrix=np.array(matrix, dtype=float), freeze=False)
    for merge in (False, True):
        with pytest.raises(pymeshlab.PyMeshLabException, match="matrix of layer 'tilted' is not affine or cannot be inverted"):
            implicit_boundaries.apply(ms, merge_visible_layers=merge)
    assert ms.mesh_number() == 2


def test_merging_with_no_visible_scan_is_refused(plugin):
    points, normals = open_scan()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "hidden")
    ms.set_current_mesh_visibility(False)
    with pytest.raises(pymeshlab.PyMeshLabException, match="No visible layer has vertices: show the scans to merge"):
        implicit_boundaries.apply(ms, merge_visible_layers=True)
    assert implicit_boundaries.apply(ms)["boundary_loops"] == 1  # the current layer, hidden or not


def save_scan_with_camera(path, points, camera):
    """An ASCII PLY of `points` (no normals) with a camera element whose viewpoint is `camera`
    (MeshLab reads it as the layer's shot, in the scan's own frame)."""
    fields = ["view_px", "view_py", "view_pz", "x_axisx", "x_axisy", "x_axisz", "y_axisx", "y_axisy", "y_axisz",
              "z_axisx", "z_axisy", "z_axisz", "focal", "scalex", "scaley", "centerx", "centery"]
    header = ["ply", "format ascii 1.0", "element camera 1"] + [f"property float {f}" for f in fields]
    header += [f"property int {f}" for f in ("viewportx", "viewporty")]
    header += [f"property float {f}" for f in ("k1", "k2", "k3", "k4")]
    header += [f"element vertex {len(points)}", "property float x", "property float y", "property float z", "end_header"]
    camera_row = [*camera, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0.01, 0.01, 320, 240, 640, 480, 0, 0, 0, 0]
    rows = [" ".join(f"{x:.9g}" for x in camera_row)] + [" ".join(f"{x:.9g}" for x in p) for p in points]
    path.write_text("\n".join(header + rows) + "\n")


def inward_fraction(mesh):
    v, f = mesh.vertex_matrix(), mesh.face_matrix()
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    return float((np.sum(normal * v[f].mean(axis=1), axis=1) < 0).mean())


def test_estimated_normals_face_each_scans_camera(plugin, tmp_path):
    """A room scanned from inside: the unit sphere as two overlapping scans without normals,
    each with its scanner's position as the layer's camera (a PLY camera element), the lower
    scan stored in its own frame with the matrix that places it. Merged with estimated normals,
    every normal faces its scanner: the surface faces inward (propagation alone turns a closed
    surface outward, away from its centre: inside out for a room)."""
    u = fibonacci_sphere(6000)
    upper, lower = u[u[:, 2] > -0.2], u[u[:, 2] < 0.2]
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_about_z(90)
    matrix[:3, 3] = [0.2, 0, 0]
    lower_local = (lower - matrix[:3, 3]) @ matrix[:3, :3]
    camera_local = (np.array([0, 0, -0.1]) - matrix[:3, 3]) @ matrix[:3, :3]
    save_scan_with_camera(tmp_path / "upper.ply", upper, [0, 0, 0.1])
    save_scan_with_camera(tmp_path / "lower.ply", lower_local, camera_local)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "upper.ply"))
    ms.load_new_mesh(str(tmp_path / "lower.ply"))
    ms.set_matrix(transformmatrix=matrix, freeze=False)
    out = implicit_boundaries.apply(ms, merge_visible_layers=True, normals=Normals.ESTIMATE)
    assert out["normals_estimated"] and out["boundary_loops"] == 0
    assert inward_fraction(ms.current_mesh()) > 0.99
    # Without cameras (the same points in plain layers): outward.
    plain = pymeshlab.MeshSet()
    plain.add_mesh(pymeshlab.Mesh(vertex_matrix=upper))
    plain.add_mesh(pymeshlab.Mesh(vertex_matrix=lower))
    implicit_boundaries.apply(plain, merge_visible_layers=True, normals=Normals.ESTIMATE)
    assert inward_fraction(plain.current_mesh()) < 0.01


def test_estimated_normals_follow_the_range_grids_triangles(plugin):
    """A scan with faces (MeshLab triangulates a range grid on import), its triangles facing
    the inside of the sphere: estimated normals follow them (inward); a point layer of the same
    vertices comes out outward."""
    u = fibonacci_sphere(4000)
    hull = pymeshlab.MeshSet()
    hull.add_mesh(pymeshlab.Mesh(vertex_matrix=u))
    hull.generate_convex_hull()
    faces = hull.current_mesh().face_matrix()[:, ::-1]  # turned inward
    vertices = hull.current_mesh().vertex_matrix()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces), "range grid")
    implicit_boundaries.apply(ms, normals=Normals.ESTIMATE)
    assert inward_fraction(ms.current_mesh()) > 0.99
    # The same grid placed by a matrix (turned, stretched, moved): the triangles still decide.
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_about_z(50) @ np.diag([1.5, 1, 1])
    matrix[:3, 3] = [2, 0, 0]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces), "range grid")
    ms.set_matrix(transformmatrix=matrix, freeze=False)
    implicit_boundaries.apply(ms, normals=Normals.ESTIMATE)
    moved = ms.current_mesh()
    v, f = moved.vertex_matrix() - matrix[:3, 3], moved.face_matrix()
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    assert (np.sum(normal * v[f].mean(axis=1), axis=1) < 0).mean() > 0.99
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices), "points")
    implicit_boundaries.apply(ms, normals=Normals.ESTIMATE)
    assert inward_fraction(ms.current_mesh()) < 0.01


def test_a_gap_no_scan_reached_is_filled_and_a_real_hole_kept(plugin):
    """Two overlapping scans of the wavy sheet, neither reaching a strip 4 spacings wide and 20
    long in their overlap (occlusion: a gap in the coverage, its loop far over the edge count of
    an undersampling gap), and a round hole of radius 8 spacings in the second scan's part.
    Merged: the strip, within 2 spacings of the samples everywhere, is filled; the hole, 8
    spacings deep, stays: the sheet's border and the hole. The same samples as one scan keep
    the strip open (a single scan's gaps are judged by their loops' size)."""
    spacing = 0.02
    rng = np.random.default_rng(2)
    scans = [strip_scan((-1, 0.3), spacing, rng), strip_scan((-0.3, 1), spacing, rng)]
    kept = []
    for points, normals in scans:
        strip = (np.abs(points[:, 0]) < 2 * spacing) & (np.abs(points[:, 1]) < 10 * spacing)
        hole = np.hypot(points[:, 0] - 0.6, points[:, 1] - 0.4) < 8 * spacing
        kept.append((points[~strip & ~hole], normals[~strip & ~hole]))
    merged = pymeshlab.MeshSet()
    for points, normals in kept:
        merged.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals))
    out = implicit_boundaries.apply(merged, merge_visible_layers=True)
    loops = implicit_boundaries.loops_from_result(out)
    assert len(loops) == 2
    centre = merged.current_mesh().vertex_matrix()[loops[1]].mean(axis=0)
    assert np.hypot(centre[0] - 0.6, centre[1] - 0.4) < spacing  # the round hole
    one = pymeshlab.MeshSet()
    one.add_mesh(pymeshlab.Mesh(vertex_matrix=np.vstack([p for p, _ in kept]), v_normals_matrix=np.vstack([n for _, n in kept])))
    assert implicit_boundaries.apply(one)["boundary_loops"] == 3
