"""Screened Poisson with the scan's real boundaries: MeshLab's screened Poisson surface as the
implicit function of our filter (its signed distance), gated by the points' occupancy."""
from typing import Optional, Union

import numpy as np
import pymeshlab

from ._plugin import apply, load
from .options import Implicit
from .reconstruct import Reconstruction, loops_from_result


def poisson_with_boundaries(source: Union[pymeshlab.MeshSet, np.ndarray], normals: Optional[np.ndarray] = None, *,
                            depth: int = 8, poisson_threads: int = 1, **params) -> Reconstruction:
    """Runs MeshLab's screened Poisson on a point cloud, then our filter on the Poisson surface:
    the same surface, kept only where the scan has samples, with its boundary loops.

    source: a pymeshlab.MeshSet whose current layer is the point cloud (with normals); the
    Poisson layer and our result are added to it (the result is the current layer). Or an
    (n, 3) array of points with their (n, 3) outward ``normals``. Either way the result comes
    back as a :class:`Reconstruction` (``.info``: the filter's result dictionary). depth: Poisson's octree
    depth (MeshLab's default 8); our lattice resolution is independent (``resolution=0``, the
    default, chooses it from the sample spacing). params: our filter's other parameters.
    Raises pymeshlab.PyMeshLabException with the filter's message on bad input.
    """
    load()
    if isinstance(source, pymeshlab.MeshSet):
        ms = source
    else:
        points = np.ascontiguousarray(source, dtype=np.float64).reshape(-1, 3)
        if normals is None or np.shape(normals) != points.shape:
            raise ValueError("poisson_with_boundaries needs one outward normal per point (screened Poisson does)")
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points,
                                   v_normals_matrix=np.ascontiguousarray(normals, dtype=np.float64)), "points")
    points_id = ms.current_mesh_id()
    ms.generate_surface_reconstruction_screened_poisson(depth=depth, threads=poisson_threads)
    poisson_id = ms.current_mesh_id()
    ms.set_current_mesh(points_id)
    info = apply(ms, implicit=Implicit.MESH_LAYER, implicit_mesh=poisson_id, **params)
    out = ms.current_mesh()
    return Reconstruction(out.vertex_matrix(), out.face_matrix(), loops_from_result(info), dict(info))
