"""Large scans, where the automatic resolution's cap makes the lattice coarser than the sampling
(issue: boundaries on unseen scans, kind 7). Random samples (not a mesh's vertices) of a smooth
open surface with one boundary (tests/shapes.py `wavy_cap`: the unit sphere above z = -0.2,
its radius times 1 + 0.03 sin 8x sin 8y, with exact normals), at several sizes, each at the
automatic resolution and at a hand-set lattice `--coarser` times coarser than the sampling.
Each run in its own process, so its peak resident memory is its own. With --triangulated the
samples also come as a mesh (their triangulation on the unit sphere, the triangles across the
opening left out), which the filter keeps as an input mesh (keep_mesh_holes): what that costs.

    python bench/large_scan.py [--sizes 100000 1000000 5000000 10000000] [--coarser 4] [--triangulated]
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pymeshlab
from scipy.spatial import ConvexHull, cKDTree

import implicit_boundaries

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import shapes  # noqa: E402


def spacing_estimate(points):
    """The filter's spacing measure, sqrt(area per sample) from 8 neighbours, on a subsample."""
    r8 = cKDTree(points).query(points[:: max(1, len(points) // 2000)], k=9)[0][:, 8]
    return float(np.median(np.sqrt(np.pi * r8 ** 2 / 8)))


def resident_kib(field):
    """VmRSS (resident now) or VmHWM (peak since the last reset_peak) of this process, KiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise RuntimeError(f"no {field} in /proc/self/status")


def reset_peak():
    """Sets the peak resident size to the current one (Linux: clear_refs 5). Without it the peak
    would include what generating the samples took before the call, and the filter's share
    (peak - before) would come out too small by a different amount at each size."""
    Path("/proc/self/clear_refs").write_text("5")


def triangulation(points, normals):
    """(f, 3) triangles of the cap's samples: their convex hull once projected onto the unit
    sphere (every sample is a hull vertex there), without the triangles that span the opening
    (an edge over 5 spacings), oriented along the normals."""
    faces = ConvexHull(points / np.linalg.norm(points, axis=1, keepdims=True)).simplices
    corners = points[faces]
    longest = np.max(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2), axis=1)
    faces = faces[longest < 5 * spacing_estimate(points)]
    corners = points[faces]
    outward = np.einsum("ij,ij->i", np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                        normals[faces].sum(axis=1)) > 0
    faces[~outward] = faces[~outward][:, ::-1]
    return np.ascontiguousarray(faces, dtype=np.int32)


def one(n, coarser, triangulated=False):
    """One filter call in this process: its loops, surface error and figures. Memory: the
    process's resident size before the call with the point layer loaded, and its peak during
    the call (the filter's own share is the difference, what its memory estimate is for)."""
    points, normals = shapes.wavy_cap(n)
    resolution = 0
    if coarser:
        resolution = int(round(np.ptp(points, axis=0).max() / (coarser * spacing_estimate(points))))
    implicit_boundaries.load()
    ms = pymeshlab.MeshSet()
    if triangulated:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, face_matrix=triangulation(points, normals),
                                   v_normals_matrix=normals), "samples")
    else:
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "samples")
    del points, normals
    before = resident_kib("VmRSS")
    reset_peak()
    t = time.perf_counter()
    info = implicit_boundaries.apply(ms, resolution=resolution)
    seconds = time.perf_counter() - t
    peak = resident_kib("VmHWM")
    vertices = ms.current_mesh().vertex_matrix()
    loops = implicit_boundaries.loops_from_result(info)
    u = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    radius = 1 + 0.03 * np.sin(8 * u[:, 0]) * np.sin(8 * u[:, 1])
    error = np.abs(np.linalg.norm(vertices, axis=1) - radius)
    return {"seconds": seconds, "peak_gb": peak / 2 ** 20, "before_gb": before / 2 ** 20,
            "resolution": int(info["resolution"]), "spacing": float(info["sample_spacing"]),
            "cell": float(info["cell_size"]), "loops": len(loops),
            "largest": sorted((len(loop) for loop in loops), reverse=True)[:4],
            "max_error_spacings": float(error.max() / info["sample_spacing"]),
            "faces": int(info["surface_faces"]), "sods_cells": int(info["sods_cells"]),
            "input_faces": ms.mesh(0).face_number(),
            "memory_estimate_gb": float(info.get("memory_estimate_gb", float("nan")))}


def child(n, coarser, triangulated):
    done = subprocess.run([sys.executable, __file__, "--one", str(n), str(coarser), str(int(triangulated))],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000, 5_000_000, 10_000_000])
    p.add_argument("--coarser", type=float, default=4.0,
                   help="the hand-set lattice's cell in sample spacings (0: only the automatic resolution)")
    p.add_argument("--triangulated", action="store_true",
                   help="the samples as a mesh too: each size run with and without its triangles")
    p.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.one:
        print(json.dumps(one(int(args.one[0]), float(args.one[1]), args.one[2] == "1")))
        return
    print("| samples | lattice | resolution | cell / spacing | loops (true: 1) | largest loops "
          "| farthest vertex from the surface (spacings) | time (s) | SODS cells | peak memory (GB) "
          "| filter's share: peak - before (GB) | its estimate (GB) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in args.sizes:
        runs = [(coarser, False) for coarser in [0.0] + ([args.coarser] if args.coarser else [])]
        for coarser, triangulated in runs + ([(0.0, True)] if args.triangulated else []):
            r = child(n, coarser, triangulated)
            label = "automatic" if not coarser else f"{coarser:g}x coarser than the spacing"
            if triangulated:
                label += f", as a mesh of {r.get('input_faces', 0):,} faces"
            if "error" in r:
                print(f"| {n:,} | {label} | {r['error']} ||||||||||", flush=True)
                continue
            print(f"| {n:,} | {label} | {r['resolution']} | {r['cell'] / r['spacing']:.2f} | {r['loops']} "
                  f"| {r['largest']} | {r['max_error_spacings']:.2f} | {r['seconds']:.1f} | {r['sods_cells']:,} "
                  f"| {r['peak_gb']:.2f} (before {r['before_gb']:.2f}) | {r['peak_gb'] - r['before_gb']:.2f} "
                  f"| {r['memory_estimate_gb']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
