"""The wheel carries the compiled plugin (implicit_boundaries/lib/libfilter_implicit_boundaries.so,
copied from where `make plugin` builds it, build/meshlab-2025.07d, or from
$IMPLICIT_BOUNDARIES_PLUGIN), so it is a platform wheel tied to this Python and pymeshlab
2025.7.post1, not a pure-Python one; the rest of the metadata is in pyproject.toml."""
import os
import shutil
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

PLUGIN_FILE = "libfilter_implicit_boundaries.so"
PLUGIN = Path(os.environ.get("IMPLICIT_BOUNDARIES_PLUGIN")
              or Path(__file__).resolve().parent.parent / "build" / "meshlab-2025.07d" / PLUGIN_FILE)


class PluginDistribution(Distribution):
    def has_ext_modules(self):  # the platform tag, as for a compiled extension
        return True


class BuildWithPlugin(build_py):
    """Copies the plugin into the package being built (never into the source tree)."""

    def run(self):
        super().run()
        if not getattr(self, "editable_mode", False) and PLUGIN.is_file():
            lib = Path(self.build_lib) / "implicit_boundaries" / "lib"
            lib.mkdir(parents=True, exist_ok=True)
            shutil.copy2(PLUGIN, lib / PLUGIN_FILE)


# Only the wheel must carry the plugin: the editable install (make deps) comes before the build.
if "bdist_wheel" in sys.argv and not PLUGIN.is_file():
    raise SystemExit(f"{PLUGIN} is not built: run 'make plugin' (or 'make wheel') at the repository root first")
setup(distclass=PluginDistribution, cmdclass={"build_py": BuildWithPlugin})
