# Thin wrapper around CMake; the README's quick start is `make demo` and `make test`.
BUILD ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
# The sanitizer build (ASan + UBSan, clang, the libFuzzer targets): doc/testing.md.
ASAN_BUILD ?= build-asan
ASAN_CC ?= clang-14
ASAN_CXX ?= clang++-14
ASAN_FLAGS ?= -O1 -gline-tables-only -DNDEBUG
# `make test SANITIZE=0` (or `make test-fast`) runs the gcc suite only.
SANITIZE ?= 1

.PHONY: all deps configure build demo test test-fast test-asan configure-asan build-asan \
        test-long install clean format

all: build

deps:
	@bash scripts/setup-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

build: configure
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD)

configure-asan: deps
	CC=$(ASAN_CC) CXX=$(ASAN_CXX) cmake -S . -B $(ASAN_BUILD) -DRIGCAL_SANITIZE=ON \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)" \
	  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)"

build-asan: configure-asan
	cmake --build $(ASAN_BUILD) -j$(JOBS)

# Every test but the long statistical ones (CTest label "long"): the gcc build (with every fuzz
# target's seeds and regressions replayed), then the sanitizer build (its unit tests, the fuzz
# targets' replays and short runs).
test: test-fast $(if $(filter 1,$(SANITIZE)),test-asan)

# The gcc build's tests only.
test-fast: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# The sanitizer build's tests only.
test-asan: build-asan
	cd $(ASAN_BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# Only the long checks: the statistical ones (many seeds, many images) and the long fuzz runs.
test-long: build $(if $(filter 1,$(SANITIZE)),build-asan)
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -L long
	$(if $(filter 1,$(SANITIZE)),cd $(ASAN_BUILD) && ctest --output-on-failure -j$(JOBS) -L long)

install: build
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX),)

format:
	find calib apps tests -name '*.h' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
