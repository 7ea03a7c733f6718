# iblkit: `make demo` and `make test` are the two commands a new user needs.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
DEMO_OUT ?= demo-out
STAMP := $(BUILD)/.deps-ok

.PHONY: all deps configure build demo test bench clean fuzz test-sanitize

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

# The whole suite under AddressSanitizer + UndefinedBehaviorSanitizer (gcc), in build-asan.
ASAN_BUILD ?= build-asan
SANITIZE_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
# The MPI tests run apart, with OpenMPI's components kept loaded and full malloc stacks, so that OpenMPI's
# own allocations (ompi_op_base_op_select, its MCA components) meet their suppressions in lsan.supp.
# Everything else, the GL tests included, runs with leak checking: a sanitizer build keeps Mesa's driver
# loaded once a context is made (render/gl/context.h, keep_drivers_loaded_for_leak_checks), so its own
# allocations meet lsan.supp's driver entries, and links Embree into the executable (CMakeLists.txt), so
# that LeakSanitizer's exit-time scan never meets dynamically loaded thread-local blocks it crashes on.
# intercept_tls_get_addr=0: up to GCC 13, the runtime's __tls_get_addr interceptor takes a dynamic TLS block
# whose start lies at a certain offset in its page for a pre-2.25 glibc header and reads the two words before it,
# and the exit-time tracer then dies ("Tracer caught signal 11", no leak named) by the chance of where malloc put
# the block (the mechanism as Mudlet found it, github.com/Mudlet/Mudlet/pull/9930): seen here once in cli_examples.
# Each `--help`/README example (cli_examples) may take IBLKIT_EXAMPLE_TIMEOUT seconds here.
SANITIZE_MPI := ^(IlfMpi\.|cli_mpi$$)
test-sanitize: | $(STAMP)
	cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS="$(SANITIZE_FLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" -DIBLKIT_BUILD_BENCH=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0 IBLKIT_EXAMPLE_TIMEOUT=900 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/fuzz/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure --timeout 3600 -j $(JOBS) -E '$(SANITIZE_MPI)'
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:fast_unwind_on_malloc=0:intercept_tls_get_addr=0 OMPI_MCA_mca_base_component_disable_dlclose=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/fuzz/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS) -R '$(SANITIZE_MPI)'

# libFuzzer harnesses (fuzz/, clang-14) in build-fuzz, each run FUZZ_SECONDS on its corpus.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 60
FUZZ_JOBS ?= 2
fuzz: | $(STAMP)
	CC=clang-14 CXX=clang++-14 cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DIBLKIT_FUZZ=ON -DIBLKIT_BUILD_TESTS=OFF -DIBLKIT_BUILD_BENCH=OFF -DIBLKIT_WITH_GL=OFF
	cmake --build $(FUZZ_BUILD) -j $(FUZZ_JOBS) --target iblkit_fuzzers
	bash fuzz/run-fuzzers $(FUZZ_BUILD) $(FUZZ_SECONDS)

clean:
	rm -rf $(BUILD) $(DEMO_OUT)

# The Python module's pytest suite (python/tests) against build/python; `make test` runs it too (CTest "python").
.PHONY: python-test
python-test: build
	python/run-tests $(BUILD) $(BUILD)/iblkit
