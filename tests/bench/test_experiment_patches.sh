#!/usr/bin/env bash
# The experiment scripts of bench/ (free_heuristic.sh, cost_bound_heuristic.sh) build vnsba_bench
# with a patch of bench/ applied; a patch that no longer applies breaks its script, and nothing
# else would notice (the patches are not part of the build). Checks that every bench/*.patch
# applies to the source tree as it is.
#   test_experiment_patches.sh SOURCE_DIR
# Exit 0: all apply; 1: one does not (named); 77: not a git checkout (a release tarball), skipped.
set -euo pipefail
source_dir=$1
if ! command -v git >/dev/null || ! git -C "$source_dir" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "skipped: $source_dir is not a git checkout, so its patches cannot be checked"
  exit 77
fi
status=0
shopt -s nullglob
patches=("$source_dir"/bench/*.patch)
[[ ${#patches[@]} -gt 0 ]] || { echo "no bench/*.patch found in $source_dir"; exit 1; }
for patch in "${patches[@]}"; do
  if why=$(git -C "$source_dir" apply --check "$patch" 2>&1); then
    echo "applies: bench/$(basename "$patch")"
  else
    echo "does not apply: bench/$(basename "$patch") (refresh it: apply it by hand, fix the" \
         "rejected hunks, git diff > it):"
    echo "$why"
    status=1
  fi
done
exit $status
