"""Implicit surface reconstruction with boundaries, as a MeshLab filter usable from pymeshlab.

    import pymeshlab, implicit_boundaries
    implicit_boundaries.load()            # loads the plugin, binds the MeshSet method
    ms = pymeshlab.MeshSet(); ms.load_new_mesh("scan.ply")
    out = ms.generate_surface_reconstruction_implicit_with_boundaries(resolution=128)

or, with numpy arrays only, :func:`reconstruct` (several aligned scans: :func:`reconstruct_scans`); on top of MeshLab's screened Poisson,
:func:`poisson_with_boundaries`; side by side with MeshLab's screened Poisson
(table, pictures, report), :func:`compare`.
"""
from ._plugin import FILTER_NAME, apply, load, plugin_path
from .compare import Comparison, compare
from .poisson import poisson_with_boundaries
from .reconstruct import Reconstruction, loops_from_result, reconstruct, reconstruct_scans

__all__ = ["FILTER_NAME", "apply", "load", "plugin_path", "reconstruct", "reconstruct_scans", "Reconstruction", "loops_from_result",
           "compare", "Comparison", "poisson_with_boundaries"]
