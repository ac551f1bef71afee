#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs every test.
#   1. a Release build of everything, then ctest over all suites;
#   2. an AddressSanitizer + UndefinedBehaviorSanitizer build (no benchmarks), then ctest over
#      the core and node suites (our code is instrumented; Fast DDS and the fastddsgen-generated
#      types are not).
# Build folders: build/release and build/asan (reused, so a second run only rebuilds changes).
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc 2>/dev/null || echo 2)
bash tools/bootstrap.sh

echo "[test] release build"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$jobs"
echo "[test] release tests"
ctest --test-dir build/release --output-on-failure -j "$jobs" --timeout 900

echo "[test] sanitizer build (address, undefined) of everything but the benchmarks"
cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVNSBA_SANITIZE=ON \
  -DVNSBA_BUILD_BENCH=OFF -DVNSBA_CORE_ONLY=OFF >/dev/null
cmake --build build/asan -j "$jobs"
echo "[test] sanitizer tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs" -L "core|node" --timeout 1800
echo "[test] all passed"
