# SPDX-License-Identifier: MIT
# The project's front door. `make run` and `make test` work on a fresh Debian bookworm machine.
JOBS ?= $(shell nproc)
PREFIX ?= /usr/local

.PHONY: all deps viewer run demo test test-tsan test-asan lint lint-changed install build-release build-ci bench \
        format check-format clean help

all: build-release

help:
	@echo "make run          install deps, build Release, play the default scenario (llsfsim run)"
	@echo "make demo         the kinematic world demo (three robots, no refbox)"
	@echo "make test         install deps, check formatting, build with -Werror, run the whole test"
	@echo "                  suite, clang-tidy on the files changed since main, the batch tests"
	@echo "                  under ThreadSanitizer, the comm tests under AddressSanitizer"
	@echo "                  (docs/testing.md)"
	@echo "make lint         clang-tidy (.clang-tidy) over every project source and test"
	@echo "make test-tsan    build the batch tests with ThreadSanitizer (build/tsan) and run them"
	@echo "make test-asan    build the comm tests with AddressSanitizer + UBSan (build/asan) and run"
	@echo "                  them (the stream server's stress test)"
	@echo "make install      build Release, install into PREFIX (default /usr/local; docs/install.md)"
	@echo "make bench        build Release and run every benchmark (bench/run)"
	@echo "make viewer       build the browser front end (viewer/dist/report.js; scripts/build-viewer)"
	@echo "make format       clang-format every source file"
	@echo "make check-format fail if a source file is not clang-formatted"
	@echo "make clean        remove build/"

deps:
	@scripts/install-deps

# The front end (npm ci from the lock, tsc, esbuild): the bundle `llsfsim report --html` inlines.
viewer: deps
	@scripts/build-viewer

build-release: deps viewer
	@cmake --preset release >/dev/null
	@cmake --build --preset release -j $(JOBS)

build-ci: deps viewer
	@cmake --preset ci >/dev/null
	@cmake --build --preset ci -j $(JOBS)

run: build-release
	./build/release/llsfsim run scenarios/default.yaml $(ARGS)

demo: build-release
	./build/release/kinematic/llsf-world-demo $(ARGS)

# The whole suite: formatting first (fails in seconds), the -Werror build and every test,
# clang-tidy on the files changed since main (`make lint`: all), the batch tests under TSan, the
# comm tests under ASan.
test: check-format build-ci
	ctest --preset ci -j $(JOBS)
	@scripts/lint --changed
	$(tsan_batch_tests)
	$(asan_comm_tests)

# The batch tests (worker threads) under ThreadSanitizer: only the libraries and the one test
# binary they need are built (build/tsan).
define tsan_batch_tests
@cmake --preset tsan >/dev/null
@cmake --build --preset tsan-batch -j $(JOBS)
ctest --preset tsan-batch -j $(JOBS)
endef

test-tsan: deps
	$(tsan_batch_tests)

# The comm tests (frame decoders, hub, UDP and TCP on loopback, the stream server's stress test)
# under AddressSanitizer + UBSan: only the comm library and its one test binary are built
# (build/asan).
define asan_comm_tests
@cmake --preset asan >/dev/null
@cmake --build --preset asan-comm -j $(JOBS)
ctest --preset asan-comm -j $(JOBS)
endef

test-asan: deps
	$(asan_comm_tests)

lint: build-ci
	@scripts/lint

lint-changed: build-ci
	@scripts/lint --changed

install: build-release
	cmake --install build/release --prefix $(PREFIX)

bench: deps
	bench/run

format:
	scripts/format

check-format: deps
	@scripts/format --check

clean:
	rm -rf build
