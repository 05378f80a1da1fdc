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
noise, outliers, normals dropped, zeroed or duplicated.
"""
import multiprocessing
import os
import re
import traceback
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings, strategies as st

from implicit_boundaries.options import Extraction, Implicit, Normals, SodsOccupancy
from shapes import check_oriented_manifold

PROFILE = os.environ.get("IB_FUZZ_PROFILE", "default")
# The default profile is derandomised so that CI sees the same examples every run.
SETTINGS = {
    "default": settings(max_examples=40, derandomize=True, database=None, deadline=None,
                        suppress_health_check=[HealthCheck.too_slow]),
    "fuzz": settings(max_examples=int(os.environ.get("IB_FUZZ_EXAMPLES", "400")), deadline=None,
                     suppress_health_check=[HealthCheck.too_slow]),
}[PROFILE]
MAX_POINTS = 20000 if PROFILE == "fuzz" else 600
MAX_RESOLUTION = 256 if PROFILE == "fuzz" else 48
DATA = Path(os.environ.get("IB_FUZZ_DATA", Path(__file__).resolve().parent.parent.parent / "shared" / "data"))
# Real meshes (vertex positions and normals from their faces) for the fuzz profile only: the
# default run must not depend on files outside the repository.
MESHES = sorted(str(p.relative_to(DATA)) for p in DATA.glob("**/*") if p.suffix in (".ply", ".off", ".obj")
                and "bunny_scans" not in p.parts) if PROFILE == "fuzz" and DATA.is_dir() else []
# A run that takes longer than this is a hang (the largest fuzz example takes a few seconds).
CHILD_TIMEOUT = 600

SHAPES = ["cluster", "plane", "line", "sphere", "noise", "point"]
NORMALS = ["none", "true", "random", "zero", "some zero", "some nan"]


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


def _run(pymeshlab, implicit_boundaries, points, normals, params, mesh_layer=None):
    """One filter call on a new MeshSet holding the points (layer 0) and, when given, a mesh
    (vertices, faces) as layer 1 for the implicit_mesh parameter."""
    ms = pymeshlab.MeshSet()
    if len(points) == 0:  # pymeshlab makes no mesh from an empty matrix, but loads an empty file
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            empty = os.path.join(tmp, "empty.ply")
            with open(empty, "w") as f:
                f.write("ply\nformat ascii 1.0\nelement vertex 0\nproperty double x\nproperty double y\n"
                        "property double z\nend_header\n")
            ms.load_new_mesh(empty)
    elif normals is None:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points), "points")
    else:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
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

    def run(self, points, normals, params, mesh_layer=None):
        if self.process is None or not self.process.is_alive():
            self.start()
        self.conn.send((points, normals, params, mesh_layer))
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


# ---------------------------------------------------------------------------------------------
# Recipes: clouds and parameters.

def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def shape_points(kind, n, rng):
    """n points of one kind in about the unit cube, and their 'true' normals (random where the
    shape has none)."""
    centre = rng.random(3)
    normals = unit(rng.normal(size=(n, 3)) + 1e-12)
    if kind == "cluster":
        points = centre + 0.05 * rng.normal(size=(n, 3))
    elif kind == "plane":
        basis = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        uv = rng.random((n, 2)) - 0.5
        points = centre + uv @ basis[:, :2].T
        normals = np.tile(basis[:, 2], (n, 1))
    elif kind == "line":
        points = centre + np.outer(rng.random(n) - 0.5, unit(rng.normal(size=3)))
    elif kind == "sphere":
        normals = unit(rng.normal(size=(n, 3)))
        points = centre + 0.4 * normals
    elif kind == "noise":
        points = rng.random((n, 3))
    else:  # "point": every sample at one position
        points = np.tile(centre, (n, 1))
    return points, normals


_MESH_CACHE = {}


def mesh_samples(name):
    """A real mesh's vertices and unit normals from its faces (zero where a vertex has none)."""
    if name not in _MESH_CACHE:
        import pymeshlab
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(DATA / name))
        if ms.current_mesh().face_number() > 0:
            ms.compute_normal_per_vertex()
        m = ms.current_mesh()
        _MESH_CACHE[name] = (m.vertex_matrix().copy(), m.vertex_normal_matrix().copy())
    return _MESH_CACHE[name]


