"""The samples of a tiled run, read in chunks and binned to tiles on disk, so that no process
holds the whole scan: binary PLY through a memory map, LAS/LAZ through laspy's chunk reader,
arrays as one chunk (other formats: read whole by pymeshlab).

Passes over the chunks: the bounding box and a coarse occupancy; the samples of a few occupied
voxels, where the scan's median spacing is measured exactly (seeds whose 8 neighbours all lie in
their voxel); then every sample appended to the tile file of each block whose halo holds it.
"""
import tempfile
from pathlib import Path
from typing import Iterator, List, Optional, Sequence, Tuple

import numpy as np
from scipy.spatial import cKDTree

#: Samples per chunk read.
CHUNK = 1_000_000
#: Voxels along the longest side of the box, for the spacing's sample of voxels.
VOXELS = 64
#: Voxels (drawn by their sample counts) whose samples measure the spacing.
SPACING_VOXELS = 40

_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def _ply_vertices(path: Path) -> Optional[np.memmap]:
    """The vertex element of a binary PLY file whose first element is its vertices with scalar
    properties, as a memory-mapped structured array; None for any other file."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            return None
        order, count, fields, element = None, 0, [], None
        while True:
            line = f.readline()
            if not line:
                return None
            words = line.decode("ascii", "replace").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "format":
                order = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(words[1])
            elif words[0] == "element":
                if element is not None and element != "vertex" and not fields:
                    return None  # another element before the vertices
                element = words[1]
                if element == "vertex":
                    count = int(words[2])
            elif words[0] == "property" and element == "vertex":
                if words[1] == "list" or words[1] not in _PLY_TYPES:
                    return None
                fields.append((words[2], order + _PLY_TYPES[words[1]] if order else "f8"))
            elif words[0] == "end_header":
                break
        offset = f.tell()
    names = [n for n, _ in fields]
    if order is None or not {"x", "y", "z"} <= set(names):
        return None
    return np.memmap(path, dtype=np.dtype(fields), mode="r", offset=offset, shape=(count,))


def _columns(rows, names: Sequence[str]) -> Optional[np.ndarray]:
    if not all(n in rows.dtype.names for n in names):
        return None
    return np.column_stack([np.asarray(rows[n], dtype=np.float64) for n in names])


def chunks(source, normals: Optional[np.ndarray] = None) -> Iterator[Tuple[np.ndarray, Optional[np.ndarray]]]:
    """(points (k, 3), normals (k, 3) or None) chunks of an array (with `normals`), or of one or
    more files, in the order of their rows."""
    if isinstance(source, np.ndarray):
        yield np.asarray(source, dtype=np.float64).reshape(-1, 3), normals
        return
    for path in [Path(p) for p in ([source] if isinstance(source, (str, Path)) else source)]:
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no such file")
        vertices = _ply_vertices(path) if path.suffix.lower() == ".ply" else None
        if vertices is not None:
            for start in range(0, len(vertices), CHUNK):
                rows = vertices[start:start + CHUNK]
                yield _columns(rows, "xyz"), _columns(rows, ("nx", "ny", "nz"))
        elif path.suffix.lower() in (".las", ".laz"):
            import laspy
            from .cloud import LAS_NORMALS
            with laspy.open(str(path)) as las:
                names = {n.lower(): n for n in las.header.point_format.extra_dimension_names}
                triple = next((t for t in LAS_NORMALS if all(n in names for n in t)), None)
                for part in las.chunk_iterator(CHUNK):
                    points = np.column_stack([np.asarray(part.x), np.asarray(part.y), np.asarray(part.z)])
                    yield points.astype(np.float64), (None if triple is None else np.column_stack(
                        [np.asarray(part[names[n]], dtype=np.float64) for n in triple]))
        else:
            from .cloud import read_cloud
            cloud = read_cloud(path, estimate_normals=False)
            yield cloud.points, (cloud.normals if np.any(cloud.normals) else None)


def survey(source, normals=None, seed: int = 0) -> Tuple[np.ndarray, np.ndarray, float, bool]:
    """(lo, hi, median spacing, whether every chunk has normals) of the samples, in three passes.

    The spacing is the filter's (spacing.h: sqrt(pi r8^2 / 8), r8 the distance to the 8th
    nearest neighbour, in the sample's tangent plane when the samples have normals), measured on the samples of up to 40 voxels drawn by their counts, voxels
    coarse enough to hold 2,000 samples on average, at the seeds more than 3 median r8 inside
    their voxel (so their neighbours are all there; a rule on the seed's own r8 would favour
    the dense ones)."""
    lo, hi, with_normals = np.full(3, np.inf), np.full(3, -np.inf), True
    for points, n in chunks(source, normals):
        if not np.isfinite(points).all():
            raise ValueError("some sample positions are NaN or infinite: remove them first")
        lo, hi = np.minimum(lo, points.min(axis=0)), np.maximum(hi, points.max(axis=0))
        with_normals &= n is not None
    if not np.all(hi >= lo):
        raise ValueError("no samples")
    fine = max(float((hi - lo).max()), 1e-300) / VOXELS
    counts = {}
    for points, _ in chunks(source, normals):
        keys, n = np.unique(_voxel(points, lo, fine), return_counts=True)
        for k, c in zip(keys.tolist(), n.tolist()):
            counts[k] = counts.get(k, 0) + c
    fine_keys, fine_n = np.array(list(counts), dtype=np.int64), np.array(list(counts.values()), dtype=np.float64)
    keys, n, factor = fine_keys, fine_n, 1
    while n.sum() / len(keys) < 2000 and factor < VOXELS:  # coarser voxels: 2 x 2 x 2 of the last each
        factor *= 2
        keys, inverse = np.unique(_coarser(fine_keys, factor), return_inverse=True)
        n = np.bincount(inverse.ravel(), weights=fine_n)
    side = fine * factor
    rng = np.random.default_rng(seed)
    chosen = rng.choice(keys, size=min(SPACING_VOXELS, len(keys)), replace=False, p=n / n.sum())
    picked = [(points[m], n[m] if with_normals else None)
              for points, n in chunks(source, normals) for m in [np.isin(_voxel(points, lo, side), chosen)]]
    inside = np.concatenate([p for p, _ in picked])
    inside_normals = np.concatenate([n for _, n in picked]) if with_normals else None
    spacings = []
    for key in chosen:
        mask = _voxel(inside, lo, side) == key
        at = inside[mask]
        if len(at) < 10:
            continue
        r8 = _reach8(at, inside_normals[mask] if with_normals else None)
        corner = lo + side * np.array(_unkey(key), dtype=np.float64)
        wall = np.minimum(at - corner, corner + side - at).min(axis=1)
        spacings.append(np.sqrt(np.pi * r8[wall > 3 * np.median(r8)] ** 2 / 8))
    spacing = np.concatenate(spacings) if spacings else np.zeros(0)
    if len(spacing) == 0:
        raise ValueError("too few samples to measure their spacing (at least 10 close together are needed)")
    return lo, hi, float(np.median(spacing)), bool(with_normals)


def _reach8(points: np.ndarray, normals: Optional[np.ndarray]) -> np.ndarray:
    """Per sample, the distance to the farthest of its 8 nearest neighbours, as spacing.h
    measures it: with normals, in the sample's tangent plane, but in space for a neighbour whose
    normal faces away (across a thin part)."""
    distance, index = cKDTree(points).query(points, k=9)
    if normals is None:
        return distance[:, 8]
    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    d = points[index[:, 1:]] - points[:, None, :]
    along = np.einsum("ijk,ik->ij", d, n)
    same_side = np.einsum("ijk,ik->ij", n[index[:, 1:]], n) > 0
    return np.sqrt((np.einsum("ijk,ijk->ij", d, d) - np.where(same_side, along ** 2, 0)).max(axis=1))


_BASE = VOXELS + 1


def _voxel(points: np.ndarray, lo: np.ndarray, side: float) -> np.ndarray:
    """Key of the voxel of side `side` (from lo) holding each point."""
    c = np.floor((points - lo) / side).astype(np.int64)
    return c[:, 0] + _BASE * (c[:, 1] + _BASE * c[:, 2])


def _unkey(key: int) -> Tuple[int, int, int]:
    return key % _BASE, key // _BASE % _BASE, key // _BASE ** 2


def _coarser(fine_keys: np.ndarray, factor: int) -> np.ndarray:
    """The keys of the voxels `factor` times larger that hold the fine voxels."""
    x, y, z = fine_keys % _BASE // factor, fine_keys // _BASE % _BASE // factor, fine_keys // _BASE ** 2 // factor
    return x + _BASE * (y + _BASE * z)


class Bins:
    """Every sample appended, in input order, to the tile file of each block whose halo holds it
    (6 float64 columns: position, normal). planes, halo: as Plan's; tile (i, j, k) is number
    (i * ny + j) * nz + k, Plan.blocks()'s order."""

    def __init__(self, planes: Sequence[np.ndarray], halo: float):
        self._folder = tempfile.TemporaryDirectory(prefix="implicit-boundaries-bins-")
        self._planes, self._halo = [np.asarray(p, dtype=np.float64) for p in planes], halo
        self._shape = [len(p) - 1 for p in self._planes]
        self.counts = np.zeros(int(np.prod(self._shape)), dtype=np.int64)

    def add(self, points: np.ndarray, normals: np.ndarray) -> None:
        rows = np.hstack([points, normals]).astype("<f8")
        # Per axis, the first and last block whose halo holds each sample.
        first = [np.clip(np.searchsorted(p[1:], points[:, a] - self._halo, "left"), 0, n - 1)
                 for a, (p, n) in enumerate(zip(self._planes, self._shape))]
        last = [np.clip(np.searchsorted(p[:-1], points[:, a] + self._halo, "right") - 1, 0, n - 1)
                for a, (p, n) in enumerate(zip(self._planes, self._shape))]
        spans = [int((l - f).max()) + 1 for f, l in zip(first, last)]
        tiles, members = [], []
        for dx in range(spans[0]):
            for dy in range(spans[1]):
                for dz in range(spans[2]):
                    ix, iy, iz = first[0] + dx, first[1] + dy, first[2] + dz
                    ok = np.flatnonzero((ix <= last[0]) & (iy <= last[1]) & (iz <= last[2]))
                    tiles.append((ix[ok] * self._shape[1] + iy[ok]) * self._shape[2] + iz[ok])
                    members.append(ok)
        tiles, members = np.concatenate(tiles), np.concatenate(members)
        order = np.lexsort((members, tiles))  # by tile, then input order
        tiles, members = tiles[order], members[order]
        starts = np.flatnonzero(np.r_[True, tiles[1:] != tiles[:-1]])
        for begin, end in zip(starts, np.r_[starts[1:], len(tiles)]):
            t = int(tiles[begin])
            with open(self._path(t), "ab") as f:
                f.write(rows[members[begin:end]].tobytes())
            self.counts[t] += end - begin

    def samples(self, t: int) -> Tuple[np.ndarray, np.ndarray]:
        """(points, normals) of tile t, in input order."""
        if self.counts[t] == 0:
            return np.zeros((0, 3)), np.zeros((0, 3))
        rows = np.fromfile(self._path(t), dtype="<f8").reshape(-1, 6)
        return np.ascontiguousarray(rows[:, :3]), np.ascontiguousarray(rows[:, 3:])

    def close(self) -> None:
        self._folder.cleanup()

    def _path(self, t: int) -> Path:
        return Path(self._folder.name) / f"{t}.bin"
