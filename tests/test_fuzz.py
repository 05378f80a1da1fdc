"""Fuzzing the filter through pymeshlab: random point clouds and parameters either give a valid
surface with boundaries or a PyMeshLabException with a message and no new layer; never a crash.

Hypothesis draws a small *recipe* (sizes, shapes, scale, seed, parameters) in this process; the
cloud is built from it deterministically, so a failing example prints as a few readable values
and replays exactly. The filter runs in a persistent child process: a segfault or abort there
is reported as a failure of that example instead of killing pytest.

The default run is bounded (CI); ``IB_FUZZ_PROFILE=fuzz`` (``make fuzz``) runs many more,
larger and randomised examples (``IB_FUZZ_EXAMPLES`` sets how many): up to 20,000 points,
resolutions up to 256, and, where the team's data folder is there (``IB_FUZZ_DATA``, default
``../shared/data`` beside the repository), its real meshes with random damage: holes punched,
noise, outliers, normals dropped, zeroed or duplicated. Some clouds come as 2 or 3 overlapping
range scans, each in its own frame with the matrix that places it, merged by the filter
("merge visible layers").
"""
import multiprocessing
import os
import re
import traceback
from pathlib import Path

import numpy as np
import pytest
from hypothesis import event, given

from implicit_boundaries.options import Extraction, Implicit, Normals, SodsOccupancy
from fuzz_checks import DOCUMENTED_REFUSALS, check_answer
from fuzz_inputs import SETTINGS, build_cloud, build_faces, clouds, flat_scan, parameters, split_into_scans, with_row

# A run that takes longer than this is a hang (the largest fuzz example takes a few seconds).
CHILD_TIMEOUT = 600


# ---------------------------------------------------------------------------------------------
# The child: loads the plugin once, then runs one filter call per message.

def _serve(conn):
    import pymeshlab
    import implicit_boundaries

    implicit_boundaries.load()
    while True:
        job = conn.recv()
        if job is None:
            return
        try:
            conn.send(_run(pymeshlab, implicit_boundaries, *job))
        except Exception:  # a bug in the harness or in pymeshlab's own checks: show it whole
            conn.send({"status": "harness error", "message": traceback.format_exc()})


def _run(pymeshlab, implicit_boundaries, points, normals, params, mesh_layer=None, scans=None, faces=None):
    """One filter call on a new MeshSet holding the points (layer 0; with `faces`, a mesh) and,
    when given, a mesh (vertices, faces) as layer 1 for the implicit_mesh parameter; or, with
    `scans`, one layer per scan (points, normals or None, 4×4 matrix), merged by the filter."""
    ms = pymeshlab.MeshSet()
    if scans:
        for i, (p, n, matrix) in enumerate(scans):
            ms.add_mesh(pymeshlab.Mesh(vertex_matrix=p) if n is None else
                        pymeshlab.Mesh(vertex_matrix=p, v_normals_matrix=n), f"scan {i}")
            ms.set_matrix(transformmatrix=matrix, freeze=False)
    elif len(points) == 0:  # pymeshlab makes no mesh from an empty matrix, but loads an empty file
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            empty = os.path.join(tmp, "empty.ply")
            with open(empty, "w") as f:
                f.write("ply\nformat ascii 1.0\nelement vertex 0\nproperty double x\nproperty double y\n"
                        "property double z\nend_header\n")
            ms.load_new_mesh(empty)
    else:
        arrays = {"vertex_matrix": points}
        if normals is not None:
            arrays["v_normals_matrix"] = normals
        if faces is not None and len(faces):
            arrays["face_matrix"] = faces
        ms.add_mesh(pymeshlab.Mesh(**arrays), "points")
    if mesh_layer is not None:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=mesh_layer[0], face_matrix=mesh_layer[1]), "mesh")
        ms.set_current_mesh(0)
    layers = ms.mesh_number()
    try:
        result = implicit_boundaries.apply(ms, **params)
    except pymeshlab.PyMeshLabException as e:
        return {"status": "refused", "message": str(e), "new_layers": ms.mesh_number() - layers}
    out = ms.current_mesh()
    holes = ms.mesh(layers + 1) if ms.mesh_number() > layers + 1 else None
    return {"status": "ok", "surface_layer": layers, "new_layers": ms.mesh_number() - layers, "current": ms.current_mesh_id(),
            "vertices": out.vertex_matrix().copy(), "faces": out.face_matrix().copy(),
            "holes": None if holes is None else (holes.vertex_matrix().copy(), holes.face_matrix().copy()),
            "selected": np.flatnonzero(out.vertex_selection_array()),
            "result": {k: (np.asarray(v) if isinstance(v, (list, np.ndarray)) else v) for k, v in result.items()}}


