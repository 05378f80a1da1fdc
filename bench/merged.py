"""Several aligned range scans in, one surface out: ours with "merge visible layers" against
MeshLab's screened Poisson with its "merge all visible layers", on the same layers (each scan a
layer with its alignment matrix, as MeshLab's Align tool leaves them), measured against a
ground truth (issue: the MeshLab scanning workflow).

    python bench/merged.py [ALIGNMENT] [--truth MESH] [--params k=v ...]
    python bench/merged.py [ALIGNMENT] --surface MESH   # only measure a surface made elsewhere
                                                         # (bench/merged_gui.sh: in the MeshLab GUI)

Defaults: the 9 Stanford bunny range scans placed by their bun.conf, and the zippered bunny
(bun_zipper.ply) as the truth, from ../shared/data. Columns: boundary loops (the truth's: 5,
all at the unscanned base), the farthest vertex from the truth (one sheet: under 1% of the
diagonal), chamfer, spurious and missing area (1% tolerance), boundary distance, seconds.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pymeshlab

import implicit_boundaries
from implicit_boundaries import metrics
from implicit_boundaries.alignment import read_alignment
from implicit_boundaries.cloud import Cloud, add_layer, mesh_arrays, read_cloud
from implicit_boundaries.methods import Surface, density_trim, poisson_depth
from implicit_boundaries.table import format_value

sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus import DEFAULT_DATA, parse_params  # noqa: E402


def scan_layers(alignment: Path) -> pymeshlab.MeshSet:
    """One layer per scan, with its matrix; missing normals left for the filter to estimate."""
    ms = pymeshlab.MeshSet()
    for path, matrix in read_alignment(alignment):
        add_layer(ms, read_cloud(path, estimate_normals=False), path.stem, matrix)
    return ms


def world_cloud(ms: pymeshlab.MeshSet) -> Cloud:
    """Every layer's vertices and normals through its matrix."""
    points, normals = [], []
    for i in range(ms.mesh_number()):
        m = ms.mesh(i)
        matrix = m.transform_matrix()
        points.append(m.vertex_matrix() @ matrix[:3, :3].T + matrix[:3, 3])
        normals.append(m.vertex_normal_matrix() @ matrix[:3, :3].T)
    return Cloud(np.vstack(points), np.vstack(normals))


def run_ours(alignment: Path, params: dict):
    ms = scan_layers(alignment)
    start = time.perf_counter()
    info = implicit_boundaries.apply(ms, merge_visible_layers=True, **params)
    seconds = time.perf_counter() - start
    return Surface(*mesh_arrays(ms.current_mesh()), info=dict(info)), seconds


def run_poisson(alignment: Path, depth: int, trim: float):
    ms = scan_layers(alignment)
    start = time.perf_counter()
    # Its pre-clean drops the zero normals (the unused grid points of a range scan) it refuses otherwise.
    ms.generate_surface_reconstruction_screened_poisson(visiblelayer=True, depth=depth, preclean=True, threads=1)
    seconds = time.perf_counter() - start
    mesh = ms.current_mesh()
    density = mesh.vertex_scalar_array().copy()
    vertices, faces = mesh.vertex_matrix().copy(), mesh.face_matrix().copy()
    if trim:
        faces = density_trim(faces, density, trim)
    return Surface(vertices, faces), seconds


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("alignment", nargs="?", default=str(DEFAULT_DATA / "bunny_scans" / "bun.conf"))
    parser.add_argument("--truth", default=str(DEFAULT_DATA / "bun_zipper.ply"))
    parser.add_argument("--params", nargs="*", default=[], help="our filter's parameters, name=value")
    parser.add_argument("--surface", help="measure this mesh (made from the same scans elsewhere) instead of running")
    args = parser.parse_args(argv)
    implicit_boundaries.load()
    alignment = Path(args.alignment)
    truth_ms = pymeshlab.MeshSet()
    truth_ms.load_new_mesh(args.truth)
    truth = mesh_arrays(truth_ms.current_mesh())
    truth_loops = [truth[0][h] for h in metrics.boundary_vertex_sets(truth[1], len(truth[0]))]
    cloud = world_cloud(scan_layers(alignment))

    ours, seconds = run_ours(alignment, parse_params(args.params))
    depth = poisson_depth(int(ours.info["resolution"]))
    if args.surface:
        given = pymeshlab.MeshSet()
        given.load_new_mesh(args.surface)
        runs = [(f"{Path(args.surface).name} (made elsewhere; time: ours here)", Surface(*mesh_arrays(given.current_mesh())), seconds)]
    else:
        runs = [("ours (merge visible layers)", ours, seconds),
                (f"screened Poisson, depth {depth} (merge visible layers)", *run_poisson(alignment, depth, 0)),
                ("screened Poisson + density trim 5%", *run_poisson(alignment, depth, 0.05))]
    tolerance = 2.5 * ours.info["sample_spacing"] + 2 * ours.info["cell_size"]
    diagonal = float(np.linalg.norm(np.ptp(truth[0], axis=0)))
    print(f"{alignment.name}: {len(cloud.points)} samples in {len(read_alignment(alignment))} scans; truth {Path(args.truth).name}: "
          f"{len(truth_loops)} loops; our resolution {ours.info['resolution']}, Poisson depth {depth}")
    header = ["method", "seconds", "loops", "true loops found", "farthest from truth (% diag)", "chamfer (% diag)",
              "spurious area %", "missing area %", "boundary distance (% diag)"]
    print("| " + " | ".join(header) + " |\n|" + "---|" * len(header))
    for name, surface, seconds in runs:
        row = metrics.measure(surface.vertices, surface.faces, cloud, truth, truth_loops, tolerance)
        farthest = metrics.point_mesh_distance(surface.vertices, *truth).max() / diagonal
        cells = [name, seconds, row["loops"], row["loops_found"], 100 * farthest, row["chamfer_pct"],
                 row["spurious_pct"], row["missing_pct"], row["boundary_distance_pct"]]
        print("| " + " | ".join(format_value(c) for c in cells) + " |")


if __name__ == "__main__":
    main()
