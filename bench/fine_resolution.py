"""Loops and time when the resolution is set by hand finer than the automatic one (issue:
boundaries on unseen scans): random samples of the smooth cap `wavy_cap` (tests/shapes.py, one
boundary, the rim), at 1, 2, 4 and 8 times the automatic resolution. The topology should not
depend on the lattice.

    python bench/fine_resolution.py [--sizes 2000 5000] [--factors 1 2 4 8]
"""
import argparse
import sys
import time
from pathlib import Path

import implicit_boundaries

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from shapes import wavy_cap  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 5000])
    parser.add_argument("--factors", type=int, nargs="+", default=[1, 2, 4, 8])
    args = parser.parse_args(argv)
    implicit_boundaries.load()
    print("| samples | resolution | loops (true: 1) | highest loop vertex (rim at z = -0.2) | time (s) |")
    print("|---|---|---|---|---|")
    for n in args.sizes:
        points, normals = wavy_cap(n)
        automatic = implicit_boundaries.reconstruct(points, normals).info["resolution"]
        for factor in args.factors:
            start = time.perf_counter()
            rec = implicit_boundaries.reconstruct(points, normals, resolution=factor * automatic)
            seconds = time.perf_counter() - start
            highest = max((rec.vertices[loop][:, 2].max() for loop in rec.loops), default=float("nan"))
            label = f"{factor * automatic}" + (" (automatic)" if factor == 1 else f" ({factor}x)")
            print(f"| {n:,} | {label} | {len(rec.loops)} | {highest:.3f} | {seconds:.1f} |", flush=True)


if __name__ == "__main__":
    main()
