"""Boundary benchmark on the meshes with known boundaries (docs/yardsticks.md: the boundary yardsticks).

For each mesh: its vertices and face normals as the input point cloud, reconstructed with our
defaults (tangent-disk SODS, automatic resolution) and variants; reports loops found against
the true boundaries, the boundary distance, the implicit evaluations against a full lattice,
and the time against MeshLab's screened Poisson in the same run. With --references, also
clean and noisy input (0.2%-diagonal Gaussian noise on the points) against MeshLab's screened
Poisson, Poisson with the 5% least dense vertices removed, and ball pivoting.

    python bench/boundaries.py [--data DIR] [--references] > results.md
"""
import argparse
import time
from pathlib import Path

import numpy as np
import pymeshlab

import implicit_boundaries
from implicit_boundaries import poisson_with_boundaries
from implicit_boundaries.methods import density_trim, poisson_depth
from implicit_boundaries.metrics import boundary_curves, boundary_distance, boundary_vertex_sets, loops_found
from implicit_boundaries.options import Implicit, SodsOccupancy

DEFAULT_DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"
CASES = ["bun_zipper.ply", "mech-holes-shark.off", "fandisk_truncated.off", "tum_rabbit.ply", "gargoyle.ply"]
METHODS = {
    "ours (defaults)": {},
    "ours, Hoppe's distance": {"implicit": Implicit.HOPPE},
    "ours, no smoothing": {"boundary_smoothing": 0},
    "ours, no trim": {"boundary_trim": 0.0},
    "ours, no trim, no smoothing": {"boundary_trim": 0.0, "boundary_smoothing": 0},
    "ours, no fit": {"boundary_fit": False},
    "ours, no fit, no smoothing": {"boundary_fit": False, "boundary_smoothing": 0},
    "ours, min_boundary_edges 0": {"min_boundary_edges": 0},
    "paper SODS (cells + 1 ring), smoothing 4": {"sods_occupancy": SodsOccupancy.SAMPLE_CELLS, "sods_dilation": 1,
                                                 "boundary_trim": 0.0},
}


def load_case(path):
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    if ms.current_mesh().face_number() > 0:
        ms.meshing_remove_unreferenced_vertices()
        ms.compute_normal_per_vertex()
    m = ms.current_mesh()
    m.compact()
    return m.vertex_matrix().copy(), m.vertex_normal_matrix().copy(), m.face_matrix().copy()


def curves(vertices, faces):
    """Boundary curves sampled every 0.05% of the bounding-box diagonal of the vertices."""
    return boundary_curves(vertices, faces, 0.0005 * np.linalg.norm(np.ptp(vertices, axis=0)))


def run(points, normals, truth, truth_curves, resolution, params):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
    t = time.perf_counter()
    out = implicit_boundaries.apply(ms, resolution=resolution, **params)
    seconds = time.perf_counter() - t
    vertices = ms.current_mesh().vertex_matrix()
    loops = [vertices[l] for l in implicit_boundaries.loops_from_result(out)]
    found, spurious = loops_found(truth, loops, 2.5 * out["sample_spacing"] + 2 * out["cell_size"])
    distance = boundary_distance(truth_curves, curves(vertices, ms.current_mesh().face_matrix()))
    return out, seconds, found, spurious, distance


def poisson_seconds(points, normals, resolution):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
    t = time.perf_counter()
    ms.generate_surface_reconstruction_screened_poisson(depth=poisson_depth(resolution))
    return time.perf_counter() - t


