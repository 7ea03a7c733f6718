# iblkit: `make demo` and `make test` are the two commands a new user needs.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
DEMO_OUT ?= demo-out
STAMP := $(BUILD)/.deps-ok

.PHONY: all deps configure build demo test bench clean

all: build

$(STAMP): scripts/install-deps
	@bash scripts/install-deps
	@mkdir -p $(BUILD) && touch $(STAMP)

deps: $(STAMP)

$(BUILD)/build.ninja: CMakeLists.txt | $(STAMP)
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release

configure: $(BUILD)/build.ninja

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	./$(BUILD)/iblkit demo --out $(DEMO_OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	./$(BUILD)/iblkit_bench --benchmark_min_time=0.2
	bash bench/run_e2e.sh $(BUILD)

clean:
	rm -rf $(BUILD) $(DEMO_OUT)
