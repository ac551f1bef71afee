#!/usr/bin/env bash
# Installs a build to a temporary prefix and uses it as a stranger would, from another folder:
#   0. what tools/demo.sh builds is everything `cmake --install` takes from the build folder
#      (issue 31: an install after the demo failed, "cannot find vnsba_plan"): checked on a fresh
#      configure with the demo's options, by what a dry run of the demo's build would link;
#   1. vnsba_plan plans on the installed demo scene;
#   2. vnsba_node, with no --config, reads the installed share/vnsba/default.yaml (its first log
#      line says so), comes up, and exits 0 on SIGINT;
#   3. docs/core-library.md's C++ block (its first ```cpp block), extracted
#      now, builds against the installed headers and CMake package and runs on a Moving AI map.
# Usage: test_install.sh BUILD_DIR SOURCE_DIR DOMAIN
set -euo pipefail
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
domain=$3
prefix=$(mktemp -d)
work=$(mktemp -d)
node_pid=""
cleanup() {
  if [[ -n "$node_pid" ]]; then kill -INT "$node_pid" 2>/dev/null || true; fi
  rm -rf "$prefix" "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "[install] the demo's build covers what cmake --install takes"
# The demo's build targets: its `targets=(...)` line.
demo_targets=$(sed -n 's/^targets=(\(.*\))$/\1/p' "$source/tools/demo.sh")
[[ -n "$demo_targets" ]] || fail "no targets=(...) line in tools/demo.sh"
fresh="$work/fresh"
cmake -G "Unix Makefiles" -S "$source" -B "$fresh" -DCMAKE_BUILD_TYPE=Release \
  >"$work/fresh.log" 2>&1 || fail "configuring a fresh build folder: $(tail -n 20 "$work/fresh.log")"
# Every target those build: the closure of the generated makefile's target dependencies
# ("tools/CMakeFiles/vnsba_plan.dir/all: core/CMakeFiles/vnsba_core.dir/all"), from the
# top-level rule of each ("vnsba_plan: tools/CMakeFiles/vnsba_plan.dir/rule").
rules="$fresh/CMakeFiles/Makefile2"
queue=()
for target in $demo_targets; do
  dir=$(sed -n "s|^$target: \(.*\)/rule\$|\1|p" "$rules")
  [[ -n "$dir" ]] || fail "tools/demo.sh builds '$target', which the build does not define"
  queue+=("$dir")
done
declare -A reached=()
while [[ ${#queue[@]} -gt 0 ]]; do
  dir=${queue[0]}
  queue=("${queue[@]:1}")
  [[ -z "${reached[$dir]:-}" ]] || continue
  reached[$dir]=1
  while read -r dependency; do
    [[ -z "$dependency" ]] || queue+=("$dependency")
  done < <(sed -n "s|^$dir/all: \(.*\)/all\$|\1|p" "$rules")
done
built=$(for dir in "${!reached[@]}"; do basename "$dir" .dir; done | sort -u)
# What the install scripts copy: executables by name, static libraries as lib<target>.a.
installed=$(grep -rhoE 'TYPE (EXECUTABLE|STATIC_LIBRARY) FILES "[^"]*"' \
  --include=cmake_install.cmake "$fresh" | sed 's|.*/||; s|"$||; s|^lib\(.*\)\.a$|\1|' | sort -u)
[[ -n "$installed" ]] || fail "no executable or library in the fresh folder's install scripts"
missing=$(comm -23 <(echo "$installed") <(echo "$built"))
[[ -z "$missing" ]] ||
  fail "cmake --install after tools/demo.sh (targets: $demo_targets) misses:" $missing
rm -rf "$fresh"

cmake --install "$build" --prefix "$prefix" >/dev/null
for tool in vnsba_plan vnsba_node vnsba_slicer vnsba_recorder vnsba_send_goal vnsba_lifecycle vnsba_make_keystore; do
  [[ -x "$prefix/bin/$tool" ]] || fail "$tool not installed in bin/"
done
for file in default.yaml paper.yaml scenes/geb079.bt scenes/ATTRIBUTION.md; do
  [[ -f "$prefix/share/vnsba/$file" ]] || fail "share/vnsba/$file not installed"
done
cd "$work"

echo "[install] vnsba_plan on the installed demo scene, from $work"
plan_out=$("$prefix/bin/vnsba_plan" "$prefix/share/vnsba/scenes/geb079.bt" --z-min 0.1 --z-max 1.5 \
  --start 2 -6 --goal 16 -6.5 --planner astar 2>&1) || fail "vnsba_plan failed: $plan_out"
grep -q "^astar OK " <<<"$plan_out" || fail "vnsba_plan did not plan: $plan_out"

echo "[install] vnsba_node without --config"
"$prefix/bin/vnsba_node" --domain "$domain" >"$work/node.log" 2>&1 &
node_pid=$!
for _ in $(seq 1 100); do
  grep -q "up on domain" "$work/node.log" && break
  kill -0 "$node_pid" 2>/dev/null || break
  sleep 0.1
done
grep -q "up on domain $domain" "$work/node.log" || fail "vnsba_node did not come up: $(cat "$work/node.log")"
first_line=$(head -n 1 "$work/node.log")
[[ "$first_line" == *"config: $prefix/share/vnsba/default.yaml"* ]] ||
  fail "the node's first log line does not name the installed config: $first_line"
kill -INT "$node_pid"
wait "$node_pid" || fail "vnsba_node exited $? on SIGINT: $(cat "$work/node.log")"
node_pid=""

echo "[install] vnsba_make_keystore from $work"
"$prefix/bin/vnsba_make_keystore" "$work/keystore" --domain "$domain" >"$work/keystore.log" 2>&1 ||
  fail "vnsba_make_keystore failed: $(cat "$work/keystore.log")"
for file in identity_ca.cert.pem cert.pem key.pem permissions_ca.cert.pem governance.p7s \
  permissions.p7s; do
  [[ -s "$work/keystore/enclaves/vnsba/node/$file" ]] || fail "the node enclave has no $file"
done

echo "[install] docs/core-library.md's C++ block against the installed package"
mkdir snippet
awk '/^```cpp/ {inside = 1; next}
     inside && /^```/ {exit} inside {print}' "$source/docs/core-library.md" >snippet/main.cpp
[[ -s snippet/main.cpp ]] || fail "no C++ block found in docs/core-library.md"
cat >snippet/CMakeLists.txt <<'CMAKE'
cmake_minimum_required(VERSION 3.22)
project(readme_snippet LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(vnsba REQUIRED)
add_executable(readme_snippet main.cpp)
target_link_libraries(readme_snippet PRIVATE vnsba::core vnsba::maps)
CMAKE
cmake -S snippet -B snippet/build -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$work/snippet.log" 2>&1 || fail "configuring the snippet: $(cat "$work/snippet.log")"
cmake --build snippet/build >>"$work/snippet.log" 2>&1 ||
  fail "building the README snippet: $(cat "$work/snippet.log")"
snippet_out=$(snippet/build/readme_snippet "$source/tests/fixtures/maps/tiny.map") ||
  fail "the README snippet failed: $snippet_out"
[[ "$snippet_out" == OK* ]] || fail "the README snippet printed: $snippet_out"
echo "[install] all passed"
