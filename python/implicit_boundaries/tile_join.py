"""The pieces of a tiled run joined into one mesh, one piece in memory at a time.

Each piece (a tile's faces) is kept on disk as it arrives. Only its border vertices can be
shared with another piece (a face of the neighbouring block meets them there), so only those
are welded: two border vertices of different pieces within the tolerance, each the other's
nearest in its piece, are one vertex (see _weld_pairs for the copies a piece makes itself). The tiles
compute them from the same lattice corners and samples, but sums over the samples in another
order (the boundary fit's) can leave them a few millionths of a cell apart near a scan's
boundary; a hundredth of a cell is far below any edge. The boundary loops of the whole are the
pieces' border edges that no other piece has, traced into cycles. The joined mesh is then read back into arrays or
streamed to a binary PLY file piece by piece.
"""
import tempfile
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


def border_half_edges(faces: np.ndarray) -> np.ndarray:
    """(b, 2) directed edges (a, b) of the (f, 3) oriented faces whose reverse no face has."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    half = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    base = int(faces.max()) + 1
    return half[~np.isin(half[:, 0] * base + half[:, 1], half[:, 1] * base + half[:, 0])]


def trace_loops(edges: np.ndarray) -> List[np.ndarray]:
    """The cycles of (b, 2) directed border edges, largest first (a vertex where two loops
    touch is left along the edge found first and visited again by the other loop)."""
    successors: Dict[int, List[int]] = {}
    for a, b in np.asarray(edges, dtype=np.int64).tolist():
        successors.setdefault(a, []).append(b)
    loops = []
    while successors:
        start = next(iter(successors))
        loop, v = [start], successors[start].pop()
        if not successors[start]:
            del successors[start]
        while v != start and v in successors:
            loop.append(v)
            following = successors[v].pop()
            if not successors[v]:
                del successors[v]
            v = following
        loops.append(np.array(loop, dtype=np.int64))
    return sorted(loops, key=len, reverse=True)


def _weld_pairs(at: np.ndarray, piece: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Of the (p, 2) pairs of rows of `at` within the tolerance, those to weld: a vertex and its
    nearest in another piece when it is that one's nearest in its own (two vertices of one piece
    can lie closer than the tolerance, at a zero crossing near a lattice corner, and must not
    become one through a third), and the copies a piece made of one vertex at one position
    (the filter splits a vertex where the block's edge leaves two fans touching; the
    neighbouring piece joins them again)."""
    if len(pairs) == 0:
        return pairs
    distance = np.linalg.norm(at[pairs[:, 0]] - at[pairs[:, 1]], axis=1)
    across = piece[pairs[:, 0]] != piece[pairs[:, 1]]
    both = np.concatenate([pairs[across], pairs[across][:, ::-1]])
    d = np.concatenate([distance[across], distance[across]])
    order = np.lexsort((d, piece[both[:, 1]], both[:, 0]))  # per (row, other piece), nearest first
    both = both[order]
    key = both[:, 0] * (int(piece.max()) + 1) + piece[both[:, 1]]
    first = np.ones(len(both), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    nearest = {(int(a), int(b)) for a, b in both[first]}
    mutual = [(a, b) for a, b in nearest if a < b and (b, a) in nearest]
    copies = pairs[~across & (distance == 0) & np.isin(pairs[:, 0], both[:, 0])]
    return np.concatenate([np.array(mutual, dtype=np.int64).reshape(-1, 2), copies])


class Join:
    """Pieces added one by one (add), then numbered and welded (finish), then read back
    (arrays) or written (write_ply). tolerance: how close two pieces' border vertices must be
    to be one vertex."""

    def __init__(self, tolerance: float):
        self.tolerance = tolerance
        self._folder = tempfile.TemporaryDirectory(prefix="implicit-boundaries-tiles-")
        self._sizes: List[Tuple[int, int]] = []            # (vertices, faces) per piece
        self._border: List[np.ndarray] = []                # per piece: its border vertices (local ids)
        self._border_at: List[np.ndarray] = []             # their positions
        self._edges: List[np.ndarray] = []                 # per piece: its border half-edges (local ids)

    def add(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        t = len(self._sizes)
        np.save(self._path(t, "v"), np.asarray(vertices, dtype=np.float64))
        np.save(self._path(t, "f"), np.asarray(faces, dtype=np.int32))
        edges = border_half_edges(faces)
        border = np.unique(edges)
        self._sizes.append((len(vertices), len(faces)))
        self._border.append(border)
        self._border_at.append(np.asarray(vertices, dtype=np.float64)[border])
        self._edges.append(edges)

    def finish(self) -> List[np.ndarray]:
        """Welds the pieces' border vertices and numbers every vertex; returns the loops."""
        tile = np.concatenate([np.full(len(b), t) for t, b in enumerate(self._border)] or [np.zeros(0, int)])
        local = np.concatenate(self._border or [np.zeros(0, int)])
        at = np.concatenate(self._border_at or [np.zeros((0, 3))])
        n = len(local)
        canonical = np.arange(n)
        if n > 1:
            pairs = _weld_pairs(at, tile, cKDTree(at).query_pairs(self.tolerance, output_type="ndarray"))
            if len(pairs):
                graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
                _, label = connected_components(graph, directed=False)
                _, first = np.unique(label, return_index=True)  # rows are in (piece, vertex) order
                canonical = first[label]
        # Per piece: the vertices it writes (all but the border ones welded to another's), from
        # its offset on; the welded ones take their canonical vertex's number.
        self._offsets, self._duplicates, self._targets = [], [], []
        global_of = np.full(n, -1, dtype=np.int64)
        offset, start = 0, 0
        for t, (nv, _) in enumerate(self._sizes):
            rows = np.arange(start, start + len(self._border[t]))
            start += len(rows)
            welded = rows[canonical[rows] != rows]
            self._offsets.append(offset)
            self._duplicates.append(local[welded])
            ids = self._ids(t)  # owned ones numbered; welded ones filled below
            owned_rows = rows[canonical[rows] == rows]
            global_of[owned_rows] = ids[local[owned_rows]]
            global_of[welded] = global_of[canonical[welded]]
            self._targets.append(global_of[welded])
            offset += nv - len(welded)
        self.vertex_count = offset
        self.face_count = sum(nf for _, nf in self._sizes)
        edges = np.concatenate([self._ids(t)[e] for t, e in enumerate(self._edges)] or [np.zeros((0, 2), int)])
        if len(edges):
            base = self.vertex_count
            edges = edges[~np.isin(edges[:, 0] * base + edges[:, 1], edges[:, 1] * base + edges[:, 0])]
        return trace_loops(edges)

    def _ids(self, t: int) -> np.ndarray:
        """Vertex numbers of piece t's vertices in the joined mesh."""
        nv = self._sizes[t][0]
        duplicates = self._duplicates[t]
        owned = np.ones(nv, dtype=bool)
        owned[duplicates] = False
        ids = np.full(nv, -1, dtype=np.int64)
        ids[owned] = self._offsets[t] + np.arange(int(owned.sum()))
        if len(self._targets) > t:
            ids[duplicates] = self._targets[t]
        return ids

    def _piece(self, t: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Piece t's own vertices (those it writes) and its faces in the joined numbering."""
        vertices, faces = np.load(self._path(t, "v")), np.load(self._path(t, "f"))
        owned = np.ones(len(vertices), dtype=bool)
        owned[self._duplicates[t]] = False
        return vertices[owned], self._ids(t)[faces]

    def arrays(self) -> Tuple[np.ndarray, np.ndarray]:
        """(vertices (m, 3), faces (f, 3) int32) of the joined mesh."""
        pieces = [self._piece(t) for t in range(len(self._sizes))]
        if not pieces:
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32)
        return np.concatenate([v for v, _ in pieces]), np.concatenate([f for _, f in pieces]).astype(np.int32)

    def write_ply(self, path) -> None:
        """The joined mesh as a binary little-endian PLY (double positions), piece by piece."""
        face = np.dtype([("n", "u1"), ("v", "<i4", (3,))])
        with open(path, "wb") as out:
            out.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {self.vertex_count}\n"
                       "property double x\nproperty double y\nproperty double z\n"
                       f"element face {self.face_count}\nproperty list uchar int vertex_indices\n"
                       "end_header\n").encode("ascii"))
            for t in range(len(self._sizes)):
                out.write(self._piece(t)[0].astype("<f8").tobytes())
            for t in range(len(self._sizes)):
                faces = self._piece(t)[1]
                rows = np.empty(len(faces), dtype=face)
                rows["n"] = 3
                rows["v"] = faces
                out.write(rows.tobytes())

    def close(self) -> None:
        self._folder.cleanup()

    def _path(self, t: int, what: str) -> Path:
        return Path(self._folder.name) / f"{t}{what}.npy"
