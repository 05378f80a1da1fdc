"""The wheel carries the compiled plugin (lib/libfilter_implicit_boundaries.so, built by `make
plugin`), so it is a platform wheel tied to this Python and pymeshlab 2025.7.post1, not a
pure-Python one; the rest of the metadata is in pyproject.toml."""
import sys
from pathlib import Path

from setuptools import setup
from setuptools.dist import Distribution

PLUGIN = Path(__file__).parent / "implicit_boundaries" / "lib" / "libfilter_implicit_boundaries.so"


class PluginDistribution(Distribution):
    def has_ext_modules(self):  # the platform tag, as for a compiled extension
        return True


# Only the wheel must carry the plugin: the editable install (make deps) comes before the build.
if "bdist_wheel" in sys.argv and not PLUGIN.is_file():
    raise SystemExit(f"{PLUGIN} is not built: run 'make plugin' (or 'make wheel') at the repository root first")
setup(distclass=PluginDistribution)
