"""Merged scans against the registration error: four overlapping scans of an open cap
(tests/shapes.py `overlapping_caps`), each shifted by the given fraction of a scan's spacing,
over several seeds; the surface must be one sheet with the cap's one loop (issue: the MeshLab
scanning workflow; the test with shift 0.8 is tests/test_layers.py).

    python bench/registration.py [--shifts S ...] [--seeds N] [--params k=v ...]
"""
import argparse
import sys
from pathlib import Path

import numpy as np

import implicit_boundaries

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import shapes  # noqa: E402
from corpus import parse_params  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shifts", nargs="+", type=float, default=[0.5, 0.8, 1.0, 1.2],
                        help="registration error, in a scan's sample spacings")
    parser.add_argument("--seeds", type=int, default=12, help="draws per shift (seeds 3, 4, ...)")
    parser.add_argument("--params", nargs="*", default=[], help="filter parameters, name=value")
    args = parser.parse_args(argv)
    params = parse_params(args.params)
    implicit_boundaries.load()
    print("| shift (spacings) | one loop | loops per draw | farthest vertex from the sphere, 99% (spacings) |")
    print("|---|---|---|---|")
    for shift in args.shifts:
        loops, farthest = [], []
        for seed in range(3, 3 + args.seeds):
            ms, spacing = shapes.overlapping_caps(seed, shift)
            out = implicit_boundaries.apply(ms, merge_visible_layers=True, **params)
            loops.append(int(out["boundary_loops"]))
            radius = np.linalg.norm(ms.current_mesh().vertex_matrix(), axis=1)
            farthest.append(np.quantile(np.abs(radius - 1), 0.99) / spacing)
        print(f"| {shift:g} | {sum(n == 1 for n in loops)}/{len(loops)} | {loops} | {max(farthest):.2f} |",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
