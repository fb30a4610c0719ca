# Thin wrapper around CMake; the README's quick start is `make demo` and `make test`.
BUILD ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
# The sanitizer builds (ASan + UBSan, clang, the libFuzzer targets): doc/testing.md. build-fuzz
# holds the format readers and their fuzz targets only (make test), build-asan everything
# (make test-asan, make test-long).
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
ASAN_CC ?= clang-14
ASAN_CXX ?= clang++-14
ASAN_FLAGS ?= -O1 -gline-tables-only -DNDEBUG
# `make test SANITIZE=0` (or `make test-fast`) runs the gcc suite only.
SANITIZE ?= 1

.PHONY: all deps configure build demo test test-fast test-fuzz test-asan configure-asan \
        build-asan configure-fuzz build-fuzz test-long install clean format

all: build

deps:
	@bash scripts/setup-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

build: configure
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD)

ASAN_CONFIGURE = CC=$(ASAN_CC) CXX=$(ASAN_CXX) cmake -S . -DRIGCAL_SANITIZE=ON \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)" \
	  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)"

configure-asan: deps
	$(ASAN_CONFIGURE) -B $(ASAN_BUILD)

build-asan: configure-asan
	cmake --build $(ASAN_BUILD) -j$(JOBS)

configure-fuzz: deps
	$(ASAN_CONFIGURE) -B $(FUZZ_BUILD) -DRIGCAL_FORMATS_ONLY=ON

build-fuzz: configure-fuzz
	cmake --build $(FUZZ_BUILD) -j$(JOBS)

# Every test but the long ones (CTest label "long"), within the CI budget of 20 minutes on 2
# cores: the gcc build's tests, then the format readers under the sanitizers (their fuzz targets'
# committed inputs replayed, then 3 s of fuzzing each).
test: test-fast $(if $(filter 1,$(SANITIZE)),test-fuzz)

# The gcc build's tests only.
test-fast: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# The format readers' sanitizer build: the fuzz targets' replays and short runs.
test-fuzz: build-fuzz
	cd $(FUZZ_BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# The whole sanitizer build's tests (the unit tests through ASan and UBSan, the fuzz targets).
test-asan: build-asan
	cd $(ASAN_BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# The long checks: the statistical ones (many seeds, many images) of the gcc build, then the whole
# sanitizer build: its unit tests and fuzz targets, with the long fuzz runs.
test-long: build $(if $(filter 1,$(SANITIZE)),build-asan)
	cmake --build $(BUILD) -j$(JOBS) --target rigcal_long_tests
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -L long
	$(if $(filter 1,$(SANITIZE)),cd $(ASAN_BUILD) && ctest --output-on-failure -j$(JOBS))

install: build
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX),)

format:
	find calib apps tests -name '*.h' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD)
