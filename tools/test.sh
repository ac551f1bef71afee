#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs every test, each in one stage:
#   1. a Release build of the executables, benchmarks and the suites below (not those of stage
#      2: VNSBA_BUILD_ALL_TESTS=OFF), then ctest over what only it can run: the benchmarks'
#      tests (bench), the published Moving AI optima (data), the Cyclone DDS interop runs
#      (interop), the demo and the installed package (demo, install);
#   2. an AddressSanitizer + UndefinedBehaviorSanitizer build (no benchmarks), then ctest over
#      the core, node and fuzz suites (our code is instrumented; Fast DDS and the
#      fastddsgen-generated types are not). They run here only: the sanitizers check more than
#      an optimised build does, and running them twice would not fit the CI's 25 minutes on 2
#      cores. To run them in the Release build too:
#        cmake -S . -B build/release -DVNSBA_BUILD_ALL_TESTS=ON && cmake --build build/release -j 2
#        ctest --test-dir build/release --output-on-failure -j 2 -L "core|node|fuzz" -LE fuzz_long
# The fuzz suite (label fuzz, tests/fuzz) feeds every loader a few thousand mutated real files in
# the sanitizer stage. Its 50x longer run (label fuzz_long) is left out of both; run it by hand with
#   ctest --test-dir build/asan --output-on-failure -L fuzz_long
# The soak (label soak: vnsba_node for 10 minutes under steady load) is left out too:
#   ctest --test-dir build/release --output-on-failure -L soak
# and so are the full-size bursts (label stress: 3 clients x 5,000 requests, SIGTERM mid-burst), in
# a Release build with every suite (VNSBA_BUILD_ALL_TESTS=ON, above) or in build/asan:
#   ctest --test-dir build/release --output-on-failure -L stress
# Build folders: build/release and build/asan (reused, so a second run only rebuilds changes).
#
# Each stage's tests run with TMPDIR a new, empty folder made for that stage (under the caller's
# TMPDIR, else /tmp) and removed at the end, also on a failure or Ctrl-C: nothing an earlier run
# left can make a test pass (issue 45), and nothing is left behind. The tests make their own
# folders inside it (tests/temp_dir.hpp).
#
# After each stage's tests, every test ctest skipped gets a line with its reason, taken from its
# output (ctest itself prints only "Skipped"), and a hint when the third-party data the build reads
# (VNSBA_DATA_DIR, ../shared/data beside the project) is missing or incomplete (issue 45, item 6):
#   [test] skipped: MovingAiOptimality.AStarMatchesPublishedOptima: Moving AI data not found at D
#   [test] the third-party data in D is missing or incomplete ... tools/fetch_data.sh --dest D ...
#
# On a failure the script names the stage, the tests that failed and the command that reruns one
# with its output (with the stage's environment); the last line is always one summary:
#   [test] all passed: release N tests, sanitizer M tests, in <minutes>m<seconds>s
#   [test] FAILED in stage 'sanitizer tests': F of M tests failed, after <minutes>m<seconds>s
# A build or the bootstrap that fails is named the same way, with the command that reruns it.
# The whole run takes about 20 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."

jobs=$(nproc 2>/dev/null || echo 2)
started=$SECONDS
stage="setup"          # what is running: named by the summary if the script stops
rerun=""               # the command that reruns it, for that summary
summary_printed=0
release_count="" sanitizer_count=""
work=""

elapsed() {
  local s=$((SECONDS - started))
  printf '%dm%02ds' $((s / 60)) $((s % 60))
}

# On every exit: remove the scratch folder and, unless a summary was printed, say where the run
# stopped (a build that failed, Ctrl-C).
finish() {
  local status=$?
  trap - EXIT INT TERM
  if [ -n "$work" ]; then rm -rf "$work"; fi
  if [ "$summary_printed" = 0 ]; then
    if [ "$status" -ge 128 ]; then
      echo "[test] INTERRUPTED in stage '$stage' (signal $((status - 128))), after $(elapsed)"
    else
      if [ -n "$rerun" ]; then
        echo
        echo "[test] stage '$stage' failed (exit $status); rerun it (from $PWD) with:"
        echo "  $rerun"
      fi
      echo "[test] FAILED in stage '$stage' (exit $status), after $(elapsed)"
    fi
  fi
  exit "$status"
}
trap finish EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# The run's scratch folder: each test stage's TMPDIR and ctest's output, removed on exit.
work=$(mktemp -d "${TMPDIR:-/tmp}/vnsba_test.XXXXXX")
work=$(cd "$work" && pwd)  # absolute: ctest writes its JUnit file relative to the build folder

