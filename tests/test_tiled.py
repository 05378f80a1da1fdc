"""Tiled reconstruction on Dask: tiles joined into the surface of one run."""
import numpy as np
import pymeshlab
import pytest

from implicit_boundaries import reconstruct, tiled
from implicit_boundaries.metrics import boundary_edges, point_mesh_distance
from implicit_boundaries.tile_join import Join, border_half_edges, trace_loops

from shapes import terrain_with_pond, wavy_cap


@pytest.fixture(scope="module")
def cap():
    return wavy_cap(200_000, seed=3)


@pytest.fixture(scope="module")
def joined(plugin, cap):
    points, normals = cap
    return tiled.reconstruct(points, normals, tiles=8, workers=2)


def test_eight_tiles_on_two_workers_join_into_the_single_runs_surface(plugin, cap, joined):
    # 200,000 random samples of an open wavy cap, in at least 8 tiles on a local cluster of 2
    # worker processes, against one run on the same lattice: the same loops, edge for edge, the
    # same faces, and every vertex on the one run's surface, to a thousandth of a cell, boundary
    # smoothing and fit included (with the smoothing swept from where each loop was entered, a
    # vertex was half a cell off).
    points, normals = cap
    p = tiled.plan(points, normals, tiles=8)
    assert joined.info["tiles"] >= 8
    one = reconstruct(points, normals, **p.filter_params(p.origin, p.origin))  # equal corners: all faces
    assert [len(loop) for loop in joined.loops] == [len(loop) for loop in one.loops]
    assert len(one.loops) >= 1 and len(one.loops[0]) > 1000  # the rim
    assert len(joined.faces) == len(one.faces)
    distance = point_mesh_distance(joined.vertices, one.vertices, one.faces)
    assert distance.max() < 1e-3 * p.cell


def test_seams_hold_no_border_edge(cap, joined):
    # No border edge runs along a block's plane inside the scan: every border vertex off the
    # rim (z near -0.2) belongs to a small gap of the random sampling, none lies on a seam.
    points, normals = cap
    p = tiled.plan(points, normals, tiles=8)
    border = joined.vertices[np.unique(boundary_edges(joined.faces))]
    for axis in range(3):
        inner = p.planes[axis][1:-1]
        if len(inner):
            near = np.abs(border[:, axis, None] - inner[None, :]).min(axis=1) < 1e-9 * p.cell
            assert near.sum() <= 2, f"{near.sum()} border vertices on a seam across axis {axis}"
    assert np.count_nonzero(border[:, 2] > -0.15) == sum(len(loop) for loop in joined.loops[1:])


def test_holes_across_seams_are_filled_or_kept_as_one_run_decides(plugin):
    # Holes cut into a terrain right on the seams of its 4 tiles, from 2 to 5 spacings in
    # radius: each tile decides with its halo which of them are undersampling (filled) and which
    # stay open, and the joined surface has one run's loops, edge for edge, and its faces.
    spacing = 0.006
    points, normals = terrain_with_pond(spacing=spacing, noise=0.0, seed=1)
    x, y = (tiled.plan(points, normals, tiles=4).planes[a][1] for a in range(2))
    holes = [((x, 0.15), 5.0), ((x, 0.8), 2.0), ((x, 0.92), 2.4), ((0.1, y), 2.2), ((0.25, y), 2.6), ((0.35, y), 4.0)]
    keep = np.ones(len(points), dtype=bool)
    for (cx, cy), radius in holes:
        keep &= np.hypot(points[:, 0] - cx, points[:, 1] - cy) > radius * spacing
    points, normals = points[keep], normals[keep]
    p = tiled.plan(points, normals, tiles=4)
    assert np.allclose([p.planes[0][1], p.planes[1][1]], [x, y], atol=p.cell)
    one = reconstruct(points, normals, **p.filter_params(p.origin, p.origin))
    joined = tiled.reconstruct(points, normals, tiles=4, workers=2)
    assert [len(loop) for loop in joined.loops] == [len(loop) for loop in one.loops]
    assert len(joined.faces) == len(one.faces)
    # The border and the pond, and three of the cut holes; the two smallest were filled.
    assert len(one.loops) == 5 and one.info["holes_filled"] >= 2
    seam_loops = [joined.vertices[loop] for loop in joined.loops if len(loop) < 200]
    assert len(seam_loops) == 3
    for loop in seam_loops:  # each one straddles a seam
        assert any(loop[:, a].min() < plane < loop[:, a].max() for a, plane in ((0, x), (1, y)))


