# Two entry points (see README, Quick start):
#   make demo  - install missing packages, build (Release), run the rigid slider-crank demo
#   make test  - install missing packages, build (Release), run the CTest suite except the
#                long runs labelled "slow" (cd build && ctest -L slow runs those)
BUILD ?= build
JOBS  ?= 2

.PHONY: demo test setup build bench clean

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

bench: build
	$(BUILD)/benchmarks/bench_rigid_slider_crank

clean:
	rm -rf $(BUILD)