def reference_loops(name, points, normals, resolution):
    """Boundary loops (point arrays), boundary curves and seconds of a MeshLab reference method."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), "points")
    t = time.perf_counter()
    if name == "ball pivoting":
        ms.generate_surface_reconstruction_ball_pivoting()
    elif name == "screened Poisson + our boundaries":
        poisson_with_boundaries(ms, depth=poisson_depth(resolution), resolution=resolution)
    else:
        ms.generate_surface_reconstruction_screened_poisson(depth=poisson_depth(resolution))
    seconds = time.perf_counter() - t
    m = ms.current_mesh()
    vertices, faces = m.vertex_matrix(), m.face_matrix()
    if name == "screened Poisson + 5% density trim":
        faces = density_trim(faces, m.vertex_scalar_array(), 0.05)  # Poisson's density is the vertex quality
    return [vertices[h] for h in boundary_vertex_sets(faces, len(vertices))], curves(vertices, faces), seconds


def references(args):
    print("| mesh | input | method | loops (true) | true found | spurious (≥10 edges / all) | boundary distance (% diag) |")
    print("|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(1)
    for name in CASES:
        clean, normals, faces = load_case(args.data / name)
        truth = [clean[h] for h in boundary_vertex_sets(faces, len(clean))]
        truth_curves = curves(clean, faces)
        diagonal = np.linalg.norm(clean.max(0) - clean.min(0))
        for label, points in [("clean", clean), ("noise 0.2%", clean + rng.normal(0, 0.002 * diagonal, clean.shape))]:
            ours, _, found, spurious, distance = run(points, normals, truth, truth_curves, 0, {})
            rows = [("ours", ours["boundary_loops"], found, spurious, distance)]
            for method in ["screened Poisson", "screened Poisson + 5% density trim", "screened Poisson + our boundaries",
                           "Hoppe + our boundaries", "ball pivoting"]:
                if method == "Hoppe + our boundaries":
                    hoppe, _, found, spurious, distance = run(points, normals, truth, truth_curves, 0,
                                                              {"implicit": Implicit.HOPPE})
                    rows.append((method, hoppe["boundary_loops"], found, spurious, distance))
                    continue
                loops, found_curves, _ = reference_loops(method, points, normals, ours["resolution"])
                found, spurious = loops_found(truth, loops, 2.5 * ours["sample_spacing"] + 2 * ours["cell_size"])
                rows.append((method, len(loops), found, spurious, boundary_distance(truth_curves, found_curves)))
            for method, count, found, spurious, distance in rows:
                print(f"| {name} | {label} | {method} | {count} ({len(truth)}) | {found}/{len(truth)} "
                      f"| {sum(s >= 10 for s in spurious)} / {len(spurious)} | {100 * distance / diagonal:.3f} |")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--data", type=Path, default=DEFAULT_DATA)
    p.add_argument("--references", action="store_true", help="clean and noisy input against MeshLab's methods")
    args = p.parse_args(argv)
    implicit_boundaries.load()
    if args.references:
        return references(args)
    print("| mesh | samples | true loops | method | resolution | loops | true found | spurious (≥10 edges / all) "
          "| largest loops | boundary distance (% diag) | evaluations / full lattice | time / screened Poisson |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in CASES:
        points, normals, faces = load_case(args.data / name)
        diagonal = np.linalg.norm(points.max(0) - points.min(0))
        truth = [points[h] for h in boundary_vertex_sets(faces, len(points))]
        truth_curves = curves(points, faces)
        resolutions = [0, 100] if name == "bun_zipper.ply" else [0]
        for resolution in resolutions:
            for method, params in METHODS.items():
                out, seconds, found, spurious, distance = run(points, normals, truth, truth_curves, resolution, params)
                ratio = seconds / poisson_seconds(points, normals, out["resolution"])
                edges = out["boundary_loop_edges"].astype(int).tolist()
                print(f"| {name} | {len(points)} | {len(truth)} | {method} | {out['resolution']} | {len(edges)} "
                      f"| {found}/{len(truth)} | {sum(s >= 10 for s in spurious)} / {len(spurious)} | {edges[:6]} "
                      f"| {100 * distance / diagonal:.3f} "
                      f"| {out['implicit_evaluations'] / out['full_lattice_evaluations']:.3f} | {ratio:.2f} |")


if __name__ == "__main__":
    main()
