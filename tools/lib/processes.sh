# shellcheck shell=bash disable=SC2154,SC2034  # logs comes from the caller, exit_of is for it
# Background processes of a script (tools/demo.sh, tools/make_docs.sh): started with their output
# in a log of their own, waited for by what they log, stopped with SIGINT (each of our tools
# drains and exits 0 on it) and SIGKILL after a timeout. Sourced; the caller sets `logs` (the
# folder of the logs) and defines `fail MESSAGE` (which exits) and `say MESSAGE` (a progress line
# on stderr). Every started process is stopped by proc_stop_all, which the caller's EXIT trap
# runs.

declare -A pid_of=()   # name -> pid, while running
declare -A exit_of=()  # name -> exit code, once stopped

is_running() {  # PID: alive and not a zombie waiting to be reaped
  local state
  [ -r "/proc/$1/stat" ] || return 1
  state=$(sed 's/^.*) //' "/proc/$1/stat" 2>/dev/null | cut -d' ' -f1) || return 1
  [ -n "$state" ] && [ "$state" != Z ]
}

start() {  # NAME BINARY ARGS...: output to $logs/NAME.log
  local name="$1"
  shift
  "$@" >"$logs/$name.log" 2>&1 &
  pid_of[$name]=$!
}

# Stops NAME: SIGINT, SIGKILL after TIMEOUT seconds. Records the exit code in exit_of.
stop() {  # NAME [TIMEOUT]
  local name="$1" timeout="${2:-10}" pid="${pid_of[$1]:-}" tenths=0 code=0
  [ -n "$pid" ] || return 0
  kill -INT "$pid" 2>/dev/null || true
  while is_running "$pid" && [ "$tenths" -lt $((timeout * 10)) ]; do
    sleep 0.1
    tenths=$((tenths + 1))
  done
  if is_running "$pid"; then
    say "$name did not stop within $timeout s: killing it"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  wait "$pid" 2>/dev/null || code=$?
  exit_of[$name]=$code
  unset "pid_of[$name]"
}

# Stops every process still running, NAMES first in that order (the others after them).
proc_stop_all() {  # [NAMES...]
  local name
  for name in "$@" "${!pid_of[@]}"; do
    [ -z "${pid_of[$name]:-}" ] || stop "$name" 5
  done
}

# Waits until NAME's log contains TEXT; fails if NAME exits first or after TIMEOUT seconds.
wait_for_log() {  # NAME TEXT TIMEOUT
  local name="$1" text="$2" timeout="$3" tenths=0
  until grep -qF -- "$text" "$logs/$name.log" 2>/dev/null; do
    if ! is_running "${pid_of[$name]}"; then
      tail -n 20 "$logs/$name.log" >&2
      fail "$name exited before '$text' (log: $logs/$name.log)"
    fi
    if [ "$tenths" -ge $((timeout * 10)) ]; then
      tail -n 20 "$logs/$name.log" >&2
      fail "no '$text' from $name within $timeout s (log: $logs/$name.log)"
    fi
    sleep 0.1
    tenths=$((tenths + 1))
  done
}
