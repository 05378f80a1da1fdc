"""Boundaries on meshes nobody here tuned to: the sample meshes that ship with pymeshlab, cut by
planes (issue: boundaries on unseen scans).

`../shared/data` is where the boundary rules were developed; this is the held-out check of the
same kinds of difficulty on other shapes. Each closed sample mesh is cut twice, by planes of
seeded random directions that take off the quarter of its vertices lowest along them (the faces
with a vertex past the plane removed, so each cut edge is jagged as a real cut's is); the cut
mesh is the truth and its vertices, with the normals the whole mesh gave them, the input, as in
`bench/corpus.py` (the same conditions, measures and summaries). pymeshlab's own scan with
holes, `bunny10k_textured.obj` (the demo's), and its raw range map of a face,
`rangemaps/face000.ply`, run as they ship (the range map's true loops include the outlines of
its 21 islands of scanner debris and its dropouts of a few grid points, which the filter leaves
out as outliers and fills as undersampling: its loop count is not a yardstick, its distances
and areas are). Its point cloud of a closed chameleon, `chameleon.pts`, runs as points with the
file's normals (truth: no loop; no truth surface, so only loops, outliers and time are measured).

    python bench/held_out.py [--conditions clean ...] [--params k=v ...] [--seed N]
"""
import argparse
from pathlib import Path

import numpy as np
import pymeshlab

import implicit_boundaries
from corpus import CONDITIONS, load_case, measure, parse_params, summary

SAMPLES = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes"
# Every mesh, with the kinds of difficulty it stands for, and whether it is cut.
CASES = {
    "airplane.obj": ("CAD, thin parts, uneven sampling, cut", True),
    "bone.ply": ("scan, cut", True),
    "bunny.obj": ("scan, cut", True),
    "cow.obj": ("thin parts, uneven sampling, cut", True),
    "bunny10k_textured.obj": ("scan, small holes", False),
    "rangemaps/face000.ply": ("range scan", False),
    "chameleon.pts": ("closed, thin parts", False),
}
CUTS = 2
CUT_FRACTION = 0.25  # of the vertices, lowest along the plane's normal


def cut(points, normals, faces, direction):
    """The mesh without its faces that reach below the CUT_FRACTION quantile along `direction`,
    its unused vertices dropped: (points, normals, faces)."""
    height = points @ direction
    keep = (height[faces] > np.quantile(height, CUT_FRACTION)).all(axis=1)
    kept = faces[keep]
    used = np.unique(kept)
    index = np.full(len(points), -1)
    index[used] = np.arange(len(used))
    return points[used], normals[used], index[kept]


def cases(seed):
    """(name, kind, points, normals, faces) for every case."""
    rng = np.random.default_rng(seed)
    for name, (kind, is_cut) in CASES.items():
        points, normals, faces = load_case(SAMPLES / name)
        if not is_cut:
            yield name, kind, points, normals, faces
            continue
        for i in range(CUTS):
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            yield f"{name} cut {i + 1}", kind, *cut(points, normals, faces, direction)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--conditions", nargs="+", default=["clean", "noise 0.2%", "no normals", "outliers 0.1%"],
                   choices=CONDITIONS)
    p.add_argument("--params", nargs="*", help="filter parameters, name=value")
    p.add_argument("--seed", type=int, default=0, help="other cutting planes, noise and outliers")
    args = p.parse_args(argv)
    params = parse_params(args.params)
    implicit_boundaries.load()
    print("| mesh | kind | condition | samples | loops / true | largest loops | resolution | boundary distance (% diag) "
          "| spurious area (%) | missing area (%) | farthest face (local spacings) | outliers left out "
          "| time / screened Poisson | time / clean |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows, kinds = [], {}
    for name, kind, points, normals, faces in cases(args.seed):
        kinds[name] = kind
        for condition in args.conditions:
            rng = np.random.default_rng(len(points) + args.seed)
            row = measure(name, condition, points, normals, faces, rng, params,
                          condition != "clean" and "clean" in args.conditions)
            rows.append(row)
            mark = "" if row["loops"] == row["true"] else " ✗"
            print(f"| {name} | {kind} | {condition} | {row['samples']} | {row['loops']} / {row['true']}{mark} "
                  f"| {sorted(row['edges'], reverse=True)[:5]} | {row['resolution']} | {row['boundary']:.3f} "
                  f"| {row['spurious']:.3f} | {row['missing']:.3f} | {row['farthest']:.2f} | {row['outliers']} "
                  f"| {row['time_ratio']:.2f} | {row['over_clean']:.2f} |", flush=True)
    summary(rows, lambda r: [r["condition"]], "condition")
    summary(rows, lambda r: [k.strip() for k in kinds[r["mesh"]].split(",")], "kind")


if __name__ == "__main__":
    main()