def test_holes_filled_at_a_raised_min_boundary_edges_are_decided_as_one_run_does(plugin):
    # At min_boundary_edges 400 one run fills the terrain's pond (25 spacings in radius) and a
    # hole of 20 spacings cut on a seam of its 4 tiles. The pond reaches 42
    # spacings past the seam, beyond a halo of 40: the halo grows with min_boundary_edges so
    # that every tile sees whole each hole it may fill (with 40, the tile beside the pond kept
    # it open: 2 loops).
    spacing = 0.006
    points, normals = terrain_with_pond(spacing=spacing, noise=0.0, seed=1)
    x = tiled.plan(points, normals, tiles=4).planes[0][1]
    keep = np.hypot(points[:, 0] - x, points[:, 1] - 0.75) > 20 * spacing
    points, normals = points[keep], normals[keep]
    params = dict(min_boundary_edges=400)
    p = tiled.plan(points, normals, tiles=4, min_boundary_edges=400)
    assert p.halo > 0.15 + 0.1  # the pond's radius and its centre's distance to the seam
    one = reconstruct(points, normals, **p.filter_params(p.origin, p.origin), **params)
    assert len(one.loops) == 1 and one.info["holes_filled"] == 2
    joined = tiled.reconstruct(points, normals, tiles=4, workers=2, **params)
    assert joined.info["halo"] == pytest.approx(p.halo)
    assert [len(loop) for loop in joined.loops] == [len(loop) for loop in one.loops]
    assert len(joined.faces) == len(one.faces)


def test_the_halo_grows_with_the_widest_hole_the_filter_may_fill():
    spacing, cell = 1.0, tiled.CELL_PER_SPACING
    assert tiled.halo_width(spacing, cell, 0) == tiled.HALO_SPACINGS
    assert tiled.halo_width(spacing, cell) == pytest.approx(tiled.HALO_SPACINGS + 12 * np.sqrt(3) / 2 * cell)
    assert tiled.halo_width(spacing, 100.0, 12) == pytest.approx(40 + 12 * np.sqrt(3) / 2 * 100)
    assert tiled.halo_width(spacing, 20.0, 0) == 60  # at least 3 cells


def test_the_plan_covers_every_sample_with_grid_aligned_blocks(cap):
    points, normals = cap
    p = tiled.plan(points, normals, tiles=8)
    assert p.count() >= 8
    assert np.all(points >= p.origin) and np.all(points <= p.end)
    for axis in range(3):
        k = (p.planes[axis] - p.origin[axis]) / p.cell
        np.testing.assert_allclose(k, np.round(k), atol=1e-6)
    assert p.cell == pytest.approx(tiled.CELL_PER_SPACING * p.spacing)
    # The filter's spacing (the 8th neighbour's disk) on a uniform cap: area per sample.
    area = 2 * np.pi * 1.2 * 1.03  # the cap's area, near enough
    assert p.spacing == pytest.approx(np.sqrt(area / len(points)), rel=0.25)


def test_missing_normals_are_refused_with_what_to_do(cap):
    points, _ = cap
    with pytest.raises(ValueError, match="needs the samples' normals"):
        tiled.reconstruct(points[:1000], tiles=2, workers=1)


@pytest.mark.parametrize("params, message", [
    (dict(lattice_cell=0.05, lattice_origin=np.zeros(3), lattice_end=np.ones(3), resolution=64),
     "leave the resolution at 0"),
    (dict(lattice_cell=0.05, lattice_origin=np.zeros(3), lattice_end=np.ones(3)), "outside the fixed lattice"),
    (dict(block_min=np.zeros(3), block_max=np.ones(3)), "needs the fixed lattice"),
    (dict(lattice_cell=0.05, lattice_origin=np.zeros(3), lattice_end=np.zeros(3)), "end above its origin"),
])
def test_the_filters_tile_parameters_refuse_bad_values(plugin, cap, params, message):
    points, normals = cap
    with pytest.raises(pymeshlab.PyMeshLabException, match=message):
        reconstruct(points[:2000], normals[:2000], **params)