# The failed tests of ctest's output file $1, one "name (reason)" a line: ctest's own list after
# "The following tests FAILED:" ("  12 - Suite.Name (Failed)", labels may follow).
failed_tests() {
  sed -n '/^The following tests FAILED:/,$p' "$1" |
    sed -nE 's/^[[:space:]]*[0-9]+ - (.*) \(([^()]*)\).*$/\1 (\2)/p'
}

# The tests ctest skipped, from its JUnit file $1, one "name: reason" a line. The reason comes from
# the test's output: GoogleTest's "file:line: Skipped" and the message under it (GTEST_SKIP), a
# script's "skipped: ..." line (SKIP_RETURN_CODE), else its last line.
skipped_tests() {
  awk '
    function unescape(s) {
      gsub(/&lt;/, "<", s); gsub(/&gt;/, ">", s); gsub(/&quot;/, "\"", s)
      gsub(/&apos;/, "\047", s); gsub(/&amp;/, "\\&", s)
      return s
    }
    function reason(   i, j, r) {
      for (i = 1; i <= n; i++) {
        if (lines[i] !~ /: Skipped$/) continue
        for (j = i + 1; j <= n && lines[j] != "" && lines[j] !~ /^\[  SKIPPED \]/; j++)
          r = r (r == "" ? "" : " ") lines[j]
        if (r != "") return r
        return "GTEST_SKIP without a message at " substr(lines[i], 1, length(lines[i]) - 9)
      }
      for (i = 1; i <= n; i++) if (lines[i] ~ /^skipped: /) return substr(lines[i], 10)
      for (i = n; i >= 1; i--) if (lines[i] ~ /[^ \t]/) return lines[i]
      return "(no output)"
    }
    /<testcase / {
      name = $0; sub(/.*<testcase name="/, "", name); sub(/".*/, "", name); name = unescape(name)
      skipped = 0; n = 0; out = 0
    }
    # Skipped by the test itself; other "notrun" tests (no executable, ...) are failures.
    /<skipped message="SKIP_/ { skipped = 1 }
    /<system-out>/ { out = 1; sub(/.*<system-out>/, "") }
    out {
      line = $0
      if (sub(/<\/system-out>.*/, "", line)) out = 0
      lines[++n] = unescape(line)
      next
    }
    /<\/testcase>/ { if (skipped) print name ": " reason() }
  ' "$1"
}

# After a stage's tests (build folder $1, ctest's JUnit file $2): each skipped test with its
# reason, and, if some were skipped and the build's data folder (VNSBA_DATA_DIR in its cache) does
# not match tools/data_manifest.tsv (tools/fetch_data.sh --check: no network, under a second),
# how to fetch the data.
report_skipped() {
  local dir=$1 junit=$2 skipped data
  [ -s "$junit" ] || return 0
  skipped=$(skipped_tests "$junit" || true)
  [ -n "$skipped" ] || return 0
  printf '%s\n' "$skipped" | sed 's/^/[test] skipped: /'
  data=$(sed -n 's/^VNSBA_DATA_DIR:PATH=//p' "$dir/CMakeCache.txt" 2>/dev/null || true)
  if [ -n "$data" ] && ! bash tools/fetch_data.sh --check --dest "$data" >/dev/null 2>&1; then
    echo "[test] the third-party data in $data is missing or incomplete" \
      "(tools/fetch_data.sh --check --dest $data names the files): tests that read it skip;" \
      "fetch it with tools/fetch_data.sh --dest $data (docs/benchmarks.md, \"The data\")"
  fi
}

# A ctest -R expression matching test name $1 only.
exact_regex() {
  printf '^%s$' "$(printf '%s' "$1" | sed -e 's/[][\\.*^$+?(){}|]/\\&/g')"
}

