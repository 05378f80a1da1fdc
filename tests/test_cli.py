"""The command line, called in-process."""
import pymeshlab

from implicit_boundaries.cli import main


def test_demo_writes_the_bunny_and_reports_its_loops(tmp_path, capsys, plugin):
    out = tmp_path / "bunny.ply"
    assert main(["demo", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "boundary loops kept; edges per loop:" in text and str(out) in text
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out))
    assert ms.current_mesh().face_number() > 10000


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
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no such file" in err[0]


def test_bad_parameter_is_reported_not_raised(tmp_path, capsys, plugin):
    assert main(["demo", "-o", str(tmp_path / "x.ply"), "--resolution", "-3"]) == 1
    assert "out of range" in capsys.readouterr().err


def test_info_reports_the_plugin(capsys, plugin):
    assert main(["info"]) == 0
    assert "loads" in capsys.readouterr().out


def test_options_reach_the_filter(tmp_path, capsys, plugin):
    keep_all = tmp_path / "all.ply"
    assert main(["demo", "-o", str(keep_all), "--min-boundary-edges", "0", "--boundary-smoothing", "0"]) == 0
    unfilled = capsys.readouterr().out
    assert main(["demo", "-o", str(tmp_path / "default.ply")]) == 0
    filled = capsys.readouterr().out
    count = lambda text: int(text.split(" boundary loops kept")[0].split()[-1])
    assert count(unfilled) > count(filled)
