#!/usr/bin/env bash
# The demo command: installs what is missing, builds, and shows the whole product on the
# embedded scene (config/scenes/geb079.bt, a real office floor scanned into an OctoMap):
#
#   vnsba_slicer  --publish  the OctoMap, sliced at the config's height band, as a 2D map
#   vnsba_node               plans every request on it (config/default.yaml)
#   vnsba_recorder           draws every run: OUT/<id>.svg and OUT/<id>.json
#   vnsba_send_goal          one request per goal, each answered by one status line
#
# all on a private DDS domain. The goals cover long corridors, routes around clutter, the exact
# A* and JPS beside VNS-BA*, an unreachable room (NO_VALID_PATH) and a goal inside a wall
# (GOAL_OCCUPIED). It prints a table of the results and the pictures written, stops every
# process it started, and exits 0 only if every goal ended as expected and every process
# stopped cleanly.
#
#   tools/demo.sh [--no-build] [--build-dir DIR] [--domain N] [--out DIR]
#
#   --no-build       use the binaries already in the build folder (no bootstrap, no build)
#   --build-dir DIR  build folder (default build/release, the test command's)
#   --domain N       DDS domain 0..232 (default: 100 + pid % 100)
#   --out DIR        where the runs go (default out/demo)
#
# The same settings may come from VNSBA_DEMO_NO_BUILD=1, VNSBA_DEMO_BUILD_DIR, VNSBA_DEMO_DOMAIN
# and VNSBA_DEMO_OUT. The build shows a line as each target starts compiling and as it is built,
# with cmake's percentage; a first build takes about 5 minutes on 2 cores. A second run rebuilds
# nothing and installs nothing.
set -euo pipefail
cd "$(dirname "$0")/.."
export LC_ALL=C  # decimal points in printf, whatever the user's locale

build=$([ "${VNSBA_DEMO_NO_BUILD:-0}" = 1 ] && echo 0 || echo 1)
build_dir="${VNSBA_DEMO_BUILD_DIR:-build/release}"
domain="${VNSBA_DEMO_DOMAIN:-$((100 + $$ % 100))}"
out_dir="${VNSBA_DEMO_OUT:-out/demo}"

usage() { sed -n '/^#   tools\/demo.sh/,/^#   --out/p' "$0" | sed 's/^# \{0,1\}//'; }
fail() { echo "[demo] error: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0 ;;
    --build-dir) [ $# -ge 2 ] || fail "--build-dir needs a folder"; build_dir="$2"; shift ;;
    --domain) [ $# -ge 2 ] || fail "--domain needs a number"; domain="$2"; shift ;;
    --out) [ $# -ge 2 ] || fail "--out needs a folder"; out_dir="$2"; shift ;;
    -h | --help) usage; exit 0 ;;
    *) usage >&2; fail "unknown option '$1'" ;;
  esac
  shift
done
[[ "$domain" =~ ^[0-9]+$ ]] && [ "$domain" -le 232 ] || fail "--domain: '$domain' is not 0..232"

config=config/default.yaml
scene=config/scenes/geb079.bt
logs="$out_dir/logs"

# The goals: id, planner, start x y, goal x y (metres, frame "map"), the status expected.
# Chosen on the slice at 0.1-1.5 m with the config's robot (robot_radius 0.15 m, whose inflation
# closes the rooms north of the corridor: their doorways are scanned narrower than 0.3 m): the
# corridor runs along y = 0 from x = -6.5 to 27.5 m; office_route goes from a room south of it,
# along it, into another. jps plans on uniform costs (its status says the node's cost_weight was
# not applied), so beside astar it shows the shortest path against the cheapest.
goals=(
  "corridor            vns_bastar  -6    0.5   27    -0.5  OK"
  "office_route        vns_bastar   2   -6     16    -6.5  OK"
  "office_route_astar  astar        2   -6     16    -6.5  OK"
  "office_route_jps    jps          2   -6     16    -6.5  OK"
  "hall_to_corridor    vns_bastar  16   -6.5   -6     0    OK"
  "closed_room         vns_bastar  -6    0      0     4    NO_VALID_PATH"
  "into_wall           vns_bastar  -6    0     10     1.3  GOAL_OCCUPIED"
)

started_at=$SECONDS
stage() { echo "[demo] $*"; }

# --- Install and build ------------------------------------------------------------------------
# The demo's four bus tools and everything else `cmake --install` takes from the build folder
# (the CMake target vnsba_install_set), so that an install after the demo finds every file.
targets=(vnsba_install_set)
# A first build of those targets (Release, configure included) on 2 cores: measured 4 min 16 s
# with other builds sharing the machine (load 3-4; 6 CPU-minutes in all), 8 min 23 s under a
# load of 5.
first_build_minutes=5
mkdir -p "$logs"