class Worker:
    """A persistent child process running the filter; restarted after it dies."""

    def __init__(self):
        self.context = multiprocessing.get_context("spawn")  # no fork of a Qt/pymeshlab process
        self.process = None

    def start(self):
        self.conn, child_end = self.context.Pipe()
        self.process = self.context.Process(target=_serve, args=(child_end,), daemon=True)
        self.process.start()
        child_end.close()

    def run(self, points, normals, params, mesh_layer=None, scans=None, faces=None):
        if self.process is None or not self.process.is_alive():
            self.start()
        self.conn.send((points, normals, params, mesh_layer, scans, faces))
        if not self.conn.poll(CHILD_TIMEOUT):
            self.stop()
            return {"status": "hang", "message": f"no answer within {CHILD_TIMEOUT} s"}
        try:
            return self.conn.recv()
        except EOFError:
            self.process.join(5)
            code = self.process.exitcode
            self.process = None
            return {"status": "crash", "message": f"the filter process died (exit code {code})"}

    def stop(self):
        if self.process is not None and self.process.is_alive():
            try:
                self.conn.send(None)
                self.process.join(10)
            finally:
                if self.process.is_alive():
                    self.process.kill()
                    self.process.join()
        self.process = None


@pytest.fixture(scope="module")
def worker():
    w = Worker()
    yield w
    w.stop()


def run_recipe(worker, recipe, params):
    points, normals = build_cloud(recipe)
    scans = split_into_scans(recipe, points, normals) if len(points) and recipe.get("scans", 1) > 1 else None
    if scans:
        params = {**params, "merge_visible_layers": True}
    faces = None if scans else build_faces(recipe, points)
    answer = worker.run(points, normals, params, scans=scans, faces=faces)
    check_answer(answer, params)
    return answer


# ---------------------------------------------------------------------------------------------

@SETTINGS
@given(recipe=clouds(), params=parameters())
def test_random_clouds_and_parameters(worker, recipe, params):
    answer = run_recipe(worker, recipe, params)
    # --hypothesis-show-statistics: how often each outcome came up
    message = answer.get("message", "").split("Details: ")[-1].replace("Implicit reconstruction with boundaries: ", "")
    outcome = answer["status"] + (": " + message[:40] if answer["status"] == "refused" else "")
    event(outcome)
    if os.environ.get("IB_FUZZ_LOG"):  # a line per example checked, for long runs
        with open(os.environ["IB_FUZZ_LOG"], "a") as log:
            log.write(f"{recipe.get('mesh') or '+'.join(recipe['shapes'])} n={recipe['n']} scans={recipe.get('scans', 1)} faces={recipe.get('faces', 'none')}: {outcome}\n")


# ---------------------------------------------------------------------------------------------
# Edge inputs named one by one (README's table of refused inputs points here), through the same
# crash-safe child.

REFUSED = {
    "infinite coordinate": (lambda: (with_row(flat_scan()[0], 5, [np.inf, 0, 0]), None), {},
                            "1 of 600 vertices have NaN or infinite"),
    "9 samples once 3 outliers are left out": (
        lambda: (np.vstack([flat_scan(9)[0] * 0.01, [[5.0, 0, 0], [0, 7.0, 0], [0, 0, 9.0]]]), None), {},
        "Only 9 samples are left once 3 outliers"),
    "resolution 7": (flat_scan, dict(resolution=7), "Resolution 7 is out of range"),
    "dilation 9": (flat_scan, dict(sods_dilation=9), "SODS dilation must be between 0 and 8"),
    "radius 8.5": (flat_scan, dict(sample_radius=8.5), "sample radius must be between 0.25 and 8"),
    "min_boundary_edges -1": (flat_scan, dict(min_boundary_edges=-1), "minimum number of boundary edges cannot be negative"),
    "smoothing 101": (flat_scan, dict(boundary_smoothing=101), "Boundary smoothing must be between 0 and 100"),
    "trim 9": (flat_scan, dict(boundary_trim=9.0), "boundary trim must be between 0"),
    "rbf_min_samples 3": (flat_scan, dict(rbf_min_samples=3), "minimum samples per cell must be between 4 and 2000"),
    "rbf_max_samples 7": (flat_scan, dict(rbf_max_samples=7), "maximum samples per cell must be between 8 and 5000"),
    "rbf_overlap 0.5": (flat_scan, dict(rbf_overlap=0.5), "overlap must be between 1"),
    "rbf_off_surface 0": (flat_scan, dict(rbf_off_surface=0.0), "off-surface distance must be above 0"),
    "mesh layer without faces": (flat_scan, dict(implicit=Implicit.MESH_LAYER, implicit_mesh=0),
                                 "has no faces"),
    "mesh layer of degenerate faces": (flat_scan, dict(implicit=Implicit.MESH_LAYER, implicit_mesh=1),
                                       "only degenerate (zero-area) faces"),
}
MESH_LAYERS = {"mesh layer of degenerate faces": (np.zeros((3, 3)), np.array([[0, 1, 2]], dtype=np.int32))}


@pytest.mark.parametrize("name", REFUSED)
def test_refused_inputs(worker, name):
    make, params, message = REFUSED[name]
    points, normals = make()
    answer = worker.run(points, normals, params, MESH_LAYERS.get(name))
    check_answer(answer, params)
    assert answer["status"] == "refused" and message in answer["message"], answer.get("message")


