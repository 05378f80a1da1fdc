"""The values of the filter's enum parameters, spelt exactly as the plugin's dialog and
pymeshlab take them, e.g. ``apply(ms, implicit=Implicit.HOPPE)``, and the one default the
Python side repeats.

Each class is named after its parameter and lists its labels in the plugin's order (the index
the filter's result dictionary reports: ``result["implicit"] == 0`` is ``Implicit.PU_RBF``);
the first is the default. tests/test_options.py checks them against the loaded plugin.
"""


class Implicit:
    """``implicit``: the implicit surface that is extracted."""
    PU_RBF = "PU-RBF (paper)"
    HOPPE = "Hoppe signed distance"
    MESH_LAYER = "Mesh layer (signed distance)"  # a closed mesh layer (``implicit_mesh``), e.g. screened Poisson's
    LABELS = (PU_RBF, HOPPE, MESH_LAYER)


class SodsOccupancy:
    """``sods_occupancy``: which lattice cells the samples mark."""
    TANGENT_DISKS = "Tangent disks"
    SAMPLE_CELLS = "Sample cells (paper)"
    LABELS = (TANGENT_DISKS, SAMPLE_CELLS)


class Normals:
    """``normals``: where the oriented normals come from."""
    USE_LAYER = "Use layer normals"
    ESTIMATE = "Estimate"
    FACING_VIEWPOINT = "Estimate, facing the viewpoint"  # with the ``viewpoint`` parameter
    LABELS = (USE_LAYER, ESTIMATE, FACING_VIEWPOINT)


class Extraction:
    """``extraction``: where the implicit function is evaluated and the surface extracted."""
    SODS_DRIVEN = "SODS-driven"
    FULL_LATTICE = "Full lattice, gated"
    PLAIN = "Plain marching cubes"
    LABELS = (SODS_DRIVEN, FULL_LATTICE, PLAIN)


# Every enum parameter of the filter, by its pymeshlab name.
ENUMS = {"implicit": Implicit, "sods_occupancy": SodsOccupancy, "normals": Normals, "extraction": Extraction}

# The filter's default normal_neighbours: normals the Python side estimates (screened Poisson
# needs them) use as many neighbours as the filter's own estimate.
NORMAL_NEIGHBOURS = 15
