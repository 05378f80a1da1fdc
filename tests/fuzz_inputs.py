"""Example generators for tests/test_fuzz.py: the profile's settings and bounds, hypothesis
strategies for cloud recipes and parameters, clouds built from a recipe (random shapes, or real
meshes from the team's data folder with random damage), and the named flat scan of the edge cases.

``IB_FUZZ_PROFILE=fuzz`` (``make fuzz``) selects the long profile, ``IB_FUZZ_EXAMPLES`` its number
of examples and ``IB_FUZZ_DATA`` the folder of real meshes (default ``../shared/data`` beside the
repository).
"""
import os
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, settings, strategies as st

from implicit_boundaries.options import Extraction, Implicit, Normals, SodsOccupancy

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

SHAPES = ["cluster", "plane", "line", "sphere", "noise", "point"]
NORMALS = ["none", "true", "random", "zero", "some zero", "some nan"]
# Faces of the points' layer (keep_mesh_holes): none (a point cloud), triangles of nearby
# samples (a mesh, with whatever holes and folds that makes), random index triples (slivers
# across everything), or faces of one vertex three times (zero area: refused).
FACES = ["none", "none", "none", "nearby", "random", "degenerate"]


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


def build_faces(recipe, points):
    """The (f, 3) faces recipe["faces"] asks for over `points` (rows as build_cloud's), or None."""
    mode = recipe.get("faces", "none")
    n = len(points)
    if mode == "none" or n < 3:
        return None
    rng = np.random.default_rng(recipe["seed"] + 2)
    if mode == "random":
        return rng.integers(0, n, (max(1, n // 2), 3)).astype(np.int32)
    if mode == "degenerate":
        return np.repeat(rng.integers(0, n, (max(1, n // 10), 1)), 3, axis=1).astype(np.int32)
    from scipy.spatial import cKDTree
    finite = np.where(np.isfinite(points).all(axis=1), 0, 1)[:, None] * 1e300  # NaN rows far away
    _, near = cKDTree(np.nan_to_num(points) + finite).query(np.nan_to_num(points), k=min(3, n))
    faces = near[:, :3] if near.shape[1] == 3 else np.zeros((0, 3), int)
    return faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])].astype(np.int32)


def split_into_scans(recipe, points, normals):
    """The cloud as recipe["scans"] overlapping range scans: bands along a random axis that
    overlap by a tenth of the extent, each shifted by a registration error of 0.1% of the
    diagonal and stored in its own frame, with the rigid matrix that places it (as the Align
    tool leaves them). A list of (points, normals or None, 4×4 matrix); empty bands left out."""
    rng = np.random.default_rng(recipe["seed"] + 1)
    count = recipe.get("scans", 1)
    finite = np.isfinite(points).all(axis=1)
    if count <= 1 or not finite.any():
        return [(points, normals, np.eye(4))]
    axis = unit(rng.normal(size=3))
    t = points @ axis
    lo, hi = t[finite].min(), t[finite].max()
    width = (hi - lo) / count
    diagonal = np.linalg.norm(np.ptp(points[finite], axis=0))
    scans = []
    for k in range(count):
        rows = np.flatnonzero(~finite | ((t >= lo + (k - 0.1) * width) & (t <= lo + (k + 1.1) * width)))
        if len(rows) == 0:
            continue
        rotation = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        rotation *= np.sign(np.linalg.det(rotation))
        shift = points[finite].mean(axis=0) + 0.001 * diagonal * unit(rng.normal(size=3))
        matrix = np.eye(4)
        matrix[:3, :3], matrix[:3, 3] = rotation, shift
        local = (points[rows] - shift) @ rotation  # inverse(matrix) applied to each row
        scans.append((local, None if normals is None else normals[rows] @ rotation, matrix))
    return scans or [(points, normals, np.eye(4))]


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
        "scans": draw(st.sampled_from([1, 1, 1, 2, 3])),  # merged as visible layers when more than 1
        "faces": draw(st.sampled_from(FACES)),
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
# Named edge inputs (test_refused_inputs, test_odd_but_valid_inputs_give_a_surface).

def flat_scan(n=600, scale=1.0, offset=0.0, seed=1):
    """A square of n samples in the plane z = 0 with their normals: points, normals."""
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.random((n, 2)), np.zeros(n)]) * scale + offset, np.tile([0, 0, 1.0], (n, 1))


def with_row(array, row, value):
    out = array.copy()
    out[row] = value
    return out