def damaged_mesh(recipe, rng):
    """Up to n samples of a real mesh, with holes punched (balls of 2-10% of the diagonal
    removed), Gaussian noise and uniform outliers in its box, as the recipe says."""
    points, normals = mesh_samples(recipe["mesh"])
    if len(points) > recipe["n"]:
        keep = rng.choice(len(points), recipe["n"], replace=False)
        points, normals = points[keep], normals[keep]
    if len(points) == 0:
        return points, normals
    diagonal = np.linalg.norm(np.ptp(points, axis=0))
    keep = np.ones(len(points), bool)
    for _ in range(recipe["holes"]):
        centre, radius = points[rng.integers(len(points))], diagonal * rng.uniform(0.02, 0.1)
        keep &= np.linalg.norm(points - centre, axis=1) > radius
    points, normals = points[keep], normals[keep]
    if len(points) == 0:
        return points, normals
    points = points + rng.normal(scale=recipe["noise"] * diagonal, size=points.shape)
    strays = int(recipe["outliers"] * len(points))
    lo, hi = points.min(axis=0), points.max(axis=0)
    points = np.vstack([points, lo + (hi - lo) * rng.random((strays, 3))])
    normals = np.vstack([normals, unit(rng.normal(size=(strays, 3)) + 1e-12)])
    return points, normals


