"""The command line, called in-process."""
import re

import numpy as np
import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.cli import DEMO_SCAN, main
from shapes import fibonacci_sphere
from test_compare import two_holed_sphere


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("implicit-boundaries: error: ")
    return err[0]


def test_demo_writes_the_bunny_compares_it_and_says_where(tmp_path, capsys, plugin):
    out, report = tmp_path / "bunny.ply", tmp_path / "report"
    assert main(["demo", "-o", str(out), "--report", str(report), "--resolution", "40"]) == 0
    text = capsys.readouterr().out
    assert "boundary loops kept; edges per loop:" in text and str(out) in text
    assert f"report: {report / 'report.html'}" in text
    assert "| screened Poisson + density trim |" in text and "chamfer" in text  # the bunny's mesh is the truth
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out))
    assert ms.current_mesh().face_number() > 10000
    assert (report / "side_by_side.png").is_file()


@pytest.fixture
def sphere_files(tmp_path):
    """A point cloud (PLY with normals) and its true mesh (OFF) of a sphere with two holes."""
    points, faces = two_holed_sphere(1500)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=points))
    ms.save_current_mesh(str(tmp_path / "cloud.ply"))
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, face_matrix=faces))
    ms.save_current_mesh(str(tmp_path / "truth.off"))
    return tmp_path / "cloud.ply", tmp_path / "truth.off"


def test_compare_writes_the_report_and_prints_the_table(sphere_files, tmp_path, capsys, plugin):
    cloud, truth = sphere_files
    report = tmp_path / "out" / "report"
    assert main(["compare", str(cloud), "--truth", str(truth), "--report", str(report), "--resolution", "24",
                 "--trim-quantile", "0.1"]) == 0
    captured = capsys.readouterr()
    lines = {line.split("|")[1].strip(): line for line in captured.out.splitlines() if line.startswith("| ")}
    assert {"implicit with boundaries", "screened Poisson", "screened Poisson + density trim"} <= set(lines)
    assert "| 2/2 |" in lines["implicit with boundaries"]
    assert f"report: {report / 'report.html'}" in captured.out
    assert "0.1" in (report / "report.html").read_text()  # the trim quantile used
    assert re.search(r"\b(\d+)/\1 done", captured.err)  # the progress bar, to its end


def test_compare_bad_arguments_exit_2_with_usage(capsys):
    with pytest.raises(SystemExit) as exit:
        main(["compare", "cloud.ply"])  # no --report
    assert exit.value.code == 2 and "--report" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit:
        main(["compare", "cloud.ply", "--report", "r", "--trim-quantile", "lots"])
    assert exit.value.code == 2


def test_compare_refuses_a_bad_quantile_in_one_line(sphere_files, tmp_path, capsys):
    cloud, _ = sphere_files
    assert main(["compare", str(cloud), "--report", str(tmp_path / "r"), "--trim-quantile", "1.5"]) == 1
    assert "quantile" in one_error_line(capsys)


@pytest.mark.parametrize("command", ["compare", "reconstruct"])
def test_unreadable_input_is_one_line_and_status_1(command, tmp_path, capsys):
    bad = tmp_path / "garbage.ply"
    bad.write_text("not a mesh\n")
    extra = ["--report", str(tmp_path / "r")] if command == "compare" else ["-o", str(tmp_path / "x.ply")]
    assert main([command, str(bad), *extra]) == 1
    assert "garbage.ply" in one_error_line(capsys)


def test_unreadable_truth_is_one_line_and_status_1(sphere_files, tmp_path, capsys, plugin):
    cloud, _ = sphere_files
    bad = tmp_path / "truth.obj"
    bad.write_text("v 0 0 0\n")  # a vertex, no faces
    assert main(["compare", str(cloud), "--truth", str(bad), "--report", str(tmp_path / "r")]) == 1
    assert "no faces" in one_error_line(capsys)
    assert main(["compare", str(cloud), "--truth", str(tmp_path / "none.ply"), "--report", str(tmp_path / "r")]) == 1
    assert "no such file" in one_error_line(capsys)


def test_verbose_shows_the_exception(tmp_path):
    with pytest.raises(FileNotFoundError):
        main(["--verbose", "compare", str(tmp_path / "nope.ply"), "--report", str(tmp_path / "r")])


