"""Finding the compiled MeshLab plugin and loading it into pymeshlab."""
import os
import re
from pathlib import Path
from typing import Optional, Tuple

import pymeshlab

FILTER_NAME = "generate_surface_reconstruction_implicit_with_boundaries"
PLUGIN_FILE = "libfilter_implicit_boundaries.so"
# pymeshlab 2025.7.post1 embeds MeshLab 2025.07d: the double build.
PYMESHLAB_MESHLAB = ("2025.07", "double")


class PluginMismatchError(OSError):
    """The plugin file was built for another MeshLab (version or scalar type) than pymeshlab's."""


def plugin_build(path) -> Optional[Tuple[str, str]]:
    """(MeshLab version, scalar type) the plugin file was built for, e.g. ("2025.07", "float"),
    read from the file's build tag without loading it; None when the file has no tag."""
    tag = re.search(rb"implicit_boundaries plugin for MeshLab ([0-9.]+) scalar=(float|double)",
                    Path(path).read_bytes())
    return (tag.group(1).decode(), tag.group(2).decode()) if tag else None


def describe_build(build: Optional[Tuple[str, str]]) -> str:
    """'MeshLab 2025.07 (float)' or 'MeshLab 2025.07d (double)' for a plugin_build() result."""
    if build is None:
        return "an unknown MeshLab (the file has no build tag: is it this project's plugin?)"
    version, scalar = build
    return f"MeshLab {version}{'d' if scalar == 'double' else ''} ({scalar})"


# Where `make plugin` puts the double plugin, relative to the repository root (CMake's build tree).
BUILT_PLUGIN = Path("build") / "meshlab-2025.07d" / PLUGIN_FILE


def plugin_path() -> Path:
    """Path of the plugin module: $IMPLICIT_BOUNDARIES_PLUGIN; else the one the wheel carries in
    this package's lib/; else, in a source checkout, the one `make plugin` built (build/)."""
    if os.environ.get("IMPLICIT_BOUNDARIES_PLUGIN"):
        path = Path(os.environ["IMPLICIT_BOUNDARIES_PLUGIN"])
        if not path.is_file():
            raise FileNotFoundError(f"IMPLICIT_BOUNDARIES_PLUGIN is {path}, which is not a file: "
                                    "set it to a built libfilter_implicit_boundaries.so")
        return path
    package = Path(__file__).resolve().parent
    for path in (package / "lib" / PLUGIN_FILE, package.parent.parent / BUILT_PLUGIN):
        if path.is_file():
            return path
    raise FileNotFoundError(
        f"the plugin is not built: run 'make plugin' at the repository root (it writes {BUILT_PLUGIN}), "
        "install the wheel, or set IMPLICIT_BOUNDARIES_PLUGIN to a built libfilter_implicit_boundaries.so")


def apply(ms: pymeshlab.MeshSet, **kwargs) -> dict:
    """Runs the filter on ``ms`` (what the bound MeshSet method does); returns its result dictionary.

    When the filter raises, pymeshlab 2025.7 (once any plugin was added with load_plugin) keeps
    a pointer to this MeshSet's log, and the next mesh loaded after this MeshSet is gone crashes
    the interpreter. Any filter that succeeds on the same MeshSet clears that pointer, so a cheap
    measure is run before the error is passed on: the geometric measures, linear in the faces
    (the topological ones took minutes on a layer of random triangles, counting its
    non-manifold vertices).
    """
    try:
        return ms.apply_filter(FILTER_NAME, **kwargs)
    except pymeshlab.PyMeshLabException:
        if ms.mesh_number() > 0:
            try:
                ms.get_geometric_measures()
            except pymeshlab.PyMeshLabException:
                pass
        raise


def _bound_method(self, **kwargs):
    return apply(self, **kwargs)


def load() -> Path:
    """Loads the plugin into pymeshlab (once per process) and binds
    ``MeshSet.generate_surface_reconstruction_implicit_with_boundaries``; returns the plugin path.

    pymeshlab binds filter methods only for the plugins present when it is imported, so the
    method is bound here.
    """
    path = plugin_path()
    build = plugin_build(path)
    if build != PYMESHLAB_MESHLAB:
        raise PluginMismatchError(
            f"the plugin {path} is built for {describe_build(build)}; pymeshlab 2025.7.post1 embeds "
            f"{describe_build(PYMESHLAB_MESHLAB)}: use the double plugin "
            "('make plugin' builds it into build/meshlab-2025.07d; the wheel carries it). "
            "The float one is for the MeshLab 2025.07 GUI")
    if FILTER_NAME not in pymeshlab.filter_list():
        pymeshlab.load_plugin(str(path))
    if not hasattr(pymeshlab.MeshSet, FILTER_NAME):
        _bound_method.__name__ = FILTER_NAME
        _bound_method.__doc__ = "Implicit reconstruction with boundaries (see pymeshlab.print_filter_parameter_list)."
        setattr(pymeshlab.MeshSet, FILTER_NAME, _bound_method)
    return path
