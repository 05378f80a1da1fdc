"""numpy in, numpy out: the filter without pymeshlab objects."""
from dataclasses import dataclass, field
from typing import Dict, List, Optional

import numpy as np
import pymeshlab

from ._plugin import apply, load
from .options import Normals


@dataclass
class Reconstruction:
    """Result of :func:`reconstruct`.

    vertices: (m, 3) float64 positions; faces: (f, 3) int32 vertex indices, oriented along the
    input normals; loops: one int array of vertex indices per boundary loop (a closed cycle, the
    first vertex not repeated), largest first; info: the filter's result dictionary
    (resolution, cell_size, implicit_evaluations, per-stage seconds, ...).
    """
    vertices: np.ndarray
    faces: np.ndarray
    loops: List[np.ndarray]
    info: Dict[str, object] = field(default_factory=dict)

    def loop_polylines(self) -> List[np.ndarray]:
        """Each boundary loop as a closed (k+1, 3) polyline (first point repeated at the end)."""
        return [self.vertices[np.append(loop, loop[0])] for loop in self.loops]


def loops_from_result(result: Dict[str, object]) -> List[np.ndarray]:
    """Splits the filter's flat ``boundary_loop_vertices`` by ``boundary_loop_edges`` into loops."""
    edges = np.asarray(result.get("boundary_loop_edges", []), dtype=np.int64)
    vertices = np.asarray(result.get("boundary_loop_vertices", []), dtype=np.int64)
    return np.split(vertices, np.cumsum(edges)[:-1]) if len(edges) else []


def reconstruct(points, normals: Optional[np.ndarray] = None, estimate_normals: bool = False,
                viewpoint: Optional[np.ndarray] = None, faces: Optional[np.ndarray] = None,
                **params) -> Reconstruction:
    """Reconstructs the surface with boundaries of the (n, 3) ``points``.

    normals: (n, 3) outward normals, or None to estimate them (as does estimate_normals=True
    when normals are given). viewpoint: (3,) the scanner's position: normals are estimated and
    turned to face it (a single range scan), instead of oriented by propagation. faces: (f, 3)
    vertex indices of the points' triangles when they are a mesh (a triangulated scan): every
    hole of the triangles stays open, unless its loop is under min_boundary_edges (set
    keep_mesh_holes=False to ignore them). params: the filter's other parameters by their pymeshlab names,
    e.g. resolution=128 (cells along the longest bounding-box side; 0, the default, chooses it
    from the sample spacing), sods_occupancy, sample_radius, sods_dilation, normal_neighbours;
    ``pymeshlab.print_filter_parameter_list(implicit_boundaries.FILTER_NAME)`` lists them.
    Raises pymeshlab.PyMeshLabException with the filter's message on bad input.
    """
    load()
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    arrays = dict(vertex_matrix=points)
    if normals is not None:
        normals = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 3)
        if normals.shape != points.shape:
            raise ValueError(f"normals have shape {normals.shape}, points {points.shape}: one normal per point")
        arrays["v_normals_matrix"] = normals
    if faces is not None:
        faces = np.ascontiguousarray(faces, dtype=np.int32).reshape(-1, 3)
        if len(faces) and (faces.min() < 0 or faces.max() >= len(points)):
            raise ValueError(f"faces refer to vertices outside 0..{len(points) - 1}")
        arrays["face_matrix"] = faces
    mesh = pymeshlab.Mesh(**arrays)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(mesh, "points")
    if viewpoint is not None:
        params.update(normals=Normals.FACING_VIEWPOINT, viewpoint=np.asarray(viewpoint, dtype=np.float64).reshape(3))
    else:
        params["normals"] = Normals.ESTIMATE if estimate_normals else Normals.USE_LAYER
    info = apply(ms, **params)
    out = ms.current_mesh()
    return Reconstruction(out.vertex_matrix(), out.face_matrix(), loops_from_result(info), dict(info))


def reconstruct_scans(scans, **params) -> Reconstruction:
    """One surface with boundaries from several range scans, as the filter's "merge visible
    layers" makes it: ``scans`` is a list of (points, normals) or (points, normals, matrix), with
    (n_i, 3) points, (n_i, 3) normals or None (estimated), and a (4, 4) matrix that takes the
    scan to the common frame (identity when left out; e.g. from
    :func:`implicit_boundaries.alignment.read_alignment`). Sample spacing is measured within
    each scan. params: as :func:`reconstruct`."""
    load()
    ms = pymeshlab.MeshSet()
    for i, scan in enumerate(scans):
        points = np.ascontiguousarray(scan[0], dtype=np.float64).reshape(-1, 3)
        normals = scan[1] if len(scan) > 1 else None
        if normals is None:
            ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points), f"scan {i}")
        else:
            normals = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 3)
            if normals.shape != points.shape:
                raise ValueError(f"scan {i}: normals have shape {normals.shape}, points {points.shape}")
            ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=normals), f"scan {i}")
        if len(scan) > 2 and scan[2] is not None:
            ms.set_matrix(transformmatrix=np.asarray(scan[2], dtype=np.float64).reshape(4, 4), freeze=False)
    if not len(ms):
        raise ValueError("no scans given")
    info = apply(ms, merge_visible_layers=True, **params)
    out = ms.current_mesh()
    return Reconstruction(out.vertex_matrix(), out.face_matrix(), loops_from_result(info), dict(info))
