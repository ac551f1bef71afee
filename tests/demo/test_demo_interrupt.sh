#!/usr/bin/env bash
# Ctrl-C during the demo (issue 45): a terminal's Ctrl-C sends SIGINT to the whole foreground
# process group, the demo script and every process it started. The demo must end within 2 s of
# it, with exit code 130, and leave no process running.
#
#   test_demo_interrupt.sh BUILD_DIR OUT_DIR
#
# The demo runs in a session of its own (setsid), as it would under a terminal; the test plays
# the terminal: it waits until the goals are being sent, signals the session's process group,
# and then looks for anything of that session still alive. Whatever happens, it kills the
# session before it exits.
set -uo pipefail
build_dir=$1
out_dir=$2
root=$(cd "$(dirname "$0")/../.." && pwd)
log=$(mktemp)
domain=$((150 + $$ % 50))
setsid bash "$root/tools/demo.sh" --no-build --build-dir "$build_dir" --out "$out_dir" \
  --domain "$domain" >"$log" 2>&1 &
demo=$!  # setsid's child is the session leader: its pid is the session and the group id
cleanup() {
  kill -KILL -- "-$demo" 2>/dev/null || true
  rm -f "$log"
}
trap cleanup EXIT

fail() {
  echo "FAILED: $*" >&2
  echo "--- the demo's output:" >&2
  cat "$log" >&2
  exit 1
}

# Until the first goal is on its way (the node, recorder and slicer all running).
for _ in $(seq 1 600); do
  grep -q "sending .* goals" "$log" && break
  kill -0 "$demo" 2>/dev/null || fail "the demo ended before sending its goals"
  sleep 0.1
done
grep -q "sending .* goals" "$log" || fail "no goal was sent within 60 s"
sleep 0.3  # vnsba_send_goal is waiting for an answer

began=$(date +%s%N)
kill -INT -- "-$demo" || fail "could not signal the demo's process group"
code=0
wait "$demo" || code=$?
took_ms=$((($(date +%s%N) - began) / 1000000))
left=$(ps -o pid=,comm= --sid "$demo" 2>/dev/null || true)

echo "the demo exited with $code ${took_ms} ms after SIGINT"
[ "$code" -eq 130 ] || fail "exit code $code, expected 130"
[ "$took_ms" -le 2000 ] || fail "it took ${took_ms} ms, more than 2 s"
[ -z "$left" ] || fail "still running after it exited: $left"
grep -q "FAILED" "$log" && fail "it reported failures after the interrupt instead of stopping"
echo "ok: exit 130 within 2 s, nothing left running"