def test_the_command_line_writes_the_tiled_surface(plugin, tmp_path, capsys):
    from implicit_boundaries.cli import main
    points, normals = wavy_cap(20_000, seed=1)
    scan = tmp_path / "cap.ply"
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals))
    ms.save_current_mesh(str(scan), save_vertex_normal=True)
    out = tmp_path / "tiled.ply"
    assert main(["tiled", str(scan), "-o", str(out), "--tiles", "2", "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "2 tiles" in printed and "1 boundary loops kept" in printed
    ms.load_new_mesh(str(out))
    assert ms.current_mesh().face_number() > 20_000
    assert len(trace_loops(border_half_edges(ms.current_mesh().face_matrix()))) == 1


def test_the_command_line_refuses_estimated_normals(tmp_path, capsys):
    from implicit_boundaries.cli import main
    assert main(["tiled", str(tmp_path / "any.ply"), "-o", str(tmp_path / "o.ply"), "--estimate-normals"]) == 1
    assert "oriented by propagation" in capsys.readouterr().err


@pytest.mark.parametrize("alignment", ["project.aln", "project.mlp", "bun.conf"])
def test_the_command_line_refuses_an_alignment_and_says_what_merges_it(alignment, tmp_path, capsys):
    from implicit_boundaries.cli import main
    assert main(["tiled", str(tmp_path / alignment), "-o", str(tmp_path / "o.ply")]) == 1
    error = capsys.readouterr().err
    assert "not an alignment" in error and f"implicit-boundaries reconstruct {tmp_path / alignment}" in error


def _grid(n):
    """A flat n x n grid of unit squares, two triangles each: (vertices, faces)."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    vertices = np.column_stack([i.ravel(), j.ravel(), np.zeros(i.size)]).astype(np.float64)
    at = lambda a, b: a * (n + 1) + b
    faces = []
    for a in range(n):
        for b in range(n):
            faces += [(at(a, b), at(a + 1, b), at(a + 1, b + 1)), (at(a, b), at(a + 1, b + 1), at(a, b + 1))]
    return vertices, np.array(faces, dtype=np.int32)


def test_the_join_welds_pieces_at_their_seam_and_streams_them(tmp_path):
    # A 10 x 10 grid cut into two pieces at x = 4.5 (face centres), one piece's seam vertices off
    # by 1e-12: joined, the grid's 121 vertices and 200 faces, and its one 40-edge border, in
    # memory and in the PLY file.
    vertices, faces = _grid(10)
    centre_x = vertices[faces].mean(axis=1)[:, 0]
    join = Join(1e-6)
    for keep, shift in ((centre_x < 4.5, 0.0), (centre_x >= 4.5, 1e-12)):
        used, local = np.unique(faces[keep], return_inverse=True)
        join.add(vertices[used] + shift, local.reshape(-1, 3))
    loops = join.finish()
    V, F = join.arrays()
    assert (len(V), len(F)) == (121, 200)
    assert [len(loop) for loop in loops] == [40]
    out = tmp_path / "joined.ply"
    join.write_ply(out)
    join.close()
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out))
    assert (ms.current_mesh().vertex_number(), ms.current_mesh().face_number()) == (121, 200)
    np.testing.assert_array_equal(ms.current_mesh().face_matrix(), F)
    assert len(trace_loops(border_half_edges(F))) == 1


def test_a_lidar_file_without_normals_is_tiled_with_normals_facing_the_sensor(plugin, tmp_path, capsys):
    # A LAS file of a terrain with a pond (no normals stored), in 4 tiles, normals estimated by
    # each tile facing a viewpoint high above: the terrain's border and the pond's, as one
    # run with the same viewpoint gives.
    import laspy
    from implicit_boundaries.cli import main
    points, _ = terrain_with_pond(spacing=0.005, noise=0.0)
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales = np.full(3, 1e-6)
    header.offsets = points.min(axis=0)
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    scan = tmp_path / "terrain.las"
    las.write(str(scan))
    out = tmp_path / "terrain.ply"
    assert main(["tiled", str(scan), "-o", str(out), "--tiles", "4", "--workers", "2",
                 "--viewpoint", "0.5", "0.5", "10"]) == 0
    assert "2 boundary loops kept" in capsys.readouterr().out
    one = reconstruct(points, viewpoint=np.array([0.5, 0.5, 10.0]))
    assert len(one.loops) == 2


def test_binary_ply_is_read_in_chunks_and_binned_to_every_tile_whose_halo_holds_it(tmp_path, monkeypatch):
    from implicit_boundaries import tile_input
    points, normals = wavy_cap(5_000, seed=2)
    scan = tmp_path / "cap.ply"
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals))
    ms.save_current_mesh(str(scan), binary=True, save_vertex_normal=True)
    monkeypatch.setattr(tile_input, "CHUNK", 1_234)
    read = list(tile_input.chunks([scan]))
    assert len(read) == 5  # 5,000 samples in chunks of 1,234
    np.testing.assert_allclose(np.concatenate([p for p, _ in read]), points, atol=1e-6)  # float32 in the file
    np.testing.assert_allclose(np.concatenate([n for _, n in read]), normals, atol=1e-6)
    p = tiled.plan([scan], tiles=8)
    bins = tile_input.Bins(p.planes, p.halo)
    for chunk, n in read:
        bins.add(chunk, n)
    stored = np.concatenate([p for p, _ in read])
    for t, (_, lo, hi) in enumerate(p.blocks()):
        expected = np.flatnonzero(np.all((stored >= lo - p.halo) & (stored <= hi + p.halo), axis=1))
        got, _ = bins.samples(t)
        np.testing.assert_array_equal(got, stored[expected])  # the same rows, in input order
    bins.close()


def test_a_tiles_error_says_which_tile_and_why(plugin, cap):
    points, normals = cap
    with pytest.raises(ValueError, match=r"(?s)tile \(\d, \d, \d\) \(\d+ samples\):.*Boundary smoothing must be"):
        tiled.reconstruct(points[:20_000], normals[:20_000], tiles=2, workers=1, boundary_smoothing=500)