@pytest.mark.parametrize("source, target", [("xyz", "stl"), ("ply", "off"), ("off", "obj")])
def test_reconstruct_converts_between_formats(source, target, tmp_path, capsys, plugin):
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(DEMO_SCAN))
    src = tmp_path / f"cloud.{source}"
    ms.save_current_mesh(str(src))
    out = tmp_path / f"surface.{target}"
    assert main(["reconstruct", str(src), "-o", str(out), "--resolution", "32"]) == 0
    ms.load_new_mesh(str(out))
    assert ms.current_mesh().face_number() > 1000


def test_unknown_output_format_is_one_line(tmp_path, capsys, plugin):
    assert main(["reconstruct", str(DEMO_SCAN), "-o", str(tmp_path / "x.nope"), "--resolution", "32"]) == 1
    assert "nope" in one_error_line(capsys)


def test_reconstruct_reads_and_writes_files(tmp_path, capsys, plugin):
    src = tmp_path / "cloud.ply"
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(__import__("conftest").SAMPLES / "bunny.obj"))
    ms.save_current_mesh(str(src))
    out = tmp_path / "sub" / "surface.obj"
    assert main(["reconstruct", str(src), "-o", str(out), "--resolution", "60"]) == 0
    assert out.is_file()
    assert "resolution 60" in capsys.readouterr().out


def test_missing_input_is_one_line_and_status_1(tmp_path, capsys):
    assert main(["reconstruct", str(tmp_path / "nope.ply"), "-o", str(tmp_path / "x.ply")]) == 1
    assert "no such file" in one_error_line(capsys)
    assert main(["compare", str(tmp_path / "nope.ply"), "--report", str(tmp_path / "r")]) == 1
    assert "no such file" in one_error_line(capsys)


def test_bad_parameter_is_reported_not_raised(tmp_path, capsys, plugin):
    assert main(["demo", "-o", str(tmp_path / "x.ply"), "--resolution", "-3"]) == 1
    assert "out of range" in capsys.readouterr().err


def test_info_reports_the_plugin(capsys, plugin):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "built for MeshLab 2025.07d (double)" in out and "loads" in out


def test_a_plugin_of_the_other_precision_is_named_not_loaded(tmp_path, capsys, plugin, monkeypatch):
    """The float plugin (for the MeshLab 2025.07 GUI) given to pymeshlab: info and load() say
    which MeshLab the file fits and which one to use. Made from the double module by changing
    its build tag (the float module is built by `make gui`)."""
    module = implicit_boundaries.plugin_path().read_bytes()
    assert module.count(b"scalar=double") == 1
    fake = tmp_path / "libfilter_implicit_boundaries.so"
    fake.write_bytes(module.replace(b"scalar=double", b"scalar=float\0"))
    monkeypatch.setenv("IMPLICIT_BOUNDARIES_PLUGIN", str(fake))
    assert main(["info"]) == 1
    out = capsys.readouterr().out
    assert "built for MeshLab 2025.07 (float)" in out
    assert "embeds MeshLab 2025.07d (double): use the double plugin" in out
    with pytest.raises(OSError, match=r"built for MeshLab 2025.07 \(float\)"):
        implicit_boundaries.load()


def test_options_reach_the_filter(tmp_path, capsys, plugin):
    fill_more = tmp_path / "fill_more.ply"  # the bunny's holes have loops of 13 to 47 edges
    assert main(["reconstruct", str(DEMO_SCAN), "-o", str(fill_more), "--min-boundary-edges", "20",
                 "--boundary-smoothing", "0"]) == 0
    filled = capsys.readouterr().out
    assert main(["reconstruct", str(DEMO_SCAN), "-o", str(tmp_path / "default.ply")]) == 0
    default = capsys.readouterr().out
    count = lambda text: int(text.split(" boundary loops kept")[0].split()[-1])
    assert 0 < count(filled) < count(default)


