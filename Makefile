# Two entry points (see README, Quick start):
#   make demo  - install missing packages, build (Release), run the rigid slider-crank demo
#   make test  - install missing packages, build (Release), run the CTest suite except the
#                long runs labelled "slow" (cd build && ctest -L slow runs those)
#   make sanitize - the same suite built Debug with AddressSanitizer (leaks included) and
#                UndefinedBehaviorSanitizer in build-sanitize/; any report fails the test
BUILD ?= build
JOBS  ?= 2

SANITIZE_BUILD ?= build-sanitize
# -O1: Debug (-g, assertions of Eigen and the engine on) but fast enough for the suite;
# -fno-sanitize-recover: an undefined-behaviour report ends the test (it fails).
SANITIZE_FLAGS = -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

.PHONY: demo test setup build bench clean sanitize

setup:
	./scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(BUILD)/app/flexmbd run examples/slider_crank_rigid.json --out $(BUILD)/demo_out
	python3 scripts/print_table.py $(BUILD)/demo_out

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

sanitize: setup
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
	  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined"
	cmake --build $(SANITIZE_BUILD) -j $(JOBS)
	cd $(SANITIZE_BUILD) && \
	  ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:halt_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -LE slow

bench: build
	$(BUILD)/benchmarks/bench_rigid_slider_crank

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD)
