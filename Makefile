# spidar-mr: the two commands a newcomer needs are `make demo` and `make test`.
# Each installs missing Debian packages (scripts/install-deps), configures and builds.
JOBS ?= $(shell nproc)
SPIDAR_MR := build/release/src/app/spidar-mr
DEMO_OUT ?= out/demo

.PHONY: all deps build demo test test-asan test-tsan bench install clean format

all: build

deps:
	@scripts/install-deps

build: deps
	cmake --preset release >/dev/null
	cmake --build --preset release -j $(JOBS)

demo: build
	$(SPIDAR_MR) demo --out $(DEMO_OUT)

test: build
	ctest --preset release -j $(JOBS)

test-asan: deps
	cmake --preset asan >/dev/null
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan -j $(JOBS)

# ThreadSanitizer build of the threaded tests (servo loop, lock-free hand-off).
test-tsan: deps
	cmake --preset tsan >/dev/null
	cmake --build --preset tsan -j $(JOBS)
	ctest --preset tsan -j $(JOBS)

bench: build
	scripts/run-benchmarks build/release/bench build/bench-results

install: build
	cmake --install build/release --prefix $(or $(PREFIX),/usr/local)

format:
	find include src tests bench -name '*.hpp' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf build out
