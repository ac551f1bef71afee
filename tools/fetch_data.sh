#!/usr/bin/env bash
# Fetches the third-party data of the tests and benchmarks (Moving AI maps and scenarios, OctoMap
# trees) into ../shared/data beside the project, never into it, and checks every file against
# the size and SHA-256 that tools/data_manifest.tsv records (issue 45, item 6).
#
#   tools/fetch_data.sh [--dest DIR]           fetch what is missing or differs, check the rest
#   tools/fetch_data.sh --check [--dest DIR]   only check DIR against the manifest (no network)
#
# A file already there with the recorded hash is left alone. A file fetched is written beside its
# place first (NAME.part) and moved there only once its hash is right. The one built file,
# octomap/derived_spherical_scan_res0.05.bt, is made from OctoMap's sample scan graph with
# graph2tree (octomap-tools, which tools/bootstrap.sh installs), as the manifest says. Each
# folder fetched into gets a MANIFEST.tsv in the data folder's format if it has none
# (vnsba_bench reads the Moving AI maps' classes from it).
#
# Needs curl or wget, and sha256sum. Exit 0: every file of the manifest is in DIR with its hash;
# 1: some are not, each named on a line of its own; 2: bad use or a missing tool.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd -P)
manifest="$root/tools/data_manifest.tsv"
dest="$root/../shared/data"
mode=fetch

usage() {
  sed -n '6,7p' "$0" | sed 's/^#   //' >&2
  exit 2
}

while [ $# -gt 0 ]; do
  case $1 in
    --check) mode=check; shift ;;
    --dest) [ $# -ge 2 ] || usage; dest=$2; shift 2 ;;
    --dest=*) dest=${1#--dest=}; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "fetch_data: unknown argument '$1'" >&2; usage ;;
  esac
done

if ! command -v sha256sum >/dev/null; then
  echo "fetch_data: sha256sum is missing (coreutils)" >&2
  exit 2
fi
[ -r "$manifest" ] || { echo "fetch_data: cannot read $manifest" >&2; exit 2; }

# The SHA-256 of file $1 (read from stdin: no escaping of odd names in sha256sum's output).
sha256_of() {
  sha256sum <"$1" | cut -d' ' -f1
}

# Whether file $1 has $2 bytes and SHA-256 $3; if not, why, on stdout.
verify() {
  if [ ! -f "$1" ]; then
    echo "missing"
    return 1
  fi
  local size hash
  size=$(stat -c %s "$1")
  if [ "$size" != "$2" ]; then
    echo "differs: $size bytes, expected $2"
    return 1
  fi
  hash=$(sha256_of "$1")
  if [ "$hash" != "$3" ]; then
    echo "differs: sha256 $hash, expected $3"
    return 1
  fi
}

# Downloads URL $1 to file $2.
download() {
  if command -v curl >/dev/null; then
    curl -fsSL --retry 3 --connect-timeout 30 -o "$2" "$1"
  else
    wget -q --tries=3 --timeout=30 -O "$2" "$1"
  fi
}

dest=$(realpath -m -- "$dest")
if [ "$mode" = check ]; then
  if [ ! -d "$dest" ]; then
    echo "[fetch_data] $dest does not exist: no data to check (fetch it with tools/fetch_data.sh)"
    exit 1
  fi
else
  if ! command -v curl >/dev/null && ! command -v wget >/dev/null; then
    echo "fetch_data: needs curl or wget (Debian: apt-get install curl)" >&2
    exit 2
  fi
  case "$dest/" in
    "$root/"*)
      echo "fetch_data: $dest is inside the project: the data lives beside it (../shared/data)" >&2
      exit 2
      ;;
  esac
  mkdir -p "$dest"
  scratch=$(mktemp -d "${TMPDIR:-/tmp}/vnsba_fetch_data.XXXXXX")
  trap 'rm -rf "$scratch"; rm -f "${part:-}"' EXIT
fi
echo "[fetch_data] ${mode}ing $dest against tools/data_manifest.tsv"

