"""The reconstruction methods a comparison runs: our filter and MeshLab's screened Poisson
(closed, density-trimmed, and as the implicit function of our filter).

Each method is a function ``(cloud, settings) -> Surface`` in :data:`METHODS`; adding a
method there adds a row, a picture and a bar to every comparison.
"""
from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, Optional, Tuple

import numpy as np
import pymeshlab

from ._plugin import apply, load
from .cloud import Cloud, add_layer, mesh_arrays
from .poisson import poisson_with_boundaries

# Screened Poisson's own default depth, used when no resolution says otherwise.
DEFAULT_DEPTH = 8


@dataclass
class Settings:
    """What every method is run with.

    resolution: our marching cubes cells along the longest side (0: the filter chooses, and
    the comparison then uses the resolution it chose); depth: screened Poisson's octree depth
    (None: the one whose 2^depth is nearest our resolution, 8 without one); trim_quantile: Poisson vertices
    whose density is below this quantile are removed; poisson_threads: screened Poisson's
    threads; params: our filter's other parameters by their pymeshlab names.
    """
    resolution: int = 0
    depth: Optional[int] = None
    trim_quantile: float = 0.05
    poisson_threads: int = 1
    params: Dict[str, object] = field(default_factory=dict)

    def as_dict(self) -> Dict[str, object]:
        """The settings as a flat dict (the filter's parameters prefixed), for the report."""
        flat = asdict(self)
        flat.update({f"filter: {k}": v for k, v in flat.pop("params").items()})
        return flat

    def poisson_depth(self) -> int:
        """The depth screened Poisson runs at: the one given, else the one matching the resolution."""
        return self.depth or (poisson_depth(self.resolution) if self.resolution else DEFAULT_DEPTH)


@dataclass
class Surface:
    """A method's output: (m, 3) vertices, (f, 3) faces; holes: the triangles that would close
    its kept holes, as (vertices, faces), when the method gives them (pictures show them
    tinted); info: numbers the method reports (our filter's runs: its result dictionary)."""
    vertices: np.ndarray
    faces: np.ndarray
    holes: Optional[Tuple[np.ndarray, np.ndarray]] = None
    info: Dict[str, object] = field(default_factory=dict)


Method = Callable[[Cloud, Settings], Surface]


def _meshset(cloud: Cloud) -> pymeshlab.MeshSet:
    ms = pymeshlab.MeshSet()
    add_layer(ms, cloud)
    return ms


def run_implicit_with_boundaries(cloud: Cloud, settings: Settings) -> Surface:
    """Our filter, its kept holes in their own layer."""
    load()
    ms = _meshset(cloud)
    info = dict(apply(ms, resolution=settings.resolution, hole_layer=True, **settings.params))
    vertices, faces = mesh_arrays(ms.mesh(1))
    holes = mesh_arrays(ms.mesh(2)) if ms.mesh_number() > 2 else None
    return Surface(vertices, faces, holes, info)


def poisson_depth(resolution: int) -> int:
    """The octree depth whose 2^depth is nearest `resolution` cells (in log scale)."""
    return int(round(np.log2(resolution)))


def _poisson(cloud: Cloud, settings: Settings) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices (m, 3), faces (f, 3), density (m,)) of MeshLab's screened Poisson surface."""
    ms = _meshset(cloud)
    ms.generate_surface_reconstruction_screened_poisson(depth=settings.poisson_depth(),
                                                        threads=settings.poisson_threads)
    mesh = ms.current_mesh()
    # Poisson stores the sample density around each vertex as its quality.
    density = mesh.vertex_scalar_array().copy()
    return mesh.vertex_matrix().copy(), mesh.face_matrix().copy(), density


def density_trim(faces: np.ndarray, density: np.ndarray, quantile: float) -> np.ndarray:
    """The faces of the (f, 3) `faces` none of whose vertices has a `density` (per vertex)
    below its `quantile`: the usual clean-up of screened Poisson (deleting those vertices)."""
    return faces[np.all(density[faces] >= np.quantile(density, quantile), axis=1)]


def run_poisson(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson (closed)."""
    vertices, faces, _ = _poisson(cloud, settings)
    return Surface(vertices, faces)


def run_poisson_trimmed(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson, then its least dense vertices removed."""
    vertices, faces, density = _poisson(cloud, settings)
    return Surface(vertices, density_trim(faces, density, settings.trim_quantile))


def run_poisson_with_boundaries(cloud: Cloud, settings: Settings) -> Surface:
    """MeshLab's screened Poisson surface as our filter's implicit function: Poisson's
    surface where the samples are, with the scan's boundaries."""
    ms = _meshset(cloud)
    info = poisson_with_boundaries(ms, depth=settings.poisson_depth(), poisson_threads=settings.poisson_threads,
                                   resolution=settings.resolution, hole_layer=True, **settings.params).info
    vertices, faces = mesh_arrays(ms.mesh(2))
    holes = mesh_arrays(ms.mesh(3)) if ms.mesh_number() > 3 else None
    return Surface(vertices, faces, holes, info)


# Our filter first: the others run at the resolution it chose.
METHODS: Dict[str, Method] = {
    "implicit with boundaries": run_implicit_with_boundaries,
    "screened Poisson": run_poisson,
    "screened Poisson + density trim": run_poisson_trimmed,
    "screened Poisson with boundaries": run_poisson_with_boundaries,
}
