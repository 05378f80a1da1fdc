"""A scan reconstructed tile by tile on Dask, joined into one surface with boundaries.

The scan gets one lattice (cell and origin fixed from a robust estimate of its sample spacing)
cut into blocks of whole cells. Each block is one Dask task: the filter runs through pymeshlab
in the worker's process on the block's samples plus a halo, on the whole scan's lattice, with
the PU-RBF's octree rooted at the whole scan's cube, and keeps the faces whose centre lies in
the block. Values at the lattice corners a block shares with its neighbour are then computed
from the same samples and the same numbers, so the faces of neighbouring blocks meet at the
same vertices; the join (tile_join.py) welds them, one piece in memory at a time.
"""
import os
from dataclasses import dataclass
from typing import Dict, Iterator, Optional, Sequence, Tuple, Union

import numpy as np
from scipy.spatial import cKDTree

from .options import Normals
from .reconstruct import Reconstruction
from .tile_join import Join

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
    r.info["worker_peak_bytes"] = _peak_resident_bytes()
    return r.vertices, r.faces, r.info


def _peak_resident_bytes() -> float:
    """This process's peak resident memory so far (Linux's VmHWM; getrusage's ru_maxrss would
    carry the peak of the process that forked the worker), 0 where /proc is not there."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return 1024.0 * int(line.split()[1])
    except OSError:
        pass
    return 0.0


def _tile_rows(points: np.ndarray, lo: np.ndarray, hi: np.ndarray, halo: float) -> np.ndarray:
    """Rows (ascending, as one run sees them) of the samples in [lo - halo, hi + halo]."""
    inside = np.all((points >= lo - halo) & (points <= hi + halo), axis=1)
    return np.flatnonzero(inside)


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
                output: Optional[str] = None, **filter_params) -> Reconstruction:
    """The surface with boundaries of a scan, reconstructed in tiles on Dask.

    points_or_files: (n, 3) samples, or one or more point files (read with their normals);
    normals: (n, 3) outward normals of the samples (required: orientations estimated tile by
    tile would not agree across tiles). resolution: cells along the longest side (0: cells of
    0.6 spacings, as the filter chooses, but without its cap of 1024); tiles: at least this
    many blocks, else blocks of about `tile_cells` cells a side; workers: local worker
    processes (default: the cores); scheduler: the address of an existing Dask scheduler
    instead (every worker needs this package and pymeshlab); progress: Dask's progress bar;
    output: a .ply path: the surface is streamed there piece by piece and the returned
    Reconstruction holds no vertices or faces (its loops index the file's vertices);
    filter_params: the filter's other parameters by their pymeshlab names.
    Returns a Reconstruction whose info holds the plan and per-tile figures.
    """
    facing = filter_params.get("normals") == Normals.FACING_VIEWPOINT
    points, normals = _samples(points_or_files, normals, facing)
    p = plan(points, resolution=resolution, tiles=tiles, tile_cells=tile_cells)
    client, cluster = _client(workers, scheduler)
    join = Join(1e-6 * p.cell)
    try:
        from distributed import as_completed
        futures, blocks = [], {}
        for index, lo, hi in p.blocks():
            rows = _tile_rows(points, lo, hi, p.halo)
            if len(rows) < 20:  # the filter needs samples to fit planes; such a block holds no surface
                continue
            params = dict(filter_params, **p.filter_params(lo, hi))
            future = client.submit(_reconstruct_tile, points[rows], normals[rows], params, pure=False)
            futures.append(future)
            blocks[future.key] = (index, len(rows))
        if progress:
            from distributed import progress as show
            show(futures)
        tile_info = []
        for future in as_completed(futures):  # each piece to disk as it comes: the client holds one
            vertices, faces, info = future.result()
            join.add(vertices, faces)
            tile_info.append(dict(block=blocks[future.key][0], samples=blocks[future.key][1],
                                  faces=len(faces), seconds=sum(v for k, v in info.items() if k.startswith("seconds_")),
                                  worker_peak_bytes=info["worker_peak_bytes"]))
            future.release()
        loops = join.finish()
        if output is None:
            vertices, faces = join.arrays()
        else:
            join.write_ply(output)
            vertices, faces = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32)
        info = dict(tiles=len(tile_info), vertex_count=join.vertex_count, face_count=join.face_count,
                    cell_size=p.cell, sample_spacing=p.spacing, lattice_origin=p.origin.tolist(),
                    lattice_end=p.end.tolist(), halo=p.halo, boundary_loops=len(loops),
                    boundary_loop_edges=[len(loop) for loop in loops], tile_info=tile_info,
                    worker_peak_bytes=max((t["worker_peak_bytes"] for t in tile_info), default=0.0))
        return Reconstruction(vertices, faces, loops, info)
    finally:
        join.close()
        client.close()
        if cluster is not None:
            cluster.close()


def _samples(points_or_files, normals, facing: bool) -> Tuple[np.ndarray, np.ndarray]:
    """(n, 3) points and normals from arrays or files. Normals are required, unless they are
    estimated facing a viewpoint (`facing`): each tile then turns its estimates to face it, a
    rule that needs no other tile (zero normals are returned for the filter to fill)."""
    if isinstance(points_or_files, (str, os.PathLike)) or (
            isinstance(points_or_files, (list, tuple)) and points_or_files and
            isinstance(points_or_files[0], (str, os.PathLike))):
        from .cloud import read_cloud
        files = [points_or_files] if isinstance(points_or_files, (str, os.PathLike)) else list(points_or_files)
        # Without normals: MeshLab's point-cloud normals, once per file (or none, when facing).
        clouds = [read_cloud(f, estimate_normals=not facing) for f in files]
        points = np.concatenate([c.points for c in clouds])
        normals = np.concatenate([c.normals for c in clouds])
    else:
        points = np.ascontiguousarray(points_or_files, dtype=np.float64).reshape(-1, 3)
    if normals is None and facing:
        normals = np.zeros_like(points)
    if normals is None:
        raise ValueError("tiled reconstruction needs the samples' normals: estimated tile by tile and oriented "
                         "by propagation, their orientations would not agree across tiles. Give the normals, "
                         "or a viewpoint they face (normals=Normals.FACING_VIEWPOINT, viewpoint=...; the CLI's "
                         "--viewpoint), or reconstruct in one run.")
    normals = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 3)
    if normals.shape != points.shape:
        raise ValueError(f"normals have shape {normals.shape}, points {points.shape}: one normal per point")
    if not np.isfinite(points).all():
        raise ValueError("some sample positions are NaN or infinite: remove them first")
    return points, normals