total=0 good=0 fetched=0
problems=()
part=""
while IFS=$'\t' read -r -u 3 path bytes sha url build; do
  case $path in ''|'#'*) continue ;; esac
  total=$((total + 1))
  target="$dest/$path"
  if why=$(verify "$target" "$bytes" "$sha"); then
    good=$((good + 1))
    continue
  fi
  if [ "$mode" = check ]; then
    problems+=("$path: $why")
    continue
  fi

  mkdir -p "$(dirname "$target")"
  part="$target.part"
  rm -f "$part"
  if [ "$build" = "-" ]; then
    echo "[fetch_data] $path ($why): downloading $url"
    if ! download "$url" "$part"; then
      problems+=("$path: download failed: $url")
      rm -f "$part"
      continue
    fi
  else
    # A built file: the URL is its input, the build column the tool and its options.
    tool=${build%% *} options=${build#"$tool"}
    made_by="$tool -i $(basename "$url")$options -o $(basename "$path") (input: $url)"
    if [ "$tool" != graph2tree ]; then
      problems+=("$path: the manifest names an unknown build tool '$tool'")
      continue
    fi
    if ! command -v graph2tree >/dev/null; then
      problems+=("$path: not built: graph2tree is missing (octomap-tools); it is made by $made_by")
      continue
    fi
    echo "[fetch_data] $path ($why): building with $made_by"
    input="$scratch/$(basename "$url")"
    out="$scratch/$(basename "$path")"
    if ! download "$url" "$input"; then
      problems+=("$path: download of its input failed: $url")
      continue
    fi
    # shellcheck disable=SC2086  # the options are words
    if ! graph2tree -i "$input" $options -o "$out" >"$scratch/graph2tree.log" 2>&1; then
      problems+=("$path: $made_by failed: $(tail -n 1 "$scratch/graph2tree.log")")
      continue
    fi
    mv "$out" "$part"
  fi
  if why=$(verify "$part" "$bytes" "$sha"); then
    mv "$part" "$target"
    part=""
    fetched=$((fetched + 1))
    good=$((good + 1))
  else
    if [ "$build" = "-" ]; then
      problems+=("$path: the download $why (from $url)")
    else
      recorded="the recorded one was made by octomap-tools 1.9.7"
      problems+=("$path: the built file $why (made by $made_by; $recorded)")
    fi
    rm -f "$part"
    part=""
  fi
done 3<"$manifest"

# A MANIFEST.tsv for each folder fetched into that has none, in the data folder's format.
if [ "$mode" = fetch ]; then
  grep -v '^#' "$manifest" | cut -f1 | grep / | cut -d/ -f1 | sort -u | while read -r folder; do
    if [ ! -d "$dest/$folder" ] || [ -e "$dest/$folder/MANIFEST.tsv" ]; then continue; fi
    {
      printf 'local_file\tbytes\tsha256_16\tsource_repo\tsource_path\tcommit\n'
      grep -v '^#' "$manifest" | awk -F'\t' -v folder="$folder" 'BEGIN { OFS = "\t" }
        index($1, folder "/") == 1 {
          file = substr($1, length(folder) + 2)
          if ($5 == "-" && $4 ~ /^https:\/\/raw\.githubusercontent\.com\//) {
            n = split(substr($4, 35), part, "/")   # owner, name, commit, path...
            path = part[4]
            for (i = 5; i <= n; i++) path = path "/" part[i]
            print file, $2, substr($3, 1, 16), part[1] "/" part[2], path, part[3]
          } else if ($5 == "-") {
            print file, $2, substr($3, 1, 16), $4, "-", "-"
          } else {
            print file, $2, substr($3, 1, 16), "GENERATED: " $5 " from " $4, "-", "-"
          }
        }'
    } >"$dest/$folder/MANIFEST.tsv"
    echo "[fetch_data] wrote $folder/MANIFEST.tsv"
  done
fi

if [ ${#problems[@]} -eq 0 ]; then
  if [ "$mode" = check ]; then
    echo "[fetch_data] all $total files present with their recorded SHA-256"
  else
    echo "[fetch_data] all $total files present with their recorded SHA-256 ($fetched fetched now)"
  fi
  exit 0
fi
for problem in "${problems[@]}"; do
  echo "[fetch_data] FAILED $problem"
done
echo "[fetch_data] ${#problems[@]} of $total files missing or wrong in $dest" \
  "(good: $good$([ "$mode" = fetch ] && echo ", fetched now: $fetched"))"
[ "$mode" = check ] && echo "[fetch_data] fetch them with: tools/fetch_data.sh --dest $dest"
exit 1
