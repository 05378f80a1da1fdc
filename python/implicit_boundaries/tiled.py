"""A scan reconstructed tile by tile on Dask, joined into one surface with boundaries.

The scan gets one lattice (cell and origin fixed from a robust estimate of its sample spacing)
cut into blocks of whole cells. Each block is one Dask task: the filter runs through pymeshlab
in the worker's process on the block's samples plus a halo, on the whole scan's lattice, with
the PU-RBF's octree rooted at the whole scan's cube, and keeps the faces whose centre lies in
the block. Values at the lattice corners a block shares with its neighbour are then computed
from the same samples and the same numbers, so the faces of neighbouring blocks meet at the
same vertices; the join welds them.
"""
import os
from dataclasses import dataclass
from typing import Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .reconstruct import Reconstruction

#: The filter's automatic cell in sample spacings (Reconstruction::kCellPerSpacing).
CELL_PER_SPACING = 0.6
#: The halo, in sample spacings. At a tile's outer edge an octree node lacks the samples beyond
#: it, so it may stay one large cell where one run splits it; its support box then reaches in
#: as far as the split rule allows (at most 1200 samples in the box: about 24 spacings for a
#: box half inside the samples' surface). Measured on 200,000 samples of a wavy cap in 8
#: tiles: 20 spacings opened 4 slits along the seams, 40 gave one run's faces and loops exactly.
HALO_SPACINGS = 40
#: Samples whose neighbourhood sets the scan's spacing (the median of these is robust).
SPACING_SEEDS = 20000
#: Lattice cells between the samples' box and the lattice's border.
MARGIN_CELLS = 4


def median_spacing(points: np.ndarray, seeds: int = SPACING_SEEDS, seed: int = 0) -> float:
    """The filter's sample spacing (spacing.h: sqrt(pi r8^2 / 8), r8 the distance to the 8th
    nearest neighbour), as the median over up to `seeds` samples drawn from the (n, 3) points."""
    points = np.asarray(points, dtype=np.float64)
    rng = np.random.default_rng(seed)
    at = points if len(points) <= seeds else points[rng.choice(len(points), seeds, replace=False)]
    distance, _ = cKDTree(points).query(at, k=9)
    return float(np.median(np.sqrt(np.pi * distance[:, 8] ** 2 / 8)))


@dataclass
class Plan:
    """The whole scan's lattice and its blocks.

    cell: lattice cell; origin, end: (3,) the lattice's corners (every sample between them);
    spacing: the scan's median spacing; planes: per axis, the block borders as grid-plane
    coordinates origin + cell * k (first and last at the lattice's ends); halo: how far
    around its block a tile reads samples.
    """
    cell: float
    origin: np.ndarray
    end: np.ndarray
    spacing: float
    planes: Tuple[np.ndarray, np.ndarray, np.ndarray]
    halo: float

    def blocks(self) -> Iterator[Tuple[Tuple[int, int, int], np.ndarray, np.ndarray]]:
        """(index, low corner, high corner) of every block."""
        px, py, pz = self.planes
        for i in range(len(px) - 1):
            for j in range(len(py) - 1):
                for k in range(len(pz) - 1):
                    yield ((i, j, k), np.array([px[i], py[j], pz[k]]), np.array([px[i + 1], py[j + 1], pz[k + 1]]))

    def count(self) -> int:
        return int(np.prod([len(p) - 1 for p in self.planes]))

    def filter_params(self, lo: np.ndarray, hi: np.ndarray) -> Dict[str, object]:
        """The filter's tile parameters for the block [lo, hi)."""
        return dict(lattice_cell=self.cell, lattice_origin=self.origin, lattice_end=self.end,
                    lattice_spacing=self.spacing, block_min=lo, block_max=hi)