def test_viewpoint_orients_the_estimated_normals(tmp_path, capsys, plugin):
    """--viewpoint: normals estimated facing the scanner, so the faces turn with it."""
    import numpy as np

    from test_reconstruct import fibonacci_sphere
    points, _ = fibonacci_sphere(4000)
    src = tmp_path / "dome.ply"
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points[points[:, 2] > 0.2]))
    ms.save_current_mesh(str(src))
    facing = []
    for z in ("5", "-5"):
        out = tmp_path / f"dome{z}.ply"
        assert main(["reconstruct", str(src), "-o", str(out), "--viewpoint", "0", "0", z]) == 0
        assert f"normals estimated, facing the viewpoint (0, 0, {z})" in capsys.readouterr().out
        ms.load_new_mesh(str(out))
        v, f = ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()
        a, b, c = (v[f[:, i]] for i in range(3))
        facing.append(np.mean(np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) > 0))
    assert facing[0] > 0.999 and facing[1] < 0.001


def quaternion(axis, degrees):
    """(qx, qy, qz, qw) of the rotation by `degrees` about the unit `axis`."""
    half = np.radians(degrees) / 2
    return (*(np.sin(half) * np.asarray(axis, dtype=float)), np.cos(half))


@pytest.mark.parametrize("alignment", ["aln", "mlp", "conf"])
def test_scans_placed_by_an_alignment_file_are_merged(alignment, tmp_path, capsys, plugin):
    """A sphere scanned as two overlapping caps, the lower one stored in its scanner's frame
    (turned 90 degrees about x, moved), and an alignment file that places it (MeshLab's .aln: its
    matrix; its project .mlp: each layer's matrix as pymeshlab's load_project reads it, and a
    hidden layer, left out; Stanford's .conf: translation and quaternion, world = R(q)^-1 p + t):
    one closed sphere. Each cap alone has one loop."""
    u = fibonacci_sphere(6000)
    upper, lower = u[u[:, 2] > -0.2], u[u[:, 2] < 0.2]
    t = np.array([0.3, -0.2, 0.1])
    q = quaternion([1, 0, 0], 90)
    rotation = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # R(q)
    lower_local = (lower - t) @ rotation.T  # p = R (world - t)
    for name, points in (("upper", upper), ("lower", lower_local)):
        ms = pymeshlab.MeshSet()
        normals = upper if name == "upper" else lower @ rotation.T  # outward, turned with the points
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals))
        ms.save_current_mesh(str(tmp_path / f"{name}.ply"))
    world = np.eye(4)  # the matrix that places the lower cap (.aln, .mlp)
    world[:3, :3], world[:3, 3] = rotation.T, t
    if alignment == "aln":
        rows = lambda m: "\n".join(" ".join(f"{x:.17g}" for x in row) for row in m)
        text = f"2\nupper.ply\n#\n{rows(np.eye(4))}\nlower.ply\n#\n{rows(world)}\n0\n"
    elif alignment == "mlp":
        layer = lambda name, m, visible=1: (f'<MLMesh visible="{visible}" label="{name}" filename="{name}">'
                                            f'<MLMatrix44>\n{" ".join(f"{x:.17g}" for x in m.ravel())}\n</MLMatrix44></MLMesh>')
        text = (f"<!DOCTYPE MeshLabDocument>\n<MeshLabProject><MeshGroup>{layer('upper.ply', np.eye(4))}"
                f"{layer('lower.ply', world)}{layer('upper.ply', np.eye(4), visible=0)}</MeshGroup></MeshLabProject>")
    else:
        text = ("camera 0 0 0 0 0 0 1\nbmesh upper.ply 0 0 0 0 0 0 1\n"
                f"bmesh lower.ply {t[0]} {t[1]} {t[2]} {q[0]} {q[1]} {q[2]} {q[3]}\n")
    (tmp_path / f"scans.{alignment}").write_text(text)
    out = tmp_path / "merged.ply"
    if alignment == "mlp":  # MeshLab itself places the lower cap where the project says
        ms = pymeshlab.MeshSet()
        ms.load_project(str(tmp_path / "scans.mlp"))
        assert ms.mesh_number() == 3
        assert np.allclose(ms.mesh(1).transform_matrix(), world)
    if alignment in ("aln", "mlp"):  # the alignment file stands for its scans
        assert main(["reconstruct", str(tmp_path / f"scans.{alignment}"), "-o", str(out)]) == 0
    else:  # the scans, placed by the alignment file
        assert main(["reconstruct", str(tmp_path / "upper.ply"), str(tmp_path / "lower.ply"),
                     "--alignment", str(tmp_path / f"scans.{alignment}"), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "merging 2 scans" in printed and "0 boundary loops kept" in printed
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out))
    assert np.abs(np.linalg.norm(ms.current_mesh().vertex_matrix(), axis=1) - 1).max() < 0.02
    assert main(["reconstruct", str(tmp_path / "upper.ply"), "-o", str(out)]) == 0
    assert "1 boundary loops kept" in capsys.readouterr().out


