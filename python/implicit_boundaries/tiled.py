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

from .reconstruct import Reconstruction
from .tile_input import Bins, chunks, survey
from .tile_join import Join

#: The filter's automatic cell in sample spacings (Reconstruction::kCellPerSpacing).
CELL_PER_SPACING = 0.6
#: The halo, in sample spacings. At a tile's outer edge an octree node lacks the samples beyond
#: it, so it may stay one large cell where one run splits it; its support box then reaches in
#: as far as the split rule allows (at most 1200 samples in the box: about 24 spacings for a
#: box half inside the samples' surface). Measured on 200,000 samples of a wavy cap in 8
#: tiles: 20 spacings opened 4 slits along the seams, 40 gave one run's faces and loops exactly.
HALO_SPACINGS = 40
#: Lattice cells between the samples' box and the lattice's border.
MARGIN_CELLS = 4
#: The filter's min_boundary_edges default (BoundaryStage::kDefaultMinBoundaryEdges).
MIN_BOUNDARY_EDGES = 12


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


def plan(points, normals=None, resolution: int = 0, tiles: Optional[int] = None, tile_cells: int = 512,
         min_boundary_edges: int = MIN_BOUNDARY_EDGES) -> Plan:
    """The lattice and blocks for the samples (an (n, 3) array or files; tile_input.survey reads
    their box and spacing): cells of 0.6 spacings (the filter's automatic resolution, uncapped)
    or of longest side / `resolution`; blocks of about `tile_cells` cells a side, or at least
    `tiles` blocks, the longest blocks split first; the halo: see halo_width."""
    lo, hi, spacing, _ = survey(points, normals)
    return _plan(lo, hi, spacing, resolution, tiles, tile_cells, min_boundary_edges)


def halo_width(spacing: float, cell: float, min_boundary_edges: int = MIN_BOUNDARY_EDGES) -> float:
    """How far around its block a tile reads samples: HALO_SPACINGS, for one run's values
    everywhere in the block, plus the widest hole the filter may fill as undersampling, so that
    a tile sees whole every such hole that reaches into its block and decides it as one run
    does. A hole is filled when its loops have fewer than `min_boundary_edges` edges (counted
    at the median spacing); a marching-cubes edge lies in one cell, so it is at most sqrt(3)
    cells long, and a loop of E edges spans at most E sqrt(3) / 2 cells. At least 3 cells."""
    return max(HALO_SPACINGS * spacing + max(0, min_boundary_edges) * np.sqrt(3) / 2 * cell, 3 * cell)


