# Two commands do everything on a fresh Debian machine:
#   make demo   installs what is missing, builds the plugin, reconstructs pymeshlab's bunny
#   make test   the same setup, then every test (C++ core, Python/pymeshlab, GUI load check,
#               the core's tests again under AddressSanitizer + UndefinedBehaviorSanitizer)
#   make fuzz   10,000 random inputs through the filter (real meshes damaged, when ../shared/data is there)
#   make wheel  dist/implicit_boundaries-*.whl, the Python package with the double plugin inside
#   make install-plugin MESHLAB=<folder of the meshlab binary>   the plugin that fits that MeshLab
PYTHON ?= python3
BUILD  ?= build
JOBS   ?= $(shell nproc)
SANITIZE_BUILD ?= build-sanitize
FLOAT_BUILD    ?= build-float
DOUBLE_PLUGIN  := $(BUILD)/meshlab-2025.07d/libfilter_implicit_boundaries.so
FLOAT_PLUGIN   := $(FLOAT_BUILD)/meshlab-2025.07/libfilter_implicit_boundaries.so
FUZZ_EXAMPLES  ?= 10000

# The Python package finds the double plugin in build/ by itself; another BUILD folder is named to it.
ifneq ($(BUILD),build)
export IMPLICIT_BOUNDARIES_PLUGIN ?= $(abspath $(DOUBLE_PLUGIN))
endif

.PHONY: all deps plugin plugin-float demo wheel install-plugin test test-core test-python test-sanitize fuzz gui gui-double clean

all: plugin

deps:
	.ci/install-deps
	$(PYTHON) -m pip install -q --no-deps -e python

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -G Ninja -DMESHLAB_SOURCE_DIR="$$(.ci/meshlab-source)" -DPython3_EXECUTABLE="$$(command -v $(PYTHON))"

plugin: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)
	rm -rf python/implicit_boundaries/lib  # where builds before 2026-12 put it: it would shadow this one

# The float plugin, for MeshLab 2025.07 (the build most people run): linked against the
# libmeshlab-common.so of a float MeshLab built from the same sources (cached, .ci/meshlab-gui).
plugin-float: deps
	.ci/install-deps gui
	cmake -S . -B $(FLOAT_BUILD) -G Ninja -DIB_SCALAR=float -DIB_BUILD_TESTS=OFF -DMESHLAB_SOURCE_DIR="$$(.ci/meshlab-source)" \
	  -DMESHLAB_COMMON_LIB="$$(.ci/meshlab-gui float)/libmeshlab-common.so"
	cmake --build $(FLOAT_BUILD) -j $(JOBS)

demo: plugin
	$(PYTHON) -m implicit_boundaries demo

# A platform wheel with the double plugin inside: `pip install dist/implicit_boundaries-*.whl`
# where pymeshlab 2025.7.post1 installs (it pulls it in) gives the package and the command line.
wheel: plugin
	IMPLICIT_BOUNDARIES_PLUGIN=$(abspath $(DOUBLE_PLUGIN)) $(PYTHON) -m pip wheel -q --no-deps -w dist ./python
	@ls dist/implicit_boundaries-*.whl

test-core: plugin
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-python: plugin
	$(PYTHON) -m pytest -q tests

# The core's unit tests (not the plugin) built with ASan + UBSan in their own build directory;
# any report stops the test with a failure. -O1 -g1: the sanitizers' usual level, line numbers
# in the reports, and a much cheaper compile than -O2 -g; asserts stay on (no NDEBUG).
test-sanitize:
	.ci/install-deps
	cmake -S . -B $(SANITIZE_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
	  -DIB_BUILD_PLUGIN=OFF -DIB_SANITIZE=ON -DMESHLAB_SOURCE_DIR="$$(.ci/meshlab-source)"
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	cd $(SANITIZE_BUILD) && ASAN_OPTIONS=halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS)

# Property-based fuzzing of the filter with many random examples (make test runs a bounded few).
fuzz: plugin
	IB_FUZZ_PROFILE=fuzz IB_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) $(PYTHON) -m pytest -q tests/test_fuzz.py

# Builds MeshLab 2025.07 (float; cached outside the repo) and tests the float plugin in it:
# installed from Help > Plugin Info > Load Plugins and found after a restart, then run from the
# Filters menu on one scan (its surface exported and compared with pymeshlab's, made with the
# double plugin: same loops, within 1e-4 of the diagonal), then on two aligned scans merged. gui-double: the same with MeshLab 2025.07d and the double plugin (pymeshlab's).
gui: plugin plugin-float
	.ci/install-plugin "$$(.ci/meshlab-gui float)" $(DOUBLE_PLUGIN) $(FLOAT_PLUGIN) | grep "installed the float plugin"
	tests/gui/load_plugin_from_dialog_in_meshlab.sh "$$(.ci/meshlab-gui float)" $(FLOAT_PLUGIN) out/gui-load-plugin
	tests/gui/apply_filter_in_meshlab.sh "$$(.ci/meshlab-gui float)" $(FLOAT_PLUGIN) out/gui
	$(PYTHON) tests/gui/same_surface.py out/gui/result.ply
	tests/gui/merge_layers_in_meshlab.sh "$$(.ci/meshlab-gui float)" $(FLOAT_PLUGIN) out/gui-merge
	@echo "Start MeshLab with the plugin: $$(.ci/meshlab-gui float)/meshlab"
	@echo "then Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction with boundaries"

gui-double: plugin
	.ci/install-deps gui
	.ci/install-plugin "$$(.ci/meshlab-gui double)" $(DOUBLE_PLUGIN) $(FLOAT_PLUGIN) | grep "installed the double plugin"
	tests/gui/apply_filter_in_meshlab.sh "$$(.ci/meshlab-gui double)" $(DOUBLE_PLUGIN) out/gui-double
	$(PYTHON) tests/gui/same_surface.py out/gui-double/result.ply
	tests/gui/merge_layers_in_meshlab.sh "$$(.ci/meshlab-gui double)" $(DOUBLE_PLUGIN) out/gui-double-merge

# Copies the plugin that fits the MeshLab in $(MESHLAB) (its precision, read from its
# libmeshlab-common.so) into that MeshLab's plugins folder.
install-plugin: plugin plugin-float
	.ci/install-plugin "$(MESHLAB)" $(DOUBLE_PLUGIN) $(FLOAT_PLUGIN)

test: test-core test-python gui gui-double test-sanitize

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) $(FLOAT_BUILD) python/build dist
