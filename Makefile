# Two entry points (see README, Quick start):
#   make demo  - install missing packages, build (Release), run the flagship demo: the
#                slider-crank with an elastic connecting rod, 8 nodal beam elements and 2
#                modes, 3 revolutions; a table, build/demo_out/deflection.png and the
#                animation build/demo_out/view.html (flexmbd view)
#                (make demo-rigid: the rigid slider-crank against its closed form)
#   make test  - install missing packages, build (Release), run the CTest suite except the
#                long runs labelled "slow" (cd build && ctest -L slow runs those)
#   make sanitize - the same suite built Debug with AddressSanitizer (leaks included) and
#                UndefinedBehaviorSanitizer in build-sanitize/; any report fails the test
#   make apidocs - the API reference: the C++ headers through Doxygen (docs/Doxyfile) into
#                build/apidocs/html, the Python module's docstrings through pydoc into
#                build/apidocs/python (scripts/apidocs.cmake)
BUILD ?= build
JOBS  ?= 2

SANITIZE_BUILD ?= build-sanitize
# -O1: Debug (-g, assertions of Eigen and the engine on) but fast enough for the suite;
# -fno-sanitize-recover: an undefined-behaviour report ends the test (it fails).
SANITIZE_FLAGS = -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

.PHONY: demo demo-rigid test setup build bench clean sanitize apidocs

setup:
	./scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

DEMO_OUT = $(BUILD)/demo_out
FLEXMBD  = $(BUILD)/app/flexmbd

# The flagship. The table needs only the standard library (python3 on PATH will do); the
# plot runs scripts/plot_results.py with Debian's /usr/bin/python3 and its matplotlib.
demo: build
	$(FLEXMBD) run examples/slider_crank_elastic_demo_nodal.json --out $(DEMO_OUT)/nodal --quiet
	$(FLEXMBD) run examples/slider_crank_elastic_demo_modal.json --out $(DEMO_OUT)/modal --quiet
	python3 scripts/demo_report.py $(DEMO_OUT)/nodal $(DEMO_OUT)/modal --labels "8 nodal elements,2 modes" \
	  --l1 0.15 --l2 0.30 --deflection mid
	$(FLEXMBD) plot $(DEMO_OUT)/nodal $(DEMO_OUT)/modal --columns mid.uy --x crank.theta --deg \
	  --labels "8 nodal elements,2 modes" --out $(DEMO_OUT)/deflection.png \
	  --title "Elastic slider-crank: midpoint deflection of the rod, 8 nodal elements vs 2 modes"
	$(FLEXMBD) view $(DEMO_OUT)/nodal --out $(DEMO_OUT)/view.html
	@echo
	@echo "the animation in a browser (offline, one file): $(abspath $(DEMO_OUT))/view.html"
	@echo "plot of the midpoint deflection against the crank angle: $(DEMO_OUT)/deflection.png"
	@echo "results: $(DEMO_OUT)/nodal and $(DEMO_OUT)/modal (results.csv, summary.json);"
	@echo "  $(FLEXMBD) summary $(DEMO_OUT)/nodal    prints a run's summary"
	@echo "  $(FLEXMBD) plot $(DEMO_OUT)/nodal --columns slider.x,mid.N --out FILE.png    plots any columns"

demo-rigid: build
	$(FLEXMBD) run examples/slider_crank_rigid.json --out $(BUILD)/demo_rigid_out
	python3 scripts/print_table.py $(BUILD)/demo_rigid_out

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

sanitize: setup
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
	  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" -DFLEXMBD_BUILD_PYTHON=OFF
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	cd $(SANITIZE_BUILD) && \
	  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -LE slow

apidocs: build
	cmake --build $(BUILD) --target apidocs
	@echo
	@echo "the C++ API reference: $(abspath $(BUILD))/apidocs/html/index.html"
	@echo "the Python API reference: $(abspath $(BUILD))/apidocs/python/index.html"

bench: build
	$(BUILD)/benchmarks/bench_rigid_slider_crank

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD)
