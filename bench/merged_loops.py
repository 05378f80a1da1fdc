"""Each boundary loop of the merged range scans, against the scans and the truth (issue: the
MeshLab scanning workflow): is a loop the truth lacks a gap the scans left, and how does it
differ from the real holes?

    python bench/merged_loops.py [ALIGNMENT] [--truth MESH]

Defaults as bench/merged.py (the 9 Stanford bunny scans through bun.conf, bun_zipper as the
truth). Per loop of our surface: its edges; whether the truth has a loop there (as bench/merged.py matches
them: on average within 2.5 sample spacings and 2 cells of one of the truth's loops); its hole region's depth (the farthest
of its hole faces' centres from a sample), absolute and in the median spacing of the samples
along the loop; how many samples of each scan lie along it; per scan, the share of its hole
faces the scan faced (|cos| over 0.3 between the face and the scan's view, the mean of its
normals) with nothing of its own in front (it looked there and saw no surface); and the truth's
triangles over the hole's middle: their longest edge against the truth's median longest edge.
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

import implicit_boundaries
from implicit_boundaries import metrics
from implicit_boundaries.cloud import mesh_arrays, read_mesh

sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus import DEFAULT_DATA  # noqa: E402
from merged import scan_layers  # noqa: E402


def world_scans(ms):
    """Per layer: its samples and unit normals in the common frame (zero normals stay zero)."""
    scans = []
    for i in range(ms.mesh_number()):
        m = ms.mesh(i)
        matrix = m.transform_matrix()
        normals = m.vertex_normal_matrix() @ matrix[:3, :3].T
        length = np.linalg.norm(normals, axis=1)
        normals[length > 0] /= length[length > 0, None]
        scans.append((m.vertex_matrix() @ matrix[:3, :3].T + matrix[:3, 3], normals))
    return scans


def hole_regions(vertices, faces):
    """Per face of the hole layer, its connected region."""
    e = np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(len(vertices),) * 2)
    return connected_components(graph, directed=False)[1][faces[:, 0]]


class ScanView:
    """One scan seen along its view (the mean of its normals: a range scanner's normals face
    it): its samples projected across the view, and their depth along it."""

    def __init__(self, points, normals, spacing):
        view = normals[np.linalg.norm(normals, axis=1) > 0].mean(0)
        self.view = view / np.linalg.norm(view)
        u = np.cross(self.view, [1, 0, 0] if abs(self.view[0]) < 0.9 else [0, 1, 0])
        self.u = u / np.linalg.norm(u)
        self.w = np.cross(self.view, self.u)
        self.across = cKDTree(np.c_[points @ self.u, points @ self.w])
        self.depth = points @ self.view
        self.spacing = spacing

    def seen_empty(self, centres, face_normals):
        """Per hole face, whether the scan faced it (|cos| over 0.3) with none of its samples in
        front of it."""
        rays = self.across.query_ball_point(np.c_[centres @ self.u, centres @ self.w], 1.5 * self.spacing)
        front = np.array([len(r) > 0 and self.depth[r].max() > d + 3 * self.spacing
                          for r, d in zip(rays, centres @ self.view)])
        return (np.abs(face_normals @ self.view) > 0.3) & ~front


def main(argv=None):
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("alignment", nargs="?", default=str(DEFAULT_DATA / "bunny_scans" / "bun.conf"))
    a.add_argument("--truth", default=str(DEFAULT_DATA / "bun_zipper.ply"))
    args = a.parse_args(argv)
    implicit_boundaries.load()
    ms = scan_layers(Path(args.alignment))
    scans = world_scans(ms)
    info = implicit_boundaries.apply(ms, merge_visible_layers=True, hole_layer=True)
    vertices, faces = mesh_arrays(ms.mesh(len(scans)))
    hole_vertices, hole_faces = mesh_arrays(ms.mesh(len(scans) + 1))
    truth_vertices, truth_faces = read_mesh(args.truth)

    samples = np.vstack([p for p, _ in scans])
    scan_of = np.concatenate([np.full(len(p), i) for i, (p, _) in enumerate(scans)])
    index = cKDTree(samples)
    per_scan = [cKDTree(p).query(p, 2)[0][:, 1] for p, _ in scans]  # each sample's spacing within its scan
    own_spacing = [np.median(d) for d in per_scan]
    spacing = np.concatenate(per_scan)
    views = [ScanView(p, n, h) for (p, n), h in zip(scans, own_spacing)]
    region = hole_regions(hole_vertices, hole_faces)
    centres = hole_vertices[hole_faces].mean(1)
    face_normals = np.cross(hole_vertices[hole_faces[:, 1]] - hole_vertices[hole_faces[:, 0]],
                            hole_vertices[hole_faces[:, 2]] - hole_vertices[hole_faces[:, 0]])
    face_normals /= np.maximum(np.linalg.norm(face_normals, axis=1), 1e-300)[:, None]
    tolerance = 2.5 * info["sample_spacing"] + 2 * info["cell_size"]
    true_loops = [cKDTree(truth_vertices[s]) for s in metrics.boundary_vertex_sets(truth_faces, len(truth_vertices))]
    truth_centres = cKDTree(truth_vertices[truth_faces].mean(1))
    truth_edge = np.linalg.norm(truth_vertices[truth_faces] - truth_vertices[np.roll(truth_faces, 1, axis=1)], axis=2).max(1)

    print(f"truth: {len(true_loops)} loops; its triangles' longest edge: median {np.median(truth_edge):.5f}, "
          f"99th percentile {np.percentile(truth_edge, 99):.5f}")
    print("| loop edges | truth has it | depth | depth (rim spacings) | rim samples per scan | scans that looked and saw none "
          "| truth's longest edge over the middle (x median) |")
    print("|---|---|---|---|---|---|---|")
    for loop in metrics.boundary_vertex_sets(faces, len(vertices)):
        points = vertices[loop]
        has = any(t.query(points)[0].mean() < tolerance for t in true_loops)
        near = cKDTree(points).query(centres)[0] < 2 * np.mean(own_spacing)
        mine = np.isin(region, np.unique(region[near]))
        rim = np.unique(np.concatenate([np.asarray(r, int) for r in index.query_ball_point(points, 2 * np.mean(own_spacing))]))
        depth, _ = index.query(centres[mine])
        looked = [f"{i}: {s:.0%}" for i, v in enumerate(views)
                  if (s := v.seen_empty(centres[mine], face_normals[mine]).mean()) >= 0.2]
        middle = centres[mine][depth > 0.5 * depth.max()]
        gap, over = truth_centres.query(middle)
        over = np.unique(over[gap < 2 * np.mean(own_spacing)])
        longest = f"{truth_edge[over].max() / np.median(truth_edge):.1f}" if len(over) else "- (open)"
        counts = np.bincount(scan_of[rim], minlength=len(scans))
        print(f"| {len(loop)} | {'yes' if has else 'no'} | {depth.max():.5f} | {depth.max() / np.median(spacing[rim]):.2f} "
              f"| {', '.join(f'{i}: {c}' for i, c in enumerate(counts) if c)} | {', '.join(looked) or '-'} | {longest} |")


if __name__ == "__main__":
    main()
