"""Output checks for tests/test_fuzz.py: an answer of the filter's child process is either a
surface (an oriented 2-manifold whose boundary loops are closed and match the result and the
selection, plus a holes layer that welds to it as a 2-manifold) or a refusal with one of the
messages README's table documents (DOCUMENTED_REFUSALS) and no new layer.
"""
import re

import numpy as np

from shapes import check_oriented_manifold


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
    r"Every face of the layer has zero area",
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
