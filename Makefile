# Dermis — convenience entry points. Everything goes through CMake; see README.md.
BUILD ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 60
JOBS ?= 2
# ccache (when installed, see DERMIS_CCACHE): paths relative to the clone, so that another clone
# of the same sources (CI's) hits the same cache entries.
export CCACHE_BASEDIR ?= $(CURDIR)
export CCACHE_NOHASHDIR ?= 1
CMAKE_FLAGS ?=

.PHONY: all deps build test test-asan fuzz run offline bench loadbench authorbench layoutbench proposebench patterns character clean format

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_FLAGS)

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

# Installs, builds and runs every test.
test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The container for real (root; not part of `make test`): builds docker/Dockerfile with buildah on
# a debootstrapped debian:12, runs the server from the image and renders a frame
# (tests/docker/image_test.sh, docs/container.md).
.PHONY: test-image
test-image:
	bash tests/docker/image_test.sh

# Same tests under AddressSanitizer + UndefinedBehaviorSanitizer.
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Debug -DDERMIS_SANITIZE=ON -DDERMIS_BUILD_BENCHMARKS=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:suppressions=$(CURDIR)/tests/asan.supp LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS) -LE gl
	# GL suites: memory errors are checked, leaks are not — Mesa's OSMesa leaves allocations made
	# from llvmpipe's JIT code (no module to suppress by) alive at exit.
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=0:suppressions=$(CURDIR)/tests/asan.supp UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS) -L gl

# libFuzzer targets (tests/fuzz: glTF loader, image decoders, scene documents) under ASan + UBSan,
# in a clang build tree of their own, FUZZ_SECONDS each; fails on any crash, leak or timeout
# (inputs in $(FUZZ_BUILD)/artifacts). See docs/reliability.md "Fuzzing".
fuzz: deps
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DDERMIS_FUZZ=ON -DDERMIS_BUILD_TESTS=OFF -DDERMIS_BUILD_BENCHMARKS=OFF $(CMAKE_FLAGS)
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target dermis-fuzz
	bash tests/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

# Installs, builds and runs the product's main job: the HTTP render server on 127.0.0.1:8080
# with the built-in character and pattern set (data in out/data; Ctrl-C stops it).
PORT ?= 8080
run: build
	$(BUILD)/dermis-server serve --port $(PORT) --data out/data

# The offline commands on the default scene: GPU bake (+ normal map) and one rendered frame.
offline: build
	$(BUILD)/dermis-server info
	$(BUILD)/dermis-server bake --gpu --normals --scene models/default.scene.json --out out/default --png
	$(BUILD)/dermis-server render --scene models/default.scene.json --out out/default/frame.png
	@echo "wrote out/default/{bump,displacement}.{exr,png}, normal.png and frame.png"

bench: build
	$(BUILD)/bench/dermis-bench $(BENCH_ARGS)

loadbench: build
	$(BUILD)/bench/dermis-loadbench $(BENCH_ARGS)

authorbench: build
	$(BUILD)/bench/dermis-authorbench $(BENCH_ARGS)

layoutbench: build
	$(BUILD)/bench/dermis-layoutbench $(BENCH_ARGS)

# SPEC §8 proposals and transfer per model (JSON; docs/benchmarks.md).
proposebench: build
	$(BUILD)/bench/dermis-proposebench $(BENCH_ARGS)

# Regenerates the built-in pattern library (patterns/*.png, manifest.json, contact sheet).
patterns: build
	cmake --build $(BUILD) --target patterns

# Regenerates the built-in default character (models/default.glb, default.charts.json).
character: build
	cmake --build $(BUILD) --target character

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) out
