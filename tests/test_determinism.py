"""The same input and parameters give the same output bit for bit, run after run: twice in this
process and once in a fresh one (where allocation addresses, and anything ordered by them,
differ). The C++ tests check 1 against 2 threads."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.options import Implicit, Normals
from shapes import fibonacci_sphere

IMPLICITS = [Implicit.HOPPE, Implicit.PU_RBF]


def open_sphere():
    """A unit sphere with a cap cut off (so loops, trimming and smoothing all run), with a
    little noise: points and outward normals."""
    normals = fibonacci_sphere(2500)
    normals = normals[normals[:, 2] < 0.6]
    noise = np.random.default_rng(7).normal(scale=0.003, size=normals.shape)
    return normals + noise, normals


def run(implicit, estimate):
    """Vertices, faces and loop vertices of one filter run on a fresh MeshSet."""
    points, normals = open_sphere()
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "sphere")
    result = implicit_boundaries.apply(ms, implicit=implicit, normals=Normals.ESTIMATE if estimate else Normals.USE_LAYER)
    out = ms.current_mesh()
    return (out.vertex_matrix().copy(), out.face_matrix().copy(),
            np.asarray(result["boundary_loop_vertices"]).copy())


def assert_identical(a, b):
    for x, y in zip(a, b):
        assert x.shape == y.shape and x.dtype == y.dtype
        assert x.tobytes() == y.tobytes()  # bit for bit, not approximately


@pytest.mark.parametrize("estimate", [False, True], ids=["layer normals", "estimated normals"])
@pytest.mark.parametrize("implicit", IMPLICITS)
def test_same_output_run_after_run(plugin, tmp_path, implicit, estimate):
    first = run(implicit, estimate)
    assert len(first[1]) > 1000 and len(first[2]) > 0  # a real surface with a boundary
    assert_identical(first, run(implicit, estimate))

    saved = tmp_path / "child.npz"
    script = (f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
              "import numpy as np, implicit_boundaries, test_determinism as t\n"
              "implicit_boundaries.load()\n"
              f"np.savez({str(saved)!r}, *t.run({implicit!r}, {estimate!r}))\n")
    child = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert child.returncode == 0, child.stderr[-2000:]
    with np.load(saved) as fresh:
        assert_identical(first, [fresh[f"arr_{i}"] for i in range(3)])