def _plan(lo, hi, spacing: float, resolution: int, tiles: Optional[int], tile_cells: int,
          min_boundary_edges: int = MIN_BOUNDARY_EDGES) -> Plan:
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
    return Plan(float(cell), origin, end, spacing, planes, halo_width(spacing, cell, min_boundary_edges))


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
                resolution: int = 0, tiles: Optional[int] = None, tile_cells: int = 512,
                workers: Optional[int] = None, scheduler: Optional[str] = None, progress: bool = False,
                output: Optional[str] = None, viewpoint: Optional[np.ndarray] = None,
                **filter_params) -> Reconstruction:
    """The surface with boundaries of a scan, reconstructed in tiles on Dask.

    points_or_files: (n, 3) samples, or one or more point files (binary PLY and LAS/LAZ are
    read in chunks; the samples are binned to tiles on disk); normals: (n, 3) outward normals
    of the samples (files: their own), required unless a `viewpoint` (3,) is given: each tile
    then estimates its samples' normals facing it (oriented by propagation instead, tiles
    would not agree). resolution: cells along the longest side (0: cells of
    0.6 spacings, as the filter chooses, but without its cap of 1024); tiles: at least this
    many blocks, else blocks of about `tile_cells` cells a side; workers: local worker
    processes (default: the cores); scheduler: the address of an existing Dask scheduler
    instead (every worker needs this package and pymeshlab); progress: tiles done, on stderr;
    output: a .ply path: the surface is streamed there piece by piece and the returned
    Reconstruction holds no vertices or faces (its loops index the file's vertices);
    filter_params: the filter's other parameters by their pymeshlab names.
    Returns a Reconstruction whose info holds the plan and per-tile figures.
    """
    facing = viewpoint is not None
    if facing:  # reconstruct() in the worker turns it into the filter's normals and viewpoint
        filter_params["viewpoint"] = np.asarray(viewpoint, dtype=np.float64).reshape(3)
    source = _source(points_or_files, normals)
    lo, hi, spacing, with_normals = survey(source, normals)
    if not with_normals and not facing:
        raise ValueError("tiled reconstruction needs the samples' normals: estimated tile by tile and oriented "
                         "by propagation, their orientations would not agree across tiles. Give the normals, "
                         "or a viewpoint they face (viewpoint=...; the CLI's --viewpoint), or reconstruct "
                         "in one run.")
    p = _plan(lo, hi, spacing, resolution, tiles, tile_cells,
              int(filter_params.get("min_boundary_edges", MIN_BOUNDARY_EDGES)))
    bins = Bins(p.planes, p.halo)
    for points, given in chunks(source, normals):  # normals facing the viewpoint: zero, the filter's to fill
        bins.add(points, given if given is not None else np.zeros_like(points))
    client, cluster = _client(workers, scheduler)
    join = Join(0.01 * p.cell)  # tile_join.py says why a hundredth
    try:
        from distributed import as_completed
        # Tiles are read from their bins and submitted a few per worker ahead, so the client,
        # the scheduler and the workers hold a few tiles' samples, never the scan's.
        blocks = [(i, index, lo, hi) for i, (index, lo, hi) in enumerate(p.blocks()) if bins.counts[i] >= 20]
        ahead = 2 * max(1, len(client.scheduler_info()["workers"]))
        pending, futures, tile_info, what = iter(blocks), as_completed(), [], {}

        def submit_next():
            for t, index, lo, hi in pending:
                points, normals = bins.samples(t)
                future = client.submit(_reconstruct_tile, points, normals, dict(filter_params, **p.filter_params(lo, hi)),
                                       pure=False)
                what[future.key] = (index, len(points))
                futures.add(future)
                return

        for _ in range(ahead):
            submit_next()
        bar = _Progress(len(blocks)) if progress else None
        for future in futures:  # each piece to disk as it comes: the client holds one
            index, samples = what.pop(future.key)
            try:
                vertices, faces, info = future.result()
            except Exception as e:  # the filter's message, with the tile it is about
                raise ValueError(f"tile {index} ({samples} samples): {e}") from e
            join.add(vertices, faces)
            tile_info.append(dict(block=index, samples=samples, faces=len(faces),
                                  seconds=sum(v for k, v in info.items() if k.startswith("seconds_")),
                                  worker_peak_bytes=info["worker_peak_bytes"]))
            future.release()
            submit_next()
            if bar:
                bar.step()
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
        bins.close()
        client.close()
        if cluster is not None:
            cluster.close()


def _source(points_or_files, normals):
    """The samples as tile_input.chunks reads them: an (n, 3) array (checked against its
    normals) or a list of files."""
    if isinstance(points_or_files, (str, os.PathLike)):
        return [points_or_files]
    if isinstance(points_or_files, (list, tuple)) and points_or_files and \
            isinstance(points_or_files[0], (str, os.PathLike)):
        return list(points_or_files)
    points = np.ascontiguousarray(points_or_files, dtype=np.float64).reshape(-1, 3)
    if normals is not None and np.shape(normals) != points.shape:
        raise ValueError(f"normals have shape {np.shape(normals)}, points {points.shape}: one normal per point")
    return points


class _Progress:
    """Tiles done, on stderr (the CLI's bar)."""

    def __init__(self, total: int):
        self.total, self.done = total, 0

    def step(self) -> None:
        import sys
        self.done += 1
        sys.stderr.write(f"\rtiles {self.done}/{self.total}")
        if self.done == self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()