def build_cloud(recipe):
    """Points (n×3) and normals (n×3 or None) from a recipe drawn by `clouds`."""
    rng = np.random.default_rng(recipe["seed"])
    n = recipe["n"]
    if recipe.get("mesh"):
        points, normals = damaged_mesh(recipe, rng)
        n = len(points)
    else:
        counts = np.bincount(rng.integers(0, len(recipe["shapes"]), n), minlength=len(recipe["shapes"]))
        parts = [shape_points(kind, int(c), rng) for kind, c in zip(recipe["shapes"], counts)]
        points = np.concatenate([p for p, _ in parts] + [np.zeros((0, 3))])
        normals = np.concatenate([q for _, q in parts] + [np.zeros((0, 3))])
    if recipe["duplicates"] and n:
        picked = rng.integers(0, n, int(recipe["duplicates"] * n))
        points, normals = np.concatenate([points, points[picked]]), np.concatenate([normals, normals[picked]])
    points = points * recipe["scale"] + recipe["offset"]
    if recipe["nans"] and len(points):
        points[rng.integers(0, len(points), recipe["nans"]), rng.integers(0, 3, recipe["nans"])] = np.nan
    mode = recipe["normals"]
    if mode == "none":
        return points, None
    if mode == "random":
        normals = unit(rng.normal(size=normals.shape) + 1e-12)
    elif mode == "zero":
        normals = np.zeros_like(normals)
    elif mode in ("some zero", "some nan") and len(normals):
        normals[rng.integers(0, len(normals), max(1, len(normals) // 20))] = 0 if mode == "some zero" else np.nan
    return points, normals


@st.composite
def clouds(draw, max_points=MAX_POINTS):
    mesh = draw(st.sampled_from([None] + MESHES)) if MESHES else None
    damage = {}
    if mesh:
        damage = {"mesh": mesh, "holes": draw(st.integers(0, 4)), "noise": draw(st.sampled_from([0, 0.001, 0.005])),
                  "outliers": draw(st.sampled_from([0, 0.001, 0.01]))}
    return {
        **damage,
        "n": draw(st.one_of(st.integers(0, 30), st.integers(0, max_points))),
        "shapes": draw(st.lists(st.sampled_from(SHAPES), min_size=1, max_size=3)),
        "scale": draw(st.sampled_from([1.0, 1e-6, 1e6])),
        "offset": draw(st.sampled_from([0.0, 1.0, -1e3])) * draw(st.sampled_from([1.0, 1e-6, 1e6])),
        "duplicates": draw(st.sampled_from([0, 0, 0.1, 1.0])),  # fraction of samples repeated
        "nans": draw(st.sampled_from([0] * 8 + [1, 5])),  # mostly clean: NaNs are refused up front
        "normals": draw(st.sampled_from(NORMALS)),
        "seed": draw(st.integers(0, 2**32 - 1)),
    }


@st.composite
def parameters(draw, max_resolution=MAX_RESOLUTION):
    return {
        "resolution": draw(st.one_of(st.just(0), st.integers(8, max_resolution))),
        "implicit": draw(st.sampled_from([Implicit.HOPPE, Implicit.PU_RBF])),
        "sods_occupancy": draw(st.sampled_from(SodsOccupancy.LABELS)),
        "sods_dilation": draw(st.integers(0, 2)),
        "sample_radius": draw(st.floats(0.25, 8.0)),
        "min_boundary_edges": draw(st.integers(0, 40)),
        "boundary_smoothing": draw(st.integers(0, 8)),
        "boundary_trim": draw(st.floats(0.0, 8.0)),
        "extraction": draw(st.sampled_from(Extraction.LABELS)),
        "normals": draw(st.sampled_from([Normals.USE_LAYER, Normals.ESTIMATE])),
        "hole_layer": draw(st.booleans()),
        # Bounded so that outputs stay small enough to check here: under the default (half the
        # RAM) a plain marching cubes run over noise returns tens of millions of faces, and
        # checking them exhausted the machine. Larger runs are benchmarked, not fuzzed.
        "memory_limit": draw(st.sampled_from([0.25, 1.0, 2.0])),
    }


# ---------------------------------------------------------------------------------------------
# What a valid answer is.

def check_loops(vertices, faces, result, selected):
    """The boundary loops in the result are closed, cover every boundary edge of the surface
    once, and match `boundary_loop_edges` and the vertex selection."""
    edges = np.asarray(result["boundary_loop_edges"], dtype=np.int64).reshape(-1)
    flat = np.asarray(result["boundary_loop_vertices"], dtype=np.int64).reshape(-1)
    assert result["boundary_loops"] == len(edges)
    assert edges.sum() == len(flat)
    assert np.all(edges >= 3), f"a loop of fewer than 3 edges: {edges}"
    assert np.all((flat >= 0) & (flat < len(vertices)))
    # As integer keys with numpy: a plain marching cubes run over noise can return millions of
    # faces, and sets of Python tuples of them took the whole machine's memory.
    n = np.int64(len(vertices))
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    boundary = directed[~np.isin(directed[:, 0] * n + directed[:, 1], directed[:, 1] * n + directed[:, 0])]
    starts = np.repeat(np.cumsum(edges) - edges, edges)  # where each vertex's loop starts in flat
    following = flat[starts + (np.arange(len(flat)) - starts + 1) % np.repeat(edges, edges)]
    loop_keys = np.minimum(flat, following) * n + np.maximum(flat, following)
    assert len(np.unique(loop_keys)) == len(loop_keys), "an edge in two loops (or twice in one)"
    boundary_keys = np.sort(boundary.min(axis=1) * n + boundary.max(axis=1))
    assert np.array_equal(np.sort(loop_keys), boundary_keys), "loops do not trace the boundary"
    assert np.array_equal(np.unique(selected), np.unique(flat)), "selected vertices are not the loop vertices"


# The refusals README's table documents, one pattern each (test_documented_refusals_are_in_the_readme checks
# that the table shows each). Anything else is an internal failure, among them "... failed (...).
# Please report it" and "ran out of memory" (the memory guard should have refused first).
DOCUMENTED_REFUSALS = [
    r"The layer has no vertices", r"The layer has only \d+ vertices", r"Only \d+ distinct vertex positions",
    r"Only \d+ samples are left once \d+ outliers", r"\d+ of \d+ vertices have NaN or infinite coordinates",
    r"All vertices are at the same position", r"All vertices lie on one line", r"Resolution \d+ is out of range",
    r"SODS dilation must be between 0 and 8", r"The sample radius must be between 0.25 and 8",
    r"Normal neighbours must be between 3 and 256", r"The minimum number of boundary edges cannot be negative",
    r"Boundary smoothing must be between 0 and 100", r"The boundary trim must be between 0 \(off\) and 8",
    r"The PU-RBF's minimum samples per cell must be between", r"The PU-RBF's maximum samples per cell must be between",
    r"The PU-RBF's overlap must be between", r"The PU-RBF's off-surface distance must be above 0",
    r"The memory limit cannot be negative", r"Resolution \d+ would need about \S+ GB of memory",
    r"No surface was extracted at resolution \d+", r"The implicit mesh layer '[^']*' (has no faces|cannot be used)",
]


def check_answer(answer, params):
    status = answer["status"]
    assert status in ("ok", "refused"), f"{status}: {answer['message']}"
    expected = 0 if status == "refused" else 1 + (bool(params.get("hole_layer")) and answer["result"]["hole_faces"] > 0)
    assert answer["new_layers"] == expected, f"{answer['new_layers']} new layers after a {status} run"
    if status == "refused":
        message = answer["message"]
        assert "failed (" not in message, f"internal failure: {message}"
        assert any(re.search(pattern, message) for pattern in DOCUMENTED_REFUSALS), f"undocumented refusal: {message}"
        return
    vertices, faces, result = answer["vertices"], answer["faces"], answer["result"]
    assert answer["current"] == answer["surface_layer"], "the new surface is not the current layer"
    assert len(faces) > 0, "an empty surface returned as a result"
    assert np.all((faces >= 0) & (faces < len(vertices)))
    assert result["surface_faces"] == len(faces) and result["surface_vertices"] == len(vertices)
    check_oriented_manifold(vertices, faces)
    check_loops(vertices, faces, result, answer["selected"])
    if answer["holes"] is None:
        return
    # The holes layer closes kept holes along their loops: with the surface, welded where their
    # vertices coincide, a 2-manifold too. (Unless distinct vertices of one layer coincide: at
    # 1e-6 scales 1e6 from the origin, doubles cannot tell them apart, nor the weld.)
    hole_vertices, hole_faces = answer["holes"]
    assert len(hole_faces) == result["hole_faces"]
    if len(np.unique(vertices, axis=0)) == len(vertices) and len(np.unique(hole_vertices, axis=0)) == len(hole_vertices):
        both, index = np.unique(np.vstack([vertices, hole_vertices]), axis=0, return_inverse=True)
        index = index.reshape(-1)
        check_oriented_manifold(both, np.vstack([index[faces], index[len(vertices) + hole_faces]]))


def run_recipe(worker, recipe, params):
    points, normals = build_cloud(recipe)
    answer = worker.run(points, normals, params)
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
            log.write(f"{recipe.get('mesh') or '+'.join(recipe['shapes'])} n={recipe['n']}: {outcome}\n")


# ---------------------------------------------------------------------------------------------
# Edge inputs named one by one (README's table of refused inputs points here), through the same
# crash-safe child.

def flat_scan(n=600, scale=1.0, offset=0.0, seed=1):
    """A square of n samples in the plane z = 0 with their normals: points, normals."""
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.random((n, 2)), np.zeros(n)]) * scale + offset, np.tile([0, 0, 1.0], (n, 1))


def with_row(array, row, value):
    out = array.copy()
    out[row] = value
    return out


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
