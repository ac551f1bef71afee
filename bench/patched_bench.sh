# Sourced by the experiment scripts (free_heuristic.sh, cost_bound_heuristic.sh): builds
# vnsba_bench from the current commit with one patch of bench/ applied, in a temporary worktree
# removed on exit, and sets `bench` to the executable and `maps` to the Moving AI folder; then
# compare_with_variable runs it twice.
#   source patched_bench.sh NAME PATCH MAPS_DIR
# NAME prefixes the error messages; MAPS_DIR must exist.
patched_bench_name=$1
patched_bench_patch=$2
maps=$3
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[[ -d $maps ]] || { echo "$patched_bench_name: no Moving AI maps at $maps" >&2; exit 2; }
maps=$(cd "$maps" && pwd)
work=$(mktemp -d)
trap 'git -C "$repo" worktree remove --force "$work/tree" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git -C "$repo" worktree add --detach "$work/tree" HEAD >/dev/null
git -C "$work/tree" apply "$repo/bench/$patched_bench_patch"
cmake -S "$work/tree" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DVNSBA_CORE_ONLY=ON \
  -DVNSBA_BUILD_TESTS=OFF >/dev/null
cmake --build "$work/build" -j "$(nproc)" --target vnsba_bench >/dev/null
bench="$work/build/tools/vnsba_bench"

# compare_with_variable VARIABLE HEADING_AS_IS HEADING_SET ARGS...: `vnsba_bench ARGS...` as is,
# then with the patch's switch VARIABLE set, each under its Markdown heading, printing the
# tables from the first "| class" header on (the same queries both times).
compare_with_variable() {
  local variable=$1 heading_as_is=$2 heading_set=$3
  shift 3
  echo "## $heading_as_is"
  "$bench" "$@" 2>/dev/null | sed -n '/^| class/,$p'
  echo "## $heading_set"
  env "$variable=1" "$bench" "$@" 2>/dev/null | sed -n '/^| class/,$p'
}