# Shows the build's progress from cmake's output, which goes whole to LOG: a line when a target
# starts compiling and one when it has been rebuilt, each with cmake's percentage and the
# minutes:seconds since the build began.
build_progress() {  # LOG
  local log="$1" line percent message event target began=$SECONDS
  local -A rebuilt=()  # targets compiled or linked in this build
  while IFS= read -r line; do
    printf '%s\n' "$line" >>"$log"
    if [[ "$line" =~ ^\[\ *([0-9]+)%\]\ (.*)$ ]]; then  # Unix Makefiles: "[ 45%] ..."
      percent=${BASH_REMATCH[1]}
      message=${BASH_REMATCH[2]}
    elif [[ "$line" =~ ^\[([0-9]+)/([0-9]+)\]\ (.*)$ ]]; then  # Ninja: "[12/80] ..."
      percent=$((BASH_REMATCH[1] * 100 / BASH_REMATCH[2]))
      message=${BASH_REMATCH[3]}
    else
      continue
    fi
    event=""
    case "$message" in
      "Building "*)
        if [[ "$message" =~ CMakeFiles/([^/]+)\.dir/ ]] && [ -z "${rebuilt[${BASH_REMATCH[1]}]:-}" ]; then
          target=${BASH_REMATCH[1]}
          rebuilt[$target]=1
          event="compiling $target"
        fi
        ;;
      "Linking "*)  # "Linking CXX static library libvnsba_core.a", "... executable tools/vnsba_plan"
        target=${message##*[ /]}
        target=${target%.a}
        target=${target%.so}
        [[ "$target" == libvnsba* ]] && target=${target#lib}
        if [[ "$line" =~ ^\[[0-9]+/ ]]; then  # Ninja says no "Built target"
          event="built $target"
        else
          rebuilt[$target]=1
        fi
        ;;
      "Built target "*)
        target=${message#Built target }
        if [ -n "${rebuilt[$target]:-}" ]; then event="built $target"; fi
        ;;
    esac
    if [ -n "$event" ]; then
      printf '[demo]   [%3d%%] %2d:%02d  %s\n' "$percent" $(((SECONDS - began) / 60)) \
        $(((SECONDS - began) % 60)) "$event"
    fi
  done
}

if [ "$build" = 1 ]; then
  stage "bootstrap: checking the Debian packages"
  bash tools/bootstrap.sh
  jobs=$(nproc 2>/dev/null || echo 2)
  first=0
  for bin in node/vnsba_node tools/vnsba_slicer tools/vnsba_recorder tools/vnsba_send_goal; do
    [ -x "$build_dir/$bin" ] || first=1
  done
  if [ "$first" = 1 ]; then
    stage "first build in $build_dir: about $first_build_minutes minutes on 2 cores" \
      "(this machine has $jobs); later runs rebuild only what changed"
  fi
  stage "building ${targets[*]} (every installed tool) in $build_dir (Release; log: $logs/build.log)"
  build_began=$SECONDS
  : >"$logs/build.log"
  # Configured once, with the test command's options, so both share one build folder; later
  # runs let `cmake --build` re-configure only when a CMakeLists.txt changed.
  if ! { [ -f "$build_dir/CMakeCache.txt" ] ||
         cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release; } >>"$logs/build.log" 2>&1 ||
     ! cmake --build "$build_dir" -j "$jobs" --target "${targets[@]}" 2>&1 |
       build_progress "$logs/build.log"; then
    tail -n 40 "$logs/build.log" >&2
    fail "the build failed (whole log: $logs/build.log)"
  fi
  if grep -qE '^\[[ 0-9%/]+\] (Building|Linking) ' "$logs/build.log"; then
    stage "build done ($((SECONDS - build_began)) s)"
  else
    stage "build: up to date, nothing to rebuild"
  fi
fi
node_bin="$build_dir/node/vnsba_node"
slicer_bin="$build_dir/tools/vnsba_slicer"
recorder_bin="$build_dir/tools/vnsba_recorder"
send_goal_bin="$build_dir/tools/vnsba_send_goal"
for bin in "$node_bin" "$slicer_bin" "$recorder_bin" "$send_goal_bin"; do
  [ -x "$bin" ] || fail "$bin is missing: build it, or drop --no-build"
done

# --- Processes: started in the background, stopped on every exit --------------------------------
say() { echo "[demo] $*" >&2; }
# shellcheck source=tools/lib/processes.sh
source tools/lib/processes.sh

cleanup() {
  local code=$?
  trap - EXIT INT TERM
  [ "${#pid_of[@]}" -eq 0 ] || say "stopping ${!pid_of[*]}"
  proc_stop_all recorder slicer node
  exit "$code"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Runs of an earlier demo must not pass for this one's.
for goal in "${goals[@]}"; do
  read -r id _ <<<"$goal"
  rm -f "$out_dir/demo-$id.json" "$out_dir/demo-$id.svg"
done

: >"$logs/send_goal.log"

stage "DDS domain $domain; logs in $logs/"
stage "starting vnsba_node ($config)"
start node "$node_bin" --config "$config" --domain "$domain"
wait_for_log node "up on domain $domain" 30

stage "starting vnsba_recorder (pictures and records into $out_dir/)"
start recorder "$recorder_bin" --out "$out_dir" --config "$config" --domain "$domain" \
  --runs "${#goals[@]}"
wait_for_log recorder "recorder: ready" 30

stage "starting vnsba_slicer: $scene sliced at the config's height band, published"
start slicer "$slicer_bin" "$scene" --publish --config "$config" --domain "$domain"
wait_for_log node "map accepted" 60
stage "$(grep -F "slice of" "$logs/slicer.log" | tail -n 1 | sed 's/^.*slice of/slicer: slice of/')"
stage "node: map accepted"

# --- Goals ------------------------------------------------------------------------------------
stage "sending ${#goals[@]} goals with vnsba_send_goal"
failures=0
for goal in "${goals[@]}"; do
  read -r id planner sx sy gx gy expected <<<"$goal"
  code=0
  # --min-readers 2: the request goes out once the node and the recorder both hear it.
  line=$("$send_goal_bin" --config "$config" --domain "$domain" --id "demo-$id" \
           --planner "$planner" --start "$sx" "$sy" --goal "$gx" "$gy" --wait 30 \
           --min-readers 2 2>>"$logs/send_goal.log") || code=$?
  # Ctrl-C (or SIGTERM) reached vnsba_send_goal, which tore DDS down and ended killed by it
  # (130, 143): bash runs the INT trap then; a TERM that reached the tool alone ends here.
  if [ "$code" -ge 128 ]; then
    echo "[demo] interrupted" >&2
    exit "$code"
  fi
  read -r _ status _ <<<"$line"
  status="${status:-NO_STATUS}"
  verdict="as expected"
  if [ "$status" != "$expected" ]; then
    verdict="EXPECTED $expected (exit code $code)"
    failures=$((failures + 1))
  fi
  printf '[demo]   %-20s (%6s,%5s) -> (%5s,%5s)  %-14s %s\n' "$id" "$sx" "$sy" "$gx" "$gy" \
    "$status" "$verdict"
done

stage "waiting for the recorder to write the ${#goals[@]} runs"
tenths=0
while is_running "${pid_of[recorder]}" && [ "$tenths" -lt 300 ]; do
  sleep 0.1
  tenths=$((tenths + 1))
done

stage "stopping the recorder, the slicer and the node"
stop recorder
stop slicer
stop node
for name in recorder slicer node; do
  if [ "${exit_of[$name]}" != 0 ]; then
    echo "[demo] $name exited with ${exit_of[$name]} (log: $logs/$name.log)" >&2
    failures=$((failures + 1))
  fi
done

# --- Results ----------------------------------------------------------------------------------
# One field of a run record's "status" object (the recorder writes it as the file's last
# object; the file is joined into one line first so the layout of the JSON does not matter).
status_field() {  # FILE KEY
  tr -d '\n' <"$1" | sed 's/.*"status": *{//' | grep -o "\"$2\": *[^,}]*" | head -n 1 |
    sed -e 's/^[^:]*: *//' -e 's/[[:space:]]*$//' -e 's/^"//' -e 's/"$//' || true
}

echo
printf '%-20s %-20s %-14s %9s %11s %6s %9s %9s %9s\n' run planner status "length m" \
  "clearance m" turns "turn deg" expanded "time ms"
printf '%s\n' "--------------------------------------------------------------------------------------------------------------------"
pictures=()
for goal in "${goals[@]}"; do
  read -r id _ <<<"$goal"
  record="$out_dir/demo-$id.json"
  if [ ! -f "$record" ] || [ ! -f "$out_dir/demo-$id.svg" ]; then
    printf '%-20s no run record written\n' "$id"
    failures=$((failures + 1))
    continue
  fi
  planner=$(status_field "$record" planner)
  status=$(status_field "$record" code_name)
  length_m=$(status_field "$record" length_m)
  clearance_m=$(status_field "$record" clearance_m)
  turns=$(status_field "$record" turns)
  turn_deg=$(status_field "$record" turn_angle_deg)
  expanded=$(status_field "$record" expanded)
  time_us=$(status_field "$record" planning_time_us)
  # clearance_m is NaN (JSON null) on a failed plan: shown as "-".
  case "${clearance_m:-null}" in null | nan | NaN | "") clearance_m="-" ;;
    *) clearance_m=$(awk -v c="$clearance_m" 'BEGIN { printf "%.3f", c }') ;; esac
  printf '%-20s %-20s %-14s %9.2f %11s %6d %9.1f %9d %9.2f\n' "$id" "${planner:-?}" \
    "${status:-?}" "${length_m:-0}" "$clearance_m" "${turns:-0}" "${turn_deg:-0}" "${expanded:-0}" \
    "$(awk -v us="${time_us:-0}" 'BEGIN { printf "%.2f", us / 1000 }')"
  pictures+=("$out_dir/demo-$id.svg")
done
echo
stage "pictures of the runs (open them in a browser):"
for picture in "${pictures[@]}"; do echo "  $picture"; done

elapsed=$((SECONDS - started_at))
if [ "$failures" -ne 0 ]; then
  echo "[demo] FAILED: $failures problem(s) (logs in $logs/); ${elapsed} s" >&2
  exit 1
fi
stage "done: every goal ended as expected, every process stopped cleanly (${elapsed} s)"
