# Thin wrapper around CMake; the README's quick start is `make demo` and `make test`.
BUILD ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)

.PHONY: all deps configure build demo test test-long install clean format

all: build

deps:
	@bash scripts/setup-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

build: configure
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	@bash scripts/demo.sh $(BUILD)

# Every test but the long statistical ones (CTest label "long").
test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -LE long

# Only the long statistical checks (many seeds, many images).
test-long: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS) -L long

install: build
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX),)

format:
	find calib apps tests -name '*.h' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD)
