"""The wheel (`make wheel`) installs into a fresh virtual environment and runs there, away from
the source tree: the package imports, loads the plugin it carries into pymeshlab, and the
command line reconstructs a scan."""
import os
import subprocess
import sys
from pathlib import Path

import pymeshlab

from test_compare import two_holed_sphere

ROOT = Path(__file__).resolve().parent.parent


def test_the_wheel_runs_in_a_fresh_virtual_environment(tmp_path, plugin):
    # What `make wheel` runs, into a folder of this test's own.
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp_path / "dist"),
                    str(ROOT / "python")], check=True)
    (wheel,) = (tmp_path / "dist").glob("implicit_boundaries-*.whl")
    assert wheel.name.endswith("linux_x86_64.whl")  # it carries a compiled plugin: not py3-none-any

    subprocess.run([sys.executable, "-m", "venv", str(tmp_path / "venv")], check=True)
    bin_dir = tmp_path / "venv" / "bin"
    subprocess.run([str(bin_dir / "python"), "-m", "pip", "install", "-q", str(wheel)], check=True)

    points, _ = two_holed_sphere(1500)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=points))
    ms.save_current_mesh(str(tmp_path / "cloud.ply"))

    # Nothing of the source tree or this environment's plugin may leak in.
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "IMPLICIT_BOUNDARIES_PLUGIN")}
    loaded = subprocess.run([str(bin_dir / "python"), "-c", "import implicit_boundaries; print(implicit_boundaries.load())"],
                            cwd=tmp_path, env=env, capture_output=True, text=True, check=True)
    assert Path(loaded.stdout.strip()).is_relative_to(tmp_path / "venv")

    done = subprocess.run([str(bin_dir / "implicit-boundaries"), "reconstruct", "cloud.ply", "-o", "surface.ply"],
                          cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "2 boundary loops kept" in done.stdout  # the sphere's two holes
    ms.load_new_mesh(str(tmp_path / "surface.ply"))
    assert ms.current_mesh().face_number() > 1000
