# spidar-mr: the two commands a newcomer needs are `make demo` and `make test`.
# Each installs missing Debian packages (scripts/install-deps), configures and builds.
JOBS ?= $(shell nproc)
# Unity (batched) builds of the release tree: a cold build takes 40 % of the CPU time (a fresh
# clone compiles in about 6 min instead of 14 on 2 cores). When you edit and rebuild often, a
# tree without them recompiles only the file you touched: `make test SPIDAR_UNITY=OFF` (use the
# same value every time, or the tree is rebuilt).
export SPIDAR_UNITY ?= ON
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

# ThreadSanitizer build of the threaded tests (servo loop, lock-free hand-off, the session's threads).
test-tsan: deps
	cmake --preset tsan >/dev/null
	cmake --build --preset tsan -j $(JOBS)
	ctest --preset tsan -j $(JOBS)

bench: build
	scripts/run-benchmarks build/release/bench build/bench-results

# Fuzzes each target for FUZZ_SECONDS with libFuzzer (clang, separate from `make test`, which
# replays the corpora), then merges new coverage into its corpus fuzz/corpus/<target>/. Crashes
# are written to build/fuzz/<target>/ and fail the target. `make fuzz-recording_reader` runs one.
#   frame_decoder     the serial wire-protocol decoder (fuzz/fuzz_frame_decoder.cpp)
#   config_loader     YAML config loading and the device config parser (fuzz/fuzz_config_loader.cpp)
#   recording_reader  the session recording's CSV and session.json reader (fuzz/fuzz_recording_reader.cpp)
FUZZ_SECONDS ?= 60
FUZZ_DIR := build/fuzz
FUZZ_TARGETS := frame_decoder config_loader recording_reader
FUZZ_CXX := clang++ -std=c++20 -O1 -g -Iinclude -isystem /usr/include/eigen3 -Wall -Wextra \
  -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
FUZZ_SRC_frame_decoder := fuzz/fuzz_frame_decoder.cpp src/device/protocol.cpp
FUZZ_SRC_config_loader := fuzz/fuzz_config_loader.cpp src/core/config.cpp src/core/file_read.cpp \
  src/core/yaml_messages.cpp src/core/yaml_nesting_scan.cpp src/core/yaml_tree_check.cpp \
  src/strings/device_config.cpp src/strings/encoder.cpp src/strings/motor.cpp \
  src/strings/point_geometry.cpp -lyaml-cpp
FUZZ_SRC_recording_reader := fuzz/fuzz_recording_reader.cpp src/session/recording_schema.cpp \
  src/session/recording_reader.cpp src/session/recording_writer.cpp src/session/csv_cursor.cpp \
  src/session/checked_file.cpp src/core/atomic_write.cpp src/core/file_read.cpp
FUZZ_MAX_LEN_frame_decoder := 1024
FUZZ_MAX_LEN_config_loader := 8192
FUZZ_MAX_LEN_recording_reader := 8192
fuzz: $(addprefix fuzz-,$(FUZZ_TARGETS))
fuzz-%:
	@scripts/install-deps --fuzz
	@mkdir -p $(FUZZ_DIR)/$*/new
	$(FUZZ_CXX) $(FUZZ_SRC_$*) -o $(FUZZ_DIR)/fuzz_$*
	$(FUZZ_DIR)/fuzz_$* -max_total_time=$(FUZZ_SECONDS) -max_len=$(FUZZ_MAX_LEN_$*) \
	  -artifact_prefix=$(FUZZ_DIR)/$*/ $(FUZZ_DIR)/$*/new fuzz/corpus/$*
	$(FUZZ_DIR)/fuzz_$* -merge=1 fuzz/corpus/$* $(FUZZ_DIR)/$*/new

install: build
	cmake --install build/release --prefix $(or $(PREFIX),/usr/local)

format:
	find include src tests bench -name '*.hpp' -o -name '*.cpp' | xargs clang-format -i

clean:
	rm -rf build out
