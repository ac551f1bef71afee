#!/usr/bin/env bash
# tools/fetch_data.sh --check (issue 45, item 6): it must name every file of
# tools/data_manifest.tsv that is missing or differs, and exit 1; pass a complete folder.
#
#   test_fetch_data.sh SOURCE_DIR DATA_DIR
#
# 1. An empty folder: every file of the manifest named missing, exit 1.
# 2. With the data beside the project (DATA_DIR): that folder passes, exit 0; and a copy of three
#    of its small files, one with a byte changed and one cut short by a byte, has exactly those
#    two named as differing, the third not named, every other file named missing, exit 1.
# Needs no network. Works in a fresh folder under TMPDIR, removed at the end. Exit 0: passed;
# 1: failed (what, on the last line); 77: no data in DATA_DIR, case 2 skipped.
set -uo pipefail
source_dir=$1
data=$2
script="$source_dir/tools/fetch_data.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/vnsba_fetch_data_test.XXXXXX")
trap 'rm -rf "$work"' EXIT

fail() {
  echo "--- fetch_data.sh's output:"
  cat "$work/out"
  echo "FAILED: $*"
  exit 1
}

files=$(grep -v '^#' "$source_dir/tools/data_manifest.tsv" | grep -c .)
[ "$files" -gt 3 ] || fail "tools/data_manifest.tsv lists $files files"

# 1. An empty folder.
mkdir "$work/empty"
bash "$script" --check --dest "$work/empty" >"$work/out" 2>&1
status=$?
[ "$status" = 1 ] || fail "an empty folder: exit $status, expected 1"
missing=$(grep -c '^\[fetch_data\] FAILED .*: missing$' "$work/out")
[ "$missing" = "$files" ] || fail "an empty folder: $missing files named missing, expected $files"
echo "an empty folder: all $files files named missing, exit 1"

# 2. The data, and a damaged copy of part of it.
small=(movingai/arena.map movingai/arena.map.scen octomap/simple.bt)
for f in "${small[@]}"; do
  if [ ! -f "$data/$f" ]; then
    echo "skipped: $data/$f is absent (the third-party data beside the project;" \
      "tools/fetch_data.sh fetches it): the damaged-copy case needs it"
    exit 77
  fi
done

bash "$script" --check --dest "$data" >"$work/out" 2>&1
status=$?
[ "$status" = 0 ] || fail "$data: exit $status, expected 0 (the data differs from the manifest)"
echo "$data: passes"

copy="$work/copy"
for f in "${small[@]}"; do
  mkdir -p "$copy/$(dirname "$f")"
  cp "$data/$f" "$copy/$f"
done
# One byte of arena.map changed (the size stays), simple.bt one byte short.
byte=$(dd if="$copy/movingai/arena.map" bs=1 skip=100 count=1 2>/dev/null)
if [ "$byte" = X ]; then other=Y; else other=X; fi
printf '%s' "$other" | dd of="$copy/movingai/arena.map" bs=1 seek=100 conv=notrunc 2>/dev/null
size=$(stat -c %s "$data/octomap/simple.bt")
head -c $((size - 1)) "$data/octomap/simple.bt" >"$copy/octomap/simple.bt"

bash "$script" --check --dest "$copy" >"$work/out" 2>&1
status=$?
[ "$status" = 1 ] || fail "the damaged copy: exit $status, expected 1"
grep -q '^\[fetch_data\] FAILED movingai/arena.map: differs: sha256 ' "$work/out" ||
  fail "the changed byte of movingai/arena.map is not reported"
grep -q "^\[fetch_data\] FAILED octomap/simple.bt: differs: $((size - 1)) bytes, expected $size\$" \
  "$work/out" || fail "octomap/simple.bt, a byte short, is not reported"
! grep -q 'FAILED movingai/arena.map.scen' "$work/out" ||
  fail "movingai/arena.map.scen, an intact copy, is reported"
differs=$(grep -c '^\[fetch_data\] FAILED .*: differs: ' "$work/out")
[ "$differs" = 2 ] || fail "the damaged copy: $differs files named as differing, expected 2"
missing=$(grep -c '^\[fetch_data\] FAILED .*: missing$' "$work/out")
[ "$missing" = $((files - 3)) ] ||
  fail "the damaged copy: $missing files named missing, expected $((files - 3))"
echo "a damaged copy: movingai/arena.map and octomap/simple.bt named, the intact file not, exit 1"