def test_a_broken_alignment_file_is_one_line(tmp_path, capsys):
    (tmp_path / "scans.aln").write_text("2\nupper.ply\n#\n1 0 0\n")
    assert main(["reconstruct", str(tmp_path / "scans.aln"), "-o", str(tmp_path / "out.ply")]) == 1
    assert "not a MeshLab alignment" in one_error_line(capsys)


def test_a_broken_project_file_is_one_line(tmp_path, capsys):
    (tmp_path / "scans.mlp").write_text('<MeshLabProject><MeshGroup><MLMesh filename="a.ply"><MLMatrix44>1 0 0'
                                        '</MLMatrix44></MLMesh></MeshGroup></MeshLabProject>')
    assert main(["reconstruct", str(tmp_path / "scans.mlp"), "-o", str(tmp_path / "out.ply")]) == 1
    assert "layer a.ply: its MLMatrix44 is not 16 numbers" in one_error_line(capsys)
    (tmp_path / "scans.mlp").write_text("<MeshLabProject><MeshGroup>")
    assert main(["reconstruct", str(tmp_path / "scans.mlp"), "-o", str(tmp_path / "out.ply")]) == 1
    assert "not a MeshLab project" in one_error_line(capsys)


def test_a_scan_missing_from_the_alignment_is_one_line(tmp_path, capsys):
    (tmp_path / "scans.conf").write_text("bmesh upper.ply 0 0 0 0 0 0 1\n")
    (tmp_path / "other.ply").write_text("")
    assert main(["reconstruct", str(tmp_path / "other.ply"), "--alignment", str(tmp_path / "scans.conf"),
                 "-o", str(tmp_path / "out.ply")]) == 1
    assert "other.ply is not in" in one_error_line(capsys)


def test_a_listed_scan_that_is_missing_is_one_line(tmp_path, capsys):
    (tmp_path / "scans.conf").write_text("bmesh upper.ply 0 0 0 0 0 0 1\n")
    assert main(["reconstruct", str(tmp_path / "scans.conf"), "-o", str(tmp_path / "out.ply")]) == 1
    assert "upper.ply: no such file" in one_error_line(capsys)


@pytest.mark.parametrize("matrix, message", [
    ("1 0 0 0\n0 1 0 0\n0 0 1 0\n0.3 -0.2 0.1 1", "last row is 0.3 -0.2 0.1 1, not 0 0 0 1"),  # written transposed
    ("2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1", "scales, shears or mirrors the scan by up to 100%"),
    ("-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1", "scales, shears or mirrors"),
])
def test_a_non_rigid_alignment_matrix_is_one_line(matrix, message, tmp_path, capsys):
    """An alignment only moves and turns scans: a matrix that projects (a transposed one),
    scales or mirrors is refused, naming the scan, before any scan is read."""
    (tmp_path / "scans.aln").write_text(f"1\nupper.ply\n#\n{matrix}\n0\n")
    assert main(["reconstruct", str(tmp_path / "scans.aln"), "-o", str(tmp_path / "out.ply")]) == 1
    line = one_error_line(capsys)
    assert "scan upper.ply" in line and message in line


def test_a_zero_quaternion_is_one_line(tmp_path, capsys):
    (tmp_path / "scans.conf").write_text("bmesh upper.ply 0 0 0 0 0 0 0\n")
    assert main(["reconstruct", str(tmp_path / "scans.conf"), "-o", str(tmp_path / "out.ply")]) == 1
    assert "quaternion (qx qy qz qw) is zero" in one_error_line(capsys)
