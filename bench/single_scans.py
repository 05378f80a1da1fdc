"""Single raw range scans, each alone: where the loops the filter keeps lie (issue: boundaries on
unseen scans).

One range scan sees an object from one side: its surface ends at the scan's outline, and where a
nearer part hides a farther one (a leg in front of the body, the tail over the back) the range
grid steps in depth. A scanner's triangulation joins the grid across such a step with long, thin
triangles that no sample supports, so the scan's own boundary loops (its outline and dropouts)
are not the whole truth: the surface behind a step was not seen. Each loop the filter keeps is
sorted by where most of its points are: on the scan's own boundary, along long triangles (within
ON_EDGE spacings of input triangles whose longest edge is over STEP times the scan's median:
depth steps and grazing angles, where the scanner saw the surface barely or not at all), or
elsewhere (over the scan's ordinary triangles: a hole the scan does not have).

    python bench/single_scans.py [--scans DIR] [--names bun045 ...] [--params k=v ...]

Inputs per scan: the scan as a mesh (its triangles given, as MeshLab opens it), its vertices
with the normals MeshLab computes from the triangles, and its vertices alone (normals estimated).
"""
import argparse
import time
from pathlib import Path

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree

import implicit_boundaries
from corpus import DEFAULT_DATA, load_case, parse_params
from implicit_boundaries.metrics import boundary_curves, boundary_vertex_sets, point_mesh_distance

STEP = 3.0          # a triangle this many times longer than the median is long
ON_EDGE = 2.0       # a loop point within this many sample spacings of the scan's boundary is on it
WHERE = ("edge", "long", "elsewhere")


def triangle_lengths(points, faces):
    """Longest edge of each of the (f, 3) faces."""
    corners = points[faces]
    return np.linalg.norm(corners - corners[:, [1, 2, 0]], axis=2).max(axis=1)


def loop_places(points, faces, vertices, loops):
    """For each loop (an index array into vertices), the fraction of its points on the scan's
    boundary, along long triangles and elsewhere."""
    spacing = np.median(cKDTree(points).query(points, k=2)[0][:, 1])
    edge = cKDTree(np.concatenate(boundary_curves(points, faces, spacing / 4)))
    longest = triangle_lengths(points, faces)
    long = longest > STEP * np.median(longest)
    places = []
    for loop in loops:
        q = vertices[loop]
        on_edge = edge.query(q)[0] < ON_EDGE * spacing
        along = (point_mesh_distance(q, points, faces[long]) < ON_EDGE * spacing) & ~on_edge
        places.append((on_edge.mean(), along.mean(), 1 - on_edge.mean() - along.mean()))
    return places


def run(name, points, normals, faces, params):
    """Rows for the three inputs of one scan."""
    true_loops = boundary_vertex_sets(faces, len(points))
    rows = []
    for label, kwargs in (("mesh", dict(normals=normals, faces=faces)), ("points, normals", dict(normals=normals)),
                          ("points", dict())):
        t = time.perf_counter()
        r = implicit_boundaries.reconstruct(points, **kwargs, **params)
        seconds = time.perf_counter() - t
        places = loop_places(points, faces, r.vertices, r.loops)
        # A loop is where most of its points are.
        kinds = [WHERE[int(np.argmax(p))] for p in places]
        elsewhere = [len(loop) for loop, kind in zip(r.loops, kinds) if kind == "elsewhere"]
        rows.append(dict(scan=name, input=label, samples=len(points), true=len(true_loops),
                         true_20=sum(len(t) >= 20 for t in true_loops), loops=len(r.loops),
                         **{k: kinds.count(k) for k in WHERE}, elsewhere_edges=sorted(elsewhere, reverse=True)[:4],
                         outliers=int(r.info.get("outliers_removed", 0)), seconds=seconds))
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scans", type=Path, default=DEFAULT_DATA / "bunny_scans", help="folder of .ply range scans")
    p.add_argument("--names", nargs="*", help="scan file names without .ply (default: every one)")
    p.add_argument("--params", nargs="*", help="filter parameters, name=value")
    args = p.parse_args(argv)
    params = parse_params(args.params)
    implicit_boundaries.load()
    names = args.names or sorted(f.stem for f in args.scans.glob("*.ply"))
    print("| scan | input | samples | scan's loops (of 20+ edges) | loops kept | on the scan's edge | along long triangles "
          "| elsewhere (their edges) | outliers left out | seconds |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    totals = {k: 0 for k in ("loops",) + WHERE}
    for name in names:
        points, normals, faces = load_case(args.scans / f"{name}.ply")
        for row in run(name, points, normals, faces, params):
            for k in totals:
                totals[k] += row[k]
            print(f"| {row['scan']} | {row['input']} | {row['samples']} | {row['true']} ({row['true_20']}) | {row['loops']} "
                  f"| {row['edge']} | {row['long']} | {row['elsewhere']} {row['elsewhere_edges'] or ''} "
                  f"| {row['outliers']} | {row['seconds']:.1f} |", flush=True)
    print(f"\nAll: {totals['loops']} loops, {totals['edge']} on a scan's edge, {totals['long']} along long triangles, "
          f"{totals['elsewhere']} elsewhere.")


if __name__ == "__main__":
    main()
