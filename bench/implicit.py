"""The implicit functions against MeshLab's screened Poisson (issue: the paper's PU-RBF).

For each mesh with a known surface (its vertices and normals as the input) and a synthetic scan
of 1,000,000 samples, runs in separate processes (so each peak memory is its own): our filter
with the PU-RBF, with Hoppe's signed distance, and screened Poisson at the depth whose 2^depth
is nearest our lattice resolution. Reports fit (implicit construction) and extraction seconds,
total seconds, peak resident memory, the time ratio to Poisson, and, against the mesh itself,
the chamfer distance on the parts both reconstruct (samples within 1% of the diagonal of the
other surface), as % of the bounding-box diagonal.

    python bench/implicit.py [--data DIR] [--cases bun_zipper.ply ...] > results.md
    python bench/implicit.py --cases bun_zipper.ply tum_rabbit.ply --chamfer 212 512

"PU-RBF, fits of 20-60 samples" is the PU-RBF with smaller local fits (rbf_min_samples 20,
rbf_max_samples 60, rbf_off_surface 0.5): the setting that meets the chamfer target.
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pymeshlab

import implicit_boundaries
from boundaries import load_case
from extraction import synthetic_scan
from implicit_boundaries.methods import poisson_depth
from implicit_boundaries.options import Implicit
from implicit_boundaries.metrics import point_mesh_distance, sample_surface

DEFAULT_DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"
# Our filter's parameters per method ("screened Poisson" is MeshLab's filter).
METHODS = {
    Implicit.PU_RBF: {"implicit": Implicit.PU_RBF},
    "PU-RBF, fits of 20-60 samples": {"implicit": Implicit.PU_RBF, "rbf_min_samples": 20, "rbf_max_samples": 60,
                                      "rbf_off_surface": 0.5},
    Implicit.HOPPE: {"implicit": Implicit.HOPPE},
    "screened Poisson": None,
    # Variants of the paper's 50-160 samples per cell, run with --methods.
    "PU-RBF, off-surface 0.5": {"implicit": Implicit.PU_RBF, "rbf_off_surface": 0.5},
    "PU-RBF, overlap 1.2": {"implicit": Implicit.PU_RBF, "rbf_overlap": 1.2},
    "PU-RBF, overlap 1.2, off-surface 0.5": {"implicit": Implicit.PU_RBF, "rbf_overlap": 1.2, "rbf_off_surface": 0.5},
}
DEFAULT_METHODS = [Implicit.PU_RBF, "PU-RBF, fits of 20-60 samples", Implicit.HOPPE, "screened Poisson"]


def surface_distances(vertices, faces, truth_vertices, truth_faces, samples=20000):
    """Distances from samples of the result to the true surface, and from samples of the true
    surface (on its triangles, between its vertices) to the result."""
    to_truth = point_mesh_distance(sample_surface(vertices, faces, samples, seed=2), truth_vertices, truth_faces)
    to_result = point_mesh_distance(sample_surface(truth_vertices, truth_faces, samples, seed=1), vertices, faces)
    return to_truth, to_result


def shared_chamfer(to_truth, to_result, tolerance):
    """Chamfer distance restricted to what both surfaces cover: the mean of the two mean
    sample-to-other-surface distances, each over the samples within `tolerance`."""
    return 0.5 * (to_truth[to_truth <= tolerance].mean() + to_result[to_result <= tolerance].mean())


def one(case, data, method, resolution):
    if case == "synthetic 1M":
        points, normals = synthetic_scan()
        truth = None
    else:
        points, normals, faces = load_case(data / case)
        truth = (points.copy(), faces) if len(faces) else None  # gargoyle: points only
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
    t = time.perf_counter()
    if method == "screened Poisson":
        # All cores, as our filter uses.
        ms.generate_surface_reconstruction_screened_poisson(depth=poisson_depth(resolution),
                                                            threads=os.cpu_count())
        info = {}
    else:
        info = implicit_boundaries.apply(ms, resolution=resolution, **METHODS[method])
    seconds = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    out = {"seconds": seconds, "peak_mb": peak, "resolution": float(info.get("resolution", resolution)),
           "fit_s": float(info.get("seconds_implicit", np.nan)), "extract_s": float(info.get("seconds_extraction", np.nan)),
           "loops": float(info.get("boundary_loops", np.nan))}
    if truth is not None:
        m = ms.current_mesh()
        diagonal = np.linalg.norm(points.max(0) - points.min(0))
        to_truth, to_result = surface_distances(m.vertex_matrix(), m.face_matrix(), *truth)
        out["chamfer_pct"] = 100 * shared_chamfer(to_truth, to_result, 0.01 * diagonal) / diagonal
        # Where the distance is: at the scan's vertices, or between them on its triangles.
        at_vertices = point_mesh_distance(truth[0][::5], m.vertex_matrix(), m.face_matrix())
        out["median_at_scan_vertices_pct"] = 100 * np.median(at_vertices) / diagonal
        out["median_on_scan_triangles_pct"] = 100 * np.median(to_result) / diagonal
    return out


def child(case, data, method, resolution):
    cmd = [sys.executable, __file__, "--one", case, method, str(resolution), "--data", str(data)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--data", type=Path, default=DEFAULT_DATA)
    p.add_argument("--cases", nargs="+", default=["bun_zipper.ply", "tum_rabbit.ply", "gargoyle.ply", "synthetic 1M"])
    p.add_argument("--chamfer", type=int, nargs="+", metavar="RESOLUTION",
                   help="only the chamfer of each method on each case at these resolutions, and where it "
                        "comes from (median distance at the scan's vertices and on its triangles)")
    p.add_argument("--methods", nargs="+", choices=list(METHODS), default=DEFAULT_METHODS, metavar="METHOD",
                   help=f"rows per case, from: {'; '.join(METHODS)}; the first sets the resolution of the others (automatic), and "
                        "the time ratio is nan without \"screened Poisson\"")
    p.add_argument("--one", nargs=3, metavar=("CASE", "METHOD", "RESOLUTION"), help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    implicit_boundaries.load()
    if args.one:
        case, method, resolution = args.one
        print(json.dumps(one(case, args.data, method, int(resolution))))
        return
    if args.chamfer:
        print("| input | method | resolution / depth | chamfer, shared parts (% diag) "
              "| median at scan vertices | median on scan triangles |\n|---|---|---|---|---|---|")
        for case in args.cases:
            for resolution in args.chamfer:
                for method in args.methods:
                    r = child(case, args.data, method, resolution)
                    size = f"depth {poisson_depth(resolution)}" if method == "screened Poisson" else f"{resolution}"
                    print(f"| {case} | {method} | {size} | {r['chamfer_pct']:.4f} | {r['median_at_scan_vertices_pct']:.4f} "
                          f"| {r['median_on_scan_triangles_pct']:.4f} |", flush=True)
        return
    print("| input | method | resolution / depth | fit (s) | extraction (s) | total (s) | / screened Poisson "
          "| peak memory (MB) | loops | chamfer, shared parts (% diag) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases:
        rows = {}
        first, *others = args.methods
        rows[first] = child(case, args.data, first, 0)
        resolution = int(rows[first].get("resolution", 256))
        for method in others:
            rows[method] = child(case, args.data, method, resolution)
        poisson = rows.get("screened Poisson", {"error": "not run"})
        for method, r in rows.items():
            if "error" in r:
                print(f"| {case} | {method} | {r['error']} ||||||||")
                continue
            size = f"depth {poisson_depth(resolution)}" if method == "screened Poisson" else f"{resolution}"
            ratio = r["seconds"] / poisson["seconds"] if "error" not in poisson else float("nan")
            print(f"| {case} | {method} | {size} | {r['fit_s']:.2f} | {r['extract_s']:.2f} | {r['seconds']:.2f} "
                  f"| {ratio:.2f} | {r['peak_mb']:.0f} | {r['loops']:.0f} | {r.get('chamfer_pct', float('nan')):.4f} |",
                  flush=True)


if __name__ == "__main__":
    main()
