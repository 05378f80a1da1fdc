"""The input point cloud: reading it from a file (the one loader of the command line, the
comparison, the tests and the benchmarks; what pymeshlab reads, and LAS/LAZ through laspy),
and handing it to pymeshlab as a layer."""
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Tuple, Union

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree

from .options import NORMAL_NEIGHBOURS


@dataclass
class Cloud:
    """The input: (n, 3) points and (n, 3) unit normals (oriented outwards), and the (f, 3)
    vertex indices of its triangles when it is a mesh (None: a point cloud). The filter keeps
    the holes of the triangles open ("Keep the mesh's holes")."""
    points: np.ndarray
    normals: np.ndarray
    faces: Optional[np.ndarray] = None

    @property
    def diagonal(self) -> float:
        """Length of the points' bounding-box diagonal."""
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0)))

    @property
    def spacing(self) -> float:
        """Median distance from a sample to its nearest other sample."""
        return float(np.median(cKDTree(self.points).query(self.points, k=2)[0][:, 1]))


def mesh_arrays(mesh: pymeshlab.Mesh) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices (m, 3), faces (f, 3)) of a pymeshlab mesh, compacted first (deleted elements
    would otherwise keep their rows), copied out of pymeshlab's memory."""
    mesh.compact()
    return mesh.vertex_matrix().copy(), mesh.face_matrix().copy()


#: Extra dimensions of a LAS/LAZ file read as normals (names compared in lower case).
LAS_NORMALS = (("nx", "ny", "nz"), ("normalx", "normaly", "normalz"), ("normal_x", "normal_y", "normal_z"))


def read_las(path: Union[str, Path]) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """(points (n, 3), normals (n, 3) or None) of a LAS or LAZ file (LiDAR) through laspy: the
    scaled x, y, z, and the normals when the file carries them as extra dimensions (nx, ny, nz
    or normal_x, ...). The coordinates are taken as they are (no reprojection)."""
    import laspy
    las = laspy.read(str(path))
    points = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)]).astype(np.float64)
    names = {name.lower(): name for name in las.point_format.extra_dimension_names}
    for triple in LAS_NORMALS:
        if all(n in names for n in triple):
            return points, np.column_stack([np.asarray(las[names[n]], dtype=np.float64) for n in triple])
    return points, None


def _load(path: Path) -> pymeshlab.MeshSet:
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    ms = pymeshlab.MeshSet()
    if path.suffix.lower() in (".las", ".laz"):
        points, normals = read_las(path)
        arrays = dict(vertex_matrix=points)
        if normals is not None:
            arrays["v_normals_matrix"] = normals
        ms.add_mesh(pymeshlab.Mesh(**arrays), path.stem)
    else:
        ms.load_new_mesh(str(path))
    return ms


def read_cloud(path: Union[str, Path], estimate_normals: bool = True) -> Cloud:
    """The (n, 3) vertices and (n, 3) normals of any file pymeshlab reads, and its faces when it
    has some (a mesh file's normals are those MeshLab computes from its faces on loading).

    When the file has no normals: estimate_normals=True estimates them with MeshLab's point
    cloud normals over the filter's number of neighbours (what screened Poisson needs);
    False leaves them zero, which our filter takes as missing and estimates itself.
    """
    path = Path(path)
    ms = _load(path)
    mesh = ms.current_mesh()
    mesh.compact()
    if mesh.vertex_number() == 0:
        raise ValueError(f"{path}: no vertices")
    if estimate_normals and not np.any(mesh.vertex_normal_matrix()):
        ms.compute_normal_for_point_clouds(k=NORMAL_NEIGHBOURS)
        mesh = ms.current_mesh()
    faces = mesh.face_matrix().copy() if mesh.face_number() else None
    return Cloud(mesh.vertex_matrix().copy(), mesh.vertex_normal_matrix().copy(), faces)


def read_mesh(path: Union[str, Path]) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices (m, 3), faces (f, 3)) of a triangle mesh file pymeshlab reads (a ground truth)."""
    path = Path(path)
    ms = _load(path)  # held: the mesh lives inside the MeshSet
    vertices, faces = mesh_arrays(ms.current_mesh())
    if len(faces) == 0:
        raise ValueError(f"{path}: the ground truth has no faces")
    return vertices, faces


def add_layer(ms: pymeshlab.MeshSet, cloud: Cloud, name: str = "points", matrix: Optional[np.ndarray] = None) -> None:
    """Adds the cloud (and its faces, when it has some) to `ms` as a new current layer called
    `name`, with `matrix` (4, 4), the transformation taking a scan to the common frame of
    several, as its layer matrix."""
    if cloud.faces is None:
        mesh = pymeshlab.Mesh(vertex_matrix=cloud.points, v_normals_matrix=cloud.normals)
    else:
        mesh = pymeshlab.Mesh(vertex_matrix=cloud.points, face_matrix=cloud.faces, v_normals_matrix=cloud.normals)
    ms.add_mesh(mesh, name)
    if matrix is not None:
        ms.set_matrix(transformmatrix=np.asarray(matrix, dtype=np.float64), freeze=False)
