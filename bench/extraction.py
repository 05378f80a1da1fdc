"""SODS-driven extraction against the full lattice (issue: evaluate only where the surface can be).

For bun_zipper and a synthetic scan of 1,000,000 samples with boundaries, at resolutions 128,
256 and 512, runs the filter with each extraction mode (SODS-driven, the paper's full lattice
gated, plain marching cubes), each in its own process so that its peak memory is its own, and
reports implicit evaluations, wall time, peak resident memory and the ratios between modes;
then the SODS-driven mode at 1024 on the synthetic scan (the memory target).

    python bench/extraction.py [--data DIR] [--resolutions 128 256 512] > results.md
    python bench/extraction.py --large    # 5,000,000 samples at the default resolution
"""
import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pymeshlab

import implicit_boundaries
from implicit_boundaries.options import Extraction, Implicit
from boundaries import load_case

DEFAULT_DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"
MODES = list(Extraction.LABELS)


def synthetic_scan(n=1_000_000, seed=0):
    """n samples (with normals) of a bumpy sphere of radius about 1, cut below z = -0.5 and
    with three round holes: an open scan with four boundaries."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(int(n * 1.4), 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    keep = d[:, 2] > -0.5
    for centre in ([1, 0, 0.2], [0, 1, 0.4], [-0.6, -0.6, 0.5]):
        c = np.asarray(centre, float) / np.linalg.norm(centre)
        keep &= d @ c < np.cos(0.25)
    d = d[keep][:n]
    # Radius r(d) = 1 + 0.05 sin(5x) sin(5y); the normal is the gradient of |p| - r(p / |p|):
    # d minus the tangential gradient of r over |p|.
    bump = 0.05 * np.sin(5 * d[:, 0]) * np.sin(5 * d[:, 1])
    points = d * (1 + bump)[:, None]
    grad_r = 0.25 * np.stack([np.cos(5 * d[:, 0]) * np.sin(5 * d[:, 1]),
                              np.sin(5 * d[:, 0]) * np.cos(5 * d[:, 1]), np.zeros(len(d))], axis=1)
    tangential = grad_r - (grad_r * d).sum(1, keepdims=True) * d
    normals = d - tangential / (1 + bump)[:, None]
    return points, normals / np.linalg.norm(normals, axis=1, keepdims=True)


def load(case, data):
    if case.startswith("synthetic "):  # "synthetic 1M", "synthetic 5M"
        return synthetic_scan(int(float(case.split()[1].rstrip("M")) * 1_000_000))
    points, normals, _ = load_case(data / case)
    return points, normals


def one(case, data, resolution, mode, implicit):
    """Runs one filter call in this process; returns its figures (peak memory of the process)."""
    points, normals = load(case, data)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
    del points, normals
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t = time.perf_counter()
    out = implicit_boundaries.apply(ms, resolution=resolution, extraction=mode, implicit=implicit)
    seconds = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {"seconds": seconds, "peak_mb": peak / 1024, "before_mb": before / 1024,
            **{k: float(out[k]) for k in ["implicit_evaluations", "full_lattice_evaluations", "crossed_cell_corners",
                                          "sods_cells", "surface_faces", "boundary_loops", "seconds_extraction",
                                          "seconds_sods", "seconds_implicit", "seconds_boundaries", "resolution",
                                          "memory_limit_gb"]}}


def child(case, data, resolution, mode, implicit):
    cmd = [sys.executable, __file__, "--one", case, str(resolution), mode, "--data", str(data), "--implicit", implicit]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "failed"}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--data", type=Path, default=DEFAULT_DATA)
    p.add_argument("--resolutions", type=int, nargs="+", default=[128, 256, 512])
    p.add_argument("--cases", nargs="+", default=["bun_zipper.ply", "synthetic 1M"])
    p.add_argument("--modes", nargs="+", choices=MODES, default=MODES,
                   help="extraction modes to run (the full lattice on the synthetic sphere is slow: its "
                        "centre is the k-d tree's worst case)")
    p.add_argument("--implicit", default=Implicit.PU_RBF, help="the filter's implicit function (default: its default)")
    p.add_argument("--large", action="store_true",
                   help="only a synthetic 5,000,000-sample scan at the default (automatic) resolution")
    p.add_argument("--one", nargs=3, metavar=("CASE", "RESOLUTION", "MODE"), help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    implicit_boundaries.load()
    if args.one:
        case, resolution, mode = args.one
        print(json.dumps(one(case, args.data, int(resolution), mode, args.implicit)))
        return
    if args.large:
        r = child("synthetic 5M", args.data, 0, Extraction.SODS_DRIVEN, args.implicit)
        print("| samples | resolution | time (s) | implicit / SODS / extraction / boundaries (s) | peak memory (GB) "
              "| memory limit (GB) | SODS cells | faces | loops |\n|---|---|---|---|---|---|---|---|---|")
        print(f"| 5,000,000 | {r['resolution']:.0f} (automatic) | {r['seconds']:.1f} | {r['seconds_implicit']:.1f} / "
              f"{r['seconds_sods']:.1f} / {r['seconds_extraction']:.1f} / {r['seconds_boundaries']:.1f} "
              f"| {r['peak_mb'] / 1024:.2f} (input {r['before_mb'] / 1024:.2f}) | {r['memory_limit_gb']:.1f} "
              f"| {r['sods_cells']:.0f} | {r['surface_faces']:.0f} | {r['boundary_loops']:.0f} |")
        return

    print("| input | resolution | mode | evaluations | / crossed-cell corners | time (s) | extraction (s) "
          "| peak memory (MB) | faces | loops | time / full lattice gated | extraction: full gated / plain |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases:
        for resolution in args.resolutions:
            rows = {mode: child(case, args.data, resolution, mode, args.implicit) for mode in args.modes}
            missing = {"error": "not run"}
            full, plain = rows.get(Extraction.FULL_LATTICE, missing), rows.get(Extraction.PLAIN, missing)
            for mode, r in rows.items():
                if "error" in r:
                    print(f"| {case} | {resolution} | {mode} | {r['error']} |||||||")
                    continue
                vs_full = f"{r['seconds'] / full['seconds']:.3f}" if "error" not in full else ""
                vs_plain = (f"{full['seconds_extraction'] / plain['seconds_extraction']:.3f}"
                            if mode == Extraction.FULL_LATTICE and "error" not in plain else "")
                print(f"| {case} | {resolution} | {mode} | {r['implicit_evaluations']:.0f} "
                      f"| {r['implicit_evaluations'] / r['crossed_cell_corners']:.2f} | {r['seconds']:.2f} "
                      f"| {r['seconds_extraction']:.2f} "
                      f"| {r['peak_mb']:.0f} (input {r['before_mb']:.0f}) | {r['surface_faces']:.0f} "
                      f"| {r['boundary_loops']:.0f} | {vs_full} | {vs_plain} |", flush=True)
    r = child("synthetic 1M", args.data, 1024, Extraction.SODS_DRIVEN, args.implicit)
    print(f"\nSODS-driven at 1024 on the synthetic 1M scan: {r}")


if __name__ == "__main__":
    main()