def plan(points: np.ndarray, resolution: int = 0, tiles: Optional[int] = None, tile_cells: int = 256,
         spacing: Optional[float] = None) -> Plan:
    """The lattice and blocks for the (n, 3) points: cells of 0.6 spacings (the filter's
    automatic resolution, uncapped) or of longest side / `resolution`; blocks of about
    `tile_cells` cells a side, or at least `tiles` blocks, the longest blocks split first."""
    points = np.asarray(points, dtype=np.float64)
    lo, hi = points.min(axis=0), points.max(axis=0)
    spacing = median_spacing(points) if spacing is None else float(spacing)
    if not spacing > 0:
        raise ValueError("the samples have no spacing (all at one position?)")
    cell = (hi - lo).max() / resolution if resolution else CELL_PER_SPACING * spacing
    origin = lo - MARGIN_CELLS * cell
    cells = np.ceil((hi - lo) / cell).astype(np.int64) + 2 * MARGIN_CELLS
    end = origin + cell * cells.astype(np.float64)
    if tiles:
        counts = np.ones(3, dtype=np.int64)
        while counts.prod() < tiles:
            a = int(np.argmax(cells / counts))
            counts[a] += 1
    else:
        counts = np.maximum(1, np.ceil(cells / max(1, int(tile_cells))).astype(np.int64))
    counts = np.minimum(counts, cells)
    planes = tuple(origin[a] + cell * np.round(np.linspace(0, cells[a], counts[a] + 1)).astype(np.float64)
                   for a in range(3))
    return Plan(float(cell), origin, end, spacing, planes, max(HALO_SPACINGS * spacing, 3 * cell))


def _reconstruct_tile(points: np.ndarray, normals: np.ndarray, params: Dict[str, object]):
    """One task: the tile's faces (vertices, faces, the filter's result dictionary)."""
    from .reconstruct import reconstruct as run
    r = run(points, normals, **params)
    return r.vertices, r.faces, r.info


def _tile_rows(points: np.ndarray, lo: np.ndarray, hi: np.ndarray, halo: float) -> np.ndarray:
    """Rows (ascending, as one run sees them) of the samples in [lo - halo, hi + halo]."""
    inside = np.all((points >= lo - halo) & (points <= hi + halo), axis=1)
    return np.flatnonzero(inside)


def weld(vertices: np.ndarray, faces: np.ndarray, tolerance: float) -> Tuple[np.ndarray, np.ndarray]:
    """Merges vertices at the same position (and border vertices within `tolerance` of each
    other: two tiles' seam vertices that differ in their last bits), drops faces left with a
    repeated vertex. Returns the compacted (vertices, faces)."""
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[faces]
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    e, counts = np.unique(edges, axis=0, return_counts=True)
    border = np.unique(e[counts == 1])
    if len(border) > 1 and tolerance > 0:
        pairs = cKDTree(unique[border]).query_pairs(tolerance, output_type="ndarray")
        if len(pairs):
            graph = coo_matrix((np.ones(len(pairs)), (border[pairs[:, 0]], border[pairs[:, 1]])),
                               shape=(len(unique), len(unique)))
            _, label = connected_components(graph, directed=False)
            _, first = np.unique(label, return_index=True)
            faces = first[label][faces]
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])]
    used, compact = np.unique(faces, return_inverse=True)
    return unique[used], compact.reshape(-1, 3).astype(np.int32)


def boundary_loops(faces: np.ndarray) -> List[np.ndarray]:
    """The boundary loops of an oriented triangle mesh, largest first: each the cycle of vertex
    indices along its border half-edges (a pinch vertex, where two loops touch, starts a new
    cycle at its second visit)."""
    faces = np.asarray(faces, dtype=np.int64)
    half = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    key = half[:, 0] * (faces.max() + 1) + half[:, 1]
    twin = half[:, 1] * (faces.max() + 1) + half[:, 0]
    border = half[~np.isin(key, twin)]
    successors: Dict[int, List[int]] = {}
    for a, b in border.tolist():
        successors.setdefault(a, []).append(b)
    loops = []
    while successors:
        start = next(iter(successors))
        loop, v = [start], successors[start].pop()
        if not successors[start]:
            del successors[start]
        while v != start:
            loop.append(v)
            nxt = successors[v].pop()
            if not successors[v]:
                del successors[v]
            v = nxt
        loops.append(np.array(loop, dtype=np.int64))
    return sorted(loops, key=len, reverse=True)


