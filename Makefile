# spidar-mr: the two commands a newcomer needs are `make demo` and `make test`.
# Each installs missing Debian packages (scripts/install-deps), configures and builds.
JOBS ?= $(shell nproc)
SPIDAR_MR := build/release/src/app/spidar-mr
DEMO_OUT ?= out/demo

.PHONY: all deps build demo test test-asan test-tsan bench fuzz install clean format

all: build

deps:
	@scripts/install-deps

build: deps
	cmake --preset release >/dev/null
	cmake --build --preset release -j $(JOBS)

# The demo builds the spidar-mr executable only (not the tests and benchmarks).
demo: deps
	cmake --preset release >/dev/null
	cmake --build --preset release -j $(JOBS) --target spidar-mr
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

# Fuzzes the serial frame decoder with libFuzzer for FUZZ_SECONDS (clang, separate from `make
# test`, which replays the corpus), then merges new coverage into the corpus. Crashes are
# written to build/fuzz/ and fail the target.
FUZZ_SECONDS ?= 60
FUZZ_DIR := build/fuzz
FUZZ_CORPUS := fuzz/corpus/frame_decoder
fuzz:
	@scripts/install-deps --fuzz
	@mkdir -p $(FUZZ_DIR)/new
	clang++ -std=c++20 -O1 -g -Iinclude -Wall -Wextra \
	  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
	  fuzz/fuzz_frame_decoder.cpp src/device/protocol.cpp -o $(FUZZ_DIR)/fuzz_frame_decoder
	$(FUZZ_DIR)/fuzz_frame_decoder -max_total_time=$(FUZZ_SECONDS) -max_len=1024 \
	  -artifact_prefix=$(FUZZ_DIR)/ $(FUZZ_DIR)/new $(FUZZ_CORPUS)
	$(FUZZ_DIR)/fuzz_frame_decoder -merge=1 $(FUZZ_CORPUS) $(FUZZ_DIR)/new

install: build
	cmake --install build/release --prefix $(or $(PREFIX),/usr/local)

format:
	find include src tests bench -name '*.hpp' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf build out