ACCEPTED = {  # the odd but valid inputs: a surface comes out
    "flat scan": (flat_scan, {}),
    "tiny coordinates (1e-6)": (lambda: flat_scan(scale=1e-6), {}),
    "huge coordinates (1e6)": (lambda: flat_scan(scale=1e6), {}),
    "unit scan far from the origin (1e6)": (lambda: flat_scan(offset=1e6), {}),
    "every sample three times": (lambda: tuple(np.tile(a, (3, 1)) for a in flat_scan()), {}),
    "all normals zero (estimated)": (lambda: (flat_scan()[0], np.zeros((600, 3))), {}),
    "flat scan, PU-RBF": (flat_scan, dict(implicit=Implicit.PU_RBF)),
}


@pytest.mark.parametrize("name", ACCEPTED)
def test_odd_but_valid_inputs_give_a_surface(worker, name):
    make, params = ACCEPTED[name]
    points, normals = make()
    answer = worker.run(points, normals, params)
    check_answer(answer, params)
    assert answer["status"] == "ok", answer.get("message")
    # the surface spans the scan, at its scale
    extent = np.ptp(answer["vertices"], axis=0)
    assert 0.8 * np.ptp(points, axis=0)[0] < extent[0] < 1.2 * np.ptp(points, axis=0)[0]


# ---------------------------------------------------------------------------------------------
# What the fuzzing found, kept as regressions: (recipe, parameters, what must come out).

# The parameters the fuzzer ran with when it found these (not the filter's defaults).
FOUND_WITH = {"resolution": 0, "implicit": Implicit.HOPPE, "sods_occupancy": SodsOccupancy.TANGENT_DISKS,
                  "sods_dilation": 0, "sample_radius": 1.0, "min_boundary_edges": 12, "boundary_smoothing": 0,
                  "boundary_trim": 0.5, "extraction": Extraction.SODS_DRIVEN, "normals": Normals.USE_LAYER,
                  "hole_layer": False}
SMALL_CLUSTER = {"n": 10, "shapes": ["cluster"], "scale": 1.0, "offset": 0.0, "duplicates": 0, "nans": 0,
                 "normals": "none", "seed": 0}
THREE_CLUSTERS = {**SMALL_CLUSTER, "n": 1455, "shapes": ["cluster"] * 3, "seed": 1116}
PLAIN_OVER_CLUSTERS = dict(sods_occupancy=SodsOccupancy.SAMPLE_CELLS, sods_dilation=1, min_boundary_edges=0,
                           boundary_trim=1.0, extraction=Extraction.PLAIN, normals=Normals.ESTIMATE)
FOUND = {
    # 10 scattered samples: every face was trimmed or filled away and an empty layer was added
    "empty surface": (SMALL_CLUSTER, dict(min_boundary_edges=28), "No surface was extracted"),
    # Plain marching cubes over three clusters: VCG's centre vertex of ambiguous cells was held
    # by pointer while edge vertices were added (use after free): a segfault, or faces on a
    # stray vertex (not a manifold)
    "centre vertex, segfault": (THREE_CLUSTERS, dict(PLAIN_OVER_CLUSTERS, sample_radius=4.0, boundary_trim=4.0), None),
    "centre vertex, not manifold": (THREE_CLUSTERS, PLAIN_OVER_CLUSTERS, None),
    # The holes layer had pinched vertices (hole-search cells touching at a corner): with the
    # surface, not a 2-manifold
    "holes layer pinch": ({**SMALL_CLUSTER, "n": 94, "shapes": ["cluster", "line"]},
                          dict(sample_radius=3.0, min_boundary_edges=0, boundary_trim=0.0, hole_layer=True), None),
    # A hole fan touching the surface only at a vertex, across an opening of the extraction: each
    # layer a 2-manifold, welded a bow-tie (found after 1,711 examples of `make fuzz`)
    "holes layer bow-tie with the surface": ({**SMALL_CLUSTER, "n": 2402},
                                             dict(sods_occupancy=SodsOccupancy.SAMPLE_CELLS, min_boundary_edges=0,
                                                  boundary_trim=0.0, hole_layer=True), None),
}


@pytest.mark.parametrize("name", FOUND)
def test_fuzzing_findings(worker, name):
    recipe, params, message = FOUND[name]
    answer = run_recipe(worker, recipe, {**FOUND_WITH, **params})
    if message is None:
        assert answer["status"] == "ok", answer.get("message")
    else:
        assert answer["status"] == "refused" and message in answer["message"], answer.get("message")


def test_documented_refusals_are_in_the_readme():
    """Every refusal the fuzz tests accept is shown in README's table of refused inputs."""
    readme = (Path(__file__).parent.parent / "README.md").read_text()
    table = readme[readme.index("| input or parameter value | message (excerpt) | test |"):]
    table = table[:table.index("\n\n")].replace("…", "X")
    missing = [pattern for pattern in DOCUMENTED_REFUSALS if not re.search(pattern, table)]
    assert not missing, f"README's refusal table lacks {missing}"
