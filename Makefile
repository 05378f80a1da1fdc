# Two commands do everything on a fresh Debian machine:
#   make demo   installs what is missing, builds the plugin, reconstructs pymeshlab's bunny
#   make test   the same setup, then every test (C++ core, Python/pymeshlab, GUI load check)
PYTHON ?= python3
BUILD  ?= build
JOBS   ?= $(shell nproc)

.PHONY: all deps plugin demo test test-core test-python test-gui gui clean

all: plugin

deps:
	.ci/install-deps
	$(PYTHON) -m pip install -q --no-deps -e python

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -G Ninja -DMESHLAB_SOURCE_DIR="$$(.ci/meshlab-source)" -DPython3_EXECUTABLE="$$(command -v $(PYTHON))"

plugin: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

demo: plugin
	$(PYTHON) -m implicit_boundaries demo

test-core: plugin
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-python: plugin
	$(PYTHON) -m pytest -q tests

# Builds MeshLab 2025.07d (cached outside the repo) and checks that it loads our plugin.
gui: plugin
	.ci/install-deps gui
	tests/gui/apply_filter_in_meshlab.sh "$$(.ci/meshlab-gui)" python/implicit_boundaries/lib/libfilter_implicit_boundaries.so
	@echo "Start MeshLab with the plugin: $$(.ci/meshlab-gui)/meshlab"
	@echo "then Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction with boundaries"


test: test-core test-python gui

clean:
	rm -rf $(BUILD) python/implicit_boundaries/lib
