"""How deep a mesh's holes are against the gaps of its own sampling: whether its vertices alone
can tell its small holes from undersampling (issue: boundaries on unseen scans, small real holes).

Per hole of the mesh (each boundary loop; a cut's rim shows as a very deep one): its depth, the radius of the
largest empty circle inside it (the farthest point of the hole's best-fit plane inside the loop
from every vertex), in median sample spacings (spacing.h's estimate). The sampling's own gaps:
per vertex away from a boundary, the largest circumradius of its triangles in the Delaunay
triangulation of it and its 14 nearest vertices seen in its tangent plane (the largest empty
circle it touches), in its local spacing; quantiles over the mesh. A hole no deeper than the
sampling's 1% largest gaps looks like undersampling to anything that sees only the points.

    python bench/hole_depths.py MESH ...
"""
import argparse
import sys

import numpy as np
from matplotlib.path import Path as PolygonPath
from scipy.spatial import Delaunay, cKDTree

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from corpus import load_case  # noqa: E402

NEIGHBOURS = 14


def spacing(points):
    """spacing.h's local spacing: sqrt(pi r_8^2 / 8)."""
    d = cKDTree(points).query(points, k=9)[0][:, 8]
    return np.sqrt(np.pi * d ** 2 / 8)


def ordered_loops(faces):
    """The mesh's boundary loops, each as its vertex indices in order."""
    edges = np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, inverse, counts = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True, return_counts=True)
    following = dict(edges[counts[inverse.ravel()] == 1])
    loops, seen = [], set()
    for start in following:
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = following[v]
        loops.append(np.array(loop))
    return loops


def hole_depth(points, tree, loop):
    """Radius of the largest empty circle inside the loop, on its best-fit plane."""
    rim = points[loop]
    centre = rim.mean(axis=0)
    axes = np.linalg.svd(rim - centre)[2][:2]
    flat = (rim - centre) @ axes.T
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    grid = np.stack(np.meshgrid(np.linspace(lo[0], hi[0], 100), np.linspace(lo[1], hi[1], 100)), -1).reshape(-1, 2)
    inside = grid[PolygonPath(flat).contains_points(grid)]
    return tree.query(centre + inside @ axes)[0].max() if len(inside) else 0.0


def sampling_gaps(points, normals, local, boundary):
    """Per vertex off the boundary: the largest circumradius of its Delaunay triangles among its
    neighbours in its tangent plane, over its local spacing."""
    neighbours = cKDTree(points).query(points, k=NEIGHBOURS + 1)[1]
    gaps = []
    for i in np.flatnonzero(~boundary):
        n = normals[i] / np.linalg.norm(normals[i])
        u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        u /= np.linalg.norm(u)
        q = points[neighbours[i]] - points[i]  # row 0: the vertex itself
        flat = np.column_stack([q @ u, q @ np.cross(n, u)])
        largest = 0.0
        for a, b, c in flat[[t for t in Delaunay(flat).simplices if 0 in t]]:
            ab, ac = b - a, c - a
            d = 2 * (ab[0] * ac[1] - ab[1] * ac[0])
            if abs(d) > 1e-300:
                x = (ac[1] * ab.dot(ab) - ab[1] * ac.dot(ac)) / d
                y = (ab[0] * ac.dot(ac) - ac[0] * ab.dot(ab)) / d
                largest = max(largest, np.hypot(x, y))
        gaps.append(largest / local[i])
    return np.array(gaps)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="+")
    args = parser.parse_args(argv)
    print("| mesh | vertices | sampling's gaps p50 / p90 / p99 / p99.9 (local spacings) | holes: edges, extent, "
          "depth (median spacings) |")
    print("|---|---|---|---|")
    for path in args.meshes:
        points, normals, faces = load_case(path)
        local = spacing(points)
        median = np.median(local)
        tree = cKDTree(points)
        loops = ordered_loops(faces)
        boundary = np.zeros(len(points), bool)
        for loop in loops:
            boundary[loop] = True
        holes = []
        for loop in sorted(loops, key=len):
            rim = points[loop]
            flat = (rim - rim.mean(axis=0)) @ np.linalg.svd(rim - rim.mean(axis=0))[2][:2].T
            extent = np.ptp(flat, axis=0) / median
            holes.append(f"{len(loop)}, {extent[0]:.1f} x {extent[1]:.1f}, **{hole_depth(points, tree, loop) / median:.2f}**")
        gaps = sampling_gaps(points, normals, local, boundary)
        quantiles = " / ".join(f"{q:.2f}" for q in np.percentile(gaps, [50, 90, 99, 99.9]))
        print(f"| {path.rsplit('/', 1)[-1]} | {len(points)} | {quantiles} | {'; '.join(holes)} |")


if __name__ == "__main__":
    main()