# Runs ctest over build folder $2 for stage $1 ("release", "sanitizer") with the environment of
# the array stage_env and TMPDIR a new empty folder; the other arguments go to ctest. Sets
# <stage>_count to the number of tests run. On a failure: the failed tests, the command that
# reruns one, the summary; then exits.
run_tests() {
  local name=$1 dir=$2
  shift 2
  local tmp="$work/$name.tmp" out="$work/$name.out" junit="$work/$name.junit.xml" status=0
  mkdir "$tmp"
  # ctest writes it on a failure only: an old one would name tests of an earlier run.
  rm -f "$dir/Testing/Temporary/LastTestsFailed.log"
  # tee -i: on Ctrl-C tee copies on until ctest has stopped; a tee gone first would end ctest with
  # SIGPIPE in the middle of what it writes.
  env ${stage_env[@]+"${stage_env[@]}"} TMPDIR="$tmp" ctest --test-dir "$dir" \
    --output-junit "$junit" "$@" 2>&1 | tee -i "$out" || status=$?
  report_skipped "$dir" "$junit"
  local count
  count=$(grep -Eo 'tests? failed out of [0-9]+' "$out" | grep -Eo '[0-9]+$' | tail -n 1 || true)
  printf -v "${name}_count" '%s' "${count:-0}"
  local left
  left=$(find "$tmp" -mindepth 1 -maxdepth 1 | head -n 10 || true)
  if [ -n "$left" ]; then
    # Not a failure of its own (a crashed test cannot clean up; it fails anyway), but worth
    # knowing: a test should leave nothing behind.
    echo "[test] left in the stage's TMPDIR after its tests (removed now):"
    printf '%s\n' "$left" | sed 's/^/[test]   /'
  fi
  [ "$status" = 0 ] && return 0

  local failed failed_count=0
  failed=$(failed_tests "$out")
  if [ -z "$failed" ] && [ -s "$dir/Testing/Temporary/LastTestsFailed.log" ]; then
    failed=$(sed -E 's/^[0-9]+://' "$dir/Testing/Temporary/LastTestsFailed.log")
  fi
  local env_words=""
  [ ${#stage_env[@]} -gt 0 ] && env_words="$(printf '%q ' "${stage_env[@]}")"
  echo
  echo "[test] stage '$stage' failed (ctest exit $status)."
  if [ -n "$failed" ]; then
    failed_count=$(printf '%s\n' "$failed" | wc -l)
    echo "[test] failed tests ($failed_count of ${count:-?}):"
    printf '%s\n' "$failed" | sed 's/^/[test]   /'
    local first
    first=$(printf '%s\n' "$failed" | head -n 1 | sed -E 's/ \([^()]*\)$//')
    echo "[test] rerun one with its output (from $PWD):"
    echo "  ${env_words}ctest --test-dir $dir --output-on-failure -R '$(exact_regex "$first")'"
    echo "[test] or every test that failed:"
    echo "  ${env_words}ctest --test-dir $dir --output-on-failure --rerun-failed"
  else
    echo "[test] ctest named no failed test: its output is above."
  fi
  summary_printed=1
  if [ "$failed_count" -gt 0 ]; then
    echo "[test] FAILED in stage '$stage': $failed_count of ${count:-?} tests failed," \
      "after $(elapsed)"
  else
    echo "[test] FAILED in stage '$stage': ctest exit $status, after $(elapsed)"
  fi
  exit 1
}

stage="bootstrap" rerun="bash tools/bootstrap.sh"
bash tools/bootstrap.sh

stage="release build" rerun="cmake --build build/release -j $jobs"
echo "[test] release build"
# Without the suites it does not run (VNSBA_BUILD_ALL_TESTS=OFF): they build in the sanitizer
# stage. For all of them in Release: cmake -S . -B build/release -DVNSBA_BUILD_ALL_TESTS=ON
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DVNSBA_BUILD_ALL_TESTS=OFF >/dev/null
cmake --build build/release -j "$jobs"
stage="release tests" rerun=""
echo "[test] release tests"
stage_env=()
run_tests release build/release --output-on-failure -j "$jobs" --timeout 900 \
  -LE "core|node|fuzz|soak|stress"  # a regular expression: fuzz also matches fuzz_long

stage="sanitizer build" rerun="cmake --build build/asan -j $jobs"
echo "[test] sanitizer build (address, undefined) of everything but the benchmarks and the soak"
# -O1 -g1: the optimisation level the sanitizers' authors recommend, and line tables only, which
# is all a sanitizer report needs for file:line. With RelWithDebInfo's -O2 -g, a file that
# includes CLI11 took 4x as long to compile under the sanitizers (100 s against 27 s), and the
# whole stage doubled: about 390 s against 700-880 s of the 20-minute CI budget on 2 cores.
cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DVNSBA_SANITIZE=ON \
  -DVNSBA_BUILD_BENCH=OFF -DVNSBA_BUILD_SOAK=OFF -DVNSBA_CORE_ONLY=OFF >/dev/null
cmake --build build/asan -j "$jobs"
stage="sanitizer tests" rerun=""
echo "[test] sanitizer tests"
# tests/lsan_suppressions.txt and asan_suppressions.txt: leaks and one overread inside libraries
# we do not build (fontconfig's caches, Fast DDS), each explained there.
stage_env=(
  "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:suppressions=$PWD/tests/asan_suppressions.txt"
  "UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1"
  "LSAN_OPTIONS=suppressions=$PWD/tests/lsan_suppressions.txt:print_suppressions=0"
)
run_tests sanitizer build/asan --output-on-failure -j "$jobs" -L "core|node|fuzz" -LE fuzz_long \
  --timeout 1800

summary_printed=1
echo "[test] all passed: release $release_count tests, sanitizer $sanitizer_count tests, in $(elapsed)"
