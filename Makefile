# Two commands do everything on a fresh Debian machine:
#   make demo   installs what is missing, builds the plugin, reconstructs pymeshlab's bunny
#   make test   the same setup, then every test (C++ core, Python/pymeshlab, GUI load check,
#               the core's tests again under AddressSanitizer + UndefinedBehaviorSanitizer)
#   make fuzz   many more random inputs through the filter than the bounded run in make test
PYTHON ?= python3
BUILD  ?= build
JOBS   ?= $(shell nproc)
SANITIZE_BUILD ?= build-sanitize
FUZZ_EXAMPLES  ?= 400

.PHONY: all deps plugin demo wheel test test-core test-python test-sanitize fuzz test-gui gui clean

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

# A platform wheel with the double plugin inside: `pip install dist/implicit_boundaries-*.whl`
# where pymeshlab 2025.7.post1 installs (it pulls it in) gives the package and the command line.
wheel: plugin
	$(PYTHON) -m pip wheel -q --no-deps -w dist ./python
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
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS) -E SpeedReport  # timing only: slow here

# Property-based fuzzing of the filter with many random examples (make test runs a bounded few).
fuzz: plugin
	IB_FUZZ_PROFILE=fuzz IB_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) $(PYTHON) -m pytest -q tests/test_fuzz.py

# Builds MeshLab 2025.07d (cached outside the repo), checks that it loads our plugin and runs it
# from the Filters menu: on one scan, then on two aligned scans of an .aln project merged.
gui: plugin
	.ci/install-deps gui
	tests/gui/apply_filter_in_meshlab.sh "$$(.ci/meshlab-gui)" python/implicit_boundaries/lib/libfilter_implicit_boundaries.so
	tests/gui/merge_layers_in_meshlab.sh "$$(.ci/meshlab-gui)" python/implicit_boundaries/lib/libfilter_implicit_boundaries.so
	@echo "Start MeshLab with the plugin: $$(.ci/meshlab-gui)/meshlab"
	@echo "then Filters > Remeshing, Simplification and Reconstruction > Implicit reconstruction with boundaries"


test: test-core test-python gui test-sanitize

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) python/implicit_boundaries/lib python/build dist
