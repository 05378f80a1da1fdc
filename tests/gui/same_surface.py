"""The surface a MeshLab GUI made from pymeshlab's bunny scan (apply_filter_in_meshlab.sh's
exported result.ply) against the one pymeshlab makes with the double plugin from the same
samples (rounded to float32, as apply_filter_in_meshlab.sh writes the scan file the GUI opens):
the same boundary loops, and every vertex of each within 1e-4 of the bounding-box diagonal of
the other. Run after the GUI test of the float MeshLab (and of the double one): the float
plugin must give what the double one gives.

    python tests/gui/same_surface.py out/gui/result.ply
"""
import sys

import numpy as np
import pymeshlab

import implicit_boundaries
from implicit_boundaries.cli import DEMO_SCAN
from implicit_boundaries.metrics import boundary_vertex_sets, point_mesh_distance


def main(argv=None) -> int:
    (path,) = argv if argv is not None else sys.argv[1:]
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(DEMO_SCAN))
    scan = ms.current_mesh()
    points = scan.vertex_matrix().astype(np.float32).astype(np.float64)
    normals = scan.vertex_normal_matrix().astype(np.float32).astype(np.float64)
    ours = implicit_boundaries.reconstruct(points, normals)
    ms.load_new_mesh(path)
    gui = ms.current_mesh()
    gui_vertices, gui_faces = gui.vertex_matrix(), gui.face_matrix()
    gui_loops = sorted(len(loop) for loop in boundary_vertex_sets(gui_faces, len(gui_vertices)))
    pymeshlab_loops = sorted(len(loop) for loop in ours.loops)
    diagonal = np.linalg.norm(np.ptp(points, axis=0))
    apart = max(point_mesh_distance(gui_vertices, ours.vertices, ours.faces).max(),
                point_mesh_distance(ours.vertices, gui_vertices, gui_faces).max()) / diagonal
    print(f"{path}: loops {gui_loops} (edges), pymeshlab with the double plugin {pymeshlab_loops}; "
          f"farthest vertex from the other surface {apart:.2e} of the diagonal")
    if gui_loops != pymeshlab_loops or apart > 1e-4:
        print("FAIL: the GUI's surface differs from pymeshlab's")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
