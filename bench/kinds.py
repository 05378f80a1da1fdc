"""Boundaries on generated scans, one per kind of difficulty that broke boundary decisions on
meshes nobody here had tuned to (issue: boundaries on unseen scans): thin parts, sharp concave
creases, uneven sampling, noise on a flat open scan. The truth is known by construction
(tests/shapes.py). Each case runs with its exact normals and with estimated ones.

    python bench/kinds.py [--cases NAME ...] [--params k=v ...]
"""
import argparse
import sys
from pathlib import Path

import implicit_boundaries

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import shapes  # noqa: E402
from corpus import parse_params  # noqa: E402

# name: (kind, generator, true loop count)
CASES = {
    "thin plate, 1.5 spacings thick": ("thin parts", lambda: shapes.thin_plate(1.5), 0),
    "thin plate, 3 spacings thick": ("thin parts", lambda: shapes.thin_plate(3), 0),
    "V-groove, 30 degrees": ("creases", lambda: shapes.v_groove(30), 1),
    "V-groove, 60 degrees": ("creases", lambda: shapes.v_groove(60), 1),
    "hemisphere, 10x sparser half, abrupt": ("uneven sampling", lambda: shapes.uneven_hemisphere(10), 1),
    "hemisphere, 10x sparser half, smooth": ("uneven sampling",
                                             lambda: shapes.uneven_hemisphere(10, smooth=True), 1),
    "terrain with a pond, noise 0.2%": ("noisy flat scan", lambda: shapes.terrain_with_pond(), 2),
    "terrain with a pond, clean": ("flat scan", lambda: shapes.terrain_with_pond(noise=0), 2),
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--params", nargs="*", default=[], help="filter parameters, name=value")
    args = parser.parse_args(argv)
    params = parse_params(args.params)
    implicit_boundaries.load()
    print("| case | kind | normals | samples | loops / true | largest loops | resolution |")
    print("|---|---|---|---|---|---|---|")
    exact = {}
    for name in args.cases:
        kind, make, true = CASES[name]
        points, normals = make()
        for source in ("exact", "estimated"):
            rec = implicit_boundaries.reconstruct(points, normals if source == "exact" else None, **params)
            loops = len(rec.loops)
            largest = sorted((len(loop) for loop in rec.loops), reverse=True)[:5]
            exact.setdefault(kind, []).append(loops == true)
            print(f"| {name} | {kind} | {source} | {len(points)} | {loops} / {true}{'' if loops == true else ' ✗'} "
                  f"| {largest} | {rec.info['resolution']} |", flush=True)
    print("\n| kind | runs | exact loop count |\n|---|---|---|")
    for kind, hits in exact.items():
        print(f"| {kind} | {len(hits)} | {sum(hits)}/{len(hits)} |")


if __name__ == "__main__":
    main()
