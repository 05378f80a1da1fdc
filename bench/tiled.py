"""Tiled reconstruction on Dask against one run on the same lattice (issue: tiles on Dask).
Random samples of a smooth open surface with one boundary (tests/shapes.py `wavy_cap`), at
each size: one run of the filter on the tiled run's lattice (all faces kept), then the tiled
run (`implicit_boundaries.tiled`, a local cluster of --workers processes). Printed per size:
loops and faces of both, how far the tiled surface's vertices lie from the one run's surface
(in cells; on up to 200,000 of them), the times and their ratio, each worker's peak memory and
the client's (this process: the plan, the bins, the join).

    python bench/tiled.py [--sizes 1000000 5000000] [--tiles 8] [--workers 1 2] [--resolution 1024]
    python bench/tiled.py --sizes 1000000 2000000 4000000 --tiles 0 --resolution 0 --skip-single [--las]
"""
import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from implicit_boundaries import reconstruct, tiled
from implicit_boundaries.metrics import point_mesh_distance

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import shapes  # noqa: E402


def peak_kib():
    """VmHWM of this process (KiB): the one run's peak, with the samples."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1])
    return 0


def write_ply(path: Path, points: np.ndarray, normals: np.ndarray) -> Path:
    """The samples as a binary PLY file of double positions and normals."""
    with open(path, "wb") as out:
        out.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
                   + "".join(f"property double {c}\n" for c in ("x", "y", "z", "nx", "ny", "nz"))
                   + "end_header\n").encode("ascii"))
        out.write(np.hstack([points, normals]).astype("<f8").tobytes())
    return path


def write_las(path: Path, points: np.ndarray, normals: np.ndarray) -> Path:
    """The samples as a LAS 1.4 file (coordinates to a millionth of the scan's extent), the
    normals as the extra dimensions nx, ny, nz (what tile_input reads as normals)."""
    import laspy
    header = laspy.LasHeader(point_format=6, version="1.4")
    header.offsets = points.min(axis=0)
    header.scales = np.full(3, 1e-6 * np.ptp(points, axis=0).max())
    header.add_extra_dims([laspy.ExtraBytesParams(name=c, type=np.float64) for c in ("nx", "ny", "nz")])
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.nx, las.ny, las.nz = normals[:, 0], normals[:, 1], normals[:, 2]
    las.write(str(path))
    return path


def main(argv=None):
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--sizes", type=int, nargs="+", default=[1_000_000, 5_000_000])
    a.add_argument("--tiles", type=int, default=8, help="at least this many tiles (0: tiles of --tile-cells)")
    a.add_argument("--workers", type=int, nargs="+", default=[2], help="local worker counts to run (scaling)")
    a.add_argument("--tile-cells", type=int, default=512, help="without --tiles: cells along a tile's side")
    a.add_argument("--resolution", type=int, default=1024,
                   help="cells along the longest side (0: 0.6 spacings, uncapped); 1024 = one run's automatic cap")
    a.add_argument("--skip-single", action="store_true",
                   help="only the tiled run, from a binary PLY file written first, to a PLY file (sizes one run cannot do)")
    a.add_argument("--las", action="store_true", help="with --skip-single: the scan as a LAS file instead of binary PLY")
    args = a.parse_args(argv)
    print("| samples | workers | tiles | cell | one run: loops, faces, s, peak GB | tiled: loops, faces, s, peak GB per worker "
          "| farthest vertex (cells) | tiled / one run time |")
    print("|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        points, normals = shapes.wavy_cap(n, seed=0)
        tiles = args.tiles or None
        p = tiled.plan(points, resolution=args.resolution, tiles=tiles, tile_cells=args.tile_cells)
        one_cell, one = "-", None
        if not args.skip_single:
            Path("/proc/self/clear_refs").write_text("5")  # resets VmHWM
            start = time.perf_counter()
            one = reconstruct(points, normals, **p.filter_params(p.origin, p.origin))
            one_seconds = time.perf_counter() - start
            one_cell = f"{len(one.loops)}, {len(one.faces):,}, {one_seconds:.1f}, {peak_kib() / 2**20:.2f}"
        source, output = (points, normals), None
        if args.skip_single:  # the scan on disk, as a user's would be, and the surface streamed there
            folder = tempfile.mkdtemp(prefix="bench-tiled-")
            scan = (write_las(Path(folder) / "scan.las", points, normals) if args.las
                    else write_ply(Path(folder) / "scan.ply", points, normals))
            source, output = ([scan], None), str(Path(folder) / "out.ply")
            del points, normals
        for workers in args.workers:
            Path("/proc/self/clear_refs").write_text("5")
            start = time.perf_counter()
            t = tiled.reconstruct(*source, resolution=args.resolution, tiles=tiles,
                                  tile_cells=args.tile_cells, workers=workers, output=output)
            tiled_seconds = time.perf_counter() - start
            client_gb = peak_kib() / 2**20
            far, ratio = "-", "-"
            if one is not None:
                rng = np.random.default_rng(0)
                probe = t.vertices[rng.choice(len(t.vertices), min(200_000, len(t.vertices)), replace=False)]
                far = f"{point_mesh_distance(probe, one.vertices, one.faces).max() / p.cell:.2g}"
                ratio = f"{tiled_seconds / one_seconds:.2f}"
            print(f"| {n:,} | {workers} | {t.info['tiles']} | {p.cell:.3g} | {one_cell} | {len(t.loops)}, "
                  f"{t.info['face_count']:,}, {tiled_seconds:.1f}, {t.info['worker_peak_bytes'] / 2**30:.2f} "
                  f"(client {client_gb:.2f}) | {far} | {ratio} |", flush=True)
            del t
        if args.skip_single:
            shutil.rmtree(folder)

if __name__ == "__main__":
    main()