def _client(workers: Optional[int], scheduler: Optional[str]):
    """A Dask client: on the scheduler at `scheduler`, else on a local cluster of `workers`
    single-threaded worker processes (default: this machine's cores)."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as e:
        raise ImportError("tiled reconstruction runs on Dask: pip install distributed "
                          "(python/requirements.txt pins the tested version)") from e
    if scheduler:
        return Client(scheduler), None
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster), cluster


def reconstruct(points_or_files: Union[np.ndarray, str, Sequence[str]], normals: Optional[np.ndarray] = None, *,
                resolution: int = 0, tiles: Optional[int] = None, tile_cells: int = 256,
                workers: Optional[int] = None, scheduler: Optional[str] = None, progress: bool = False,
                **filter_params) -> Reconstruction:
    """The surface with boundaries of a scan, reconstructed in tiles on Dask.

    points_or_files: (n, 3) samples, or one or more point files (read with their normals);
    normals: (n, 3) outward normals of the samples (required: orientations estimated tile by
    tile would not agree across tiles). resolution: cells along the longest side (0: cells of
    0.6 spacings, as the filter chooses, but without its cap of 1024); tiles: at least this
    many blocks, else blocks of about `tile_cells` cells a side; workers: local worker
    processes (default: the cores); scheduler: the address of an existing Dask scheduler
    instead (every worker needs this package and pymeshlab); progress: Dask's progress bar;
    filter_params: the filter's other parameters by their pymeshlab names.
    Returns a Reconstruction whose info holds the plan and per-tile figures.
    """
    points, normals = _samples(points_or_files, normals)
    p = plan(points, resolution=resolution, tiles=tiles, tile_cells=tile_cells)
    client, cluster = _client(workers, scheduler)
    try:
        futures, blocks = [], []
        for index, lo, hi in p.blocks():
            rows = _tile_rows(points, lo, hi, p.halo)
            if len(rows) < 20:  # the filter needs samples to fit planes; such a block holds no surface
                continue
            params = dict(filter_params, **p.filter_params(lo, hi))
            futures.append(client.submit(_reconstruct_tile, points[rows], normals[rows], params, pure=False))
            blocks.append((index, len(rows)))
        if progress:
            from distributed import progress as show
            show(futures)
        results = client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return _join(results, blocks, p)


def _join(results, blocks, p: Plan) -> Reconstruction:
    """The tiles' faces as one welded mesh with its loops."""
    vertices, faces, offset = [], [], 0
    for v, f, _ in results:
        vertices.append(v)
        faces.append(f.astype(np.int64) + offset)
        offset += len(v)
    V = np.concatenate(vertices) if vertices else np.zeros((0, 3))
    F = np.concatenate(faces) if faces else np.zeros((0, 3), dtype=np.int64)
    V, F = weld(V, F, 1e-6 * p.cell)
    loops = boundary_loops(F) if len(F) else []
    info = dict(tiles=len(blocks), blocks=[b for b, _ in blocks], tile_samples=[n for _, n in blocks],
                cell_size=p.cell, sample_spacing=p.spacing, lattice_origin=p.origin.tolist(),
                lattice_end=p.end.tolist(), halo=p.halo, boundary_loops=len(loops),
                boundary_loop_edges=[len(l) for l in loops],
                seconds_tiles=[sum(v for k, v in r[2].items() if k.startswith("seconds_")) for r in results])
    return Reconstruction(V, F.astype(np.int32), loops, info)


def _samples(points_or_files, normals) -> Tuple[np.ndarray, np.ndarray]:
    """(n, 3) points and normals from arrays or files; normals are required."""
    if isinstance(points_or_files, (str, os.PathLike)) or (
            isinstance(points_or_files, (list, tuple)) and points_or_files and
            isinstance(points_or_files[0], (str, os.PathLike))):
        from .cloud import read_cloud
        files = [points_or_files] if isinstance(points_or_files, (str, os.PathLike)) else list(points_or_files)
        clouds = [read_cloud(f) for f in files]  # normals estimated once per file when it has none
        points = np.concatenate([c.points for c in clouds])
        normals = np.concatenate([c.normals for c in clouds])
    else:
        points = np.ascontiguousarray(points_or_files, dtype=np.float64).reshape(-1, 3)
    if normals is None:
        raise ValueError("tiled reconstruction needs the samples' normals: estimated tile by tile their "
                         "orientations would not agree across tiles. Estimate them once for the whole scan "
                         "(e.g. MeshLab's 'Compute normals for point sets') or reconstruct in one run.")
    normals = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 3)
    if normals.shape != points.shape:
        raise ValueError(f"normals have shape {normals.shape}, points {points.shape}: one normal per point")
    if not np.isfinite(points).all():
        raise ValueError("some sample positions are NaN or infinite: remove them first")
    return points, normals
