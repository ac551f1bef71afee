#!/usr/bin/env bash
# One interop run: vnsba_node (Fast DDS) and vnsba_cyclone_client (Cyclone DDS) on a domain of
# their own, then the node is stopped with SIGTERM and must exit 0.
#   run_interop.sh NODE CLIENT transient_local|volatile|localhost [extra client args...]
set -euo pipefail
node_bin=$1 client_bin=$2 mode=$3
shift 3
# Domains 213-215, one per mode, and topics in a namespace of this run's own: other tests that
# share a domain (every id 1..232 is some suite's) never see these topics.
case "$mode" in
  transient_local) domain=213 durability=transient_local localhost=false ;;
  volatile) domain=214 durability=volatile localhost=false ;;
  localhost) domain=215 durability=transient_local localhost=true ;;
  *) echo "mode: found '$mode', expected transient_local, volatile or localhost" >&2; exit 2 ;;
esac
work=$(mktemp -d)
node_pid=
cleanup() {
  if [[ -n "$node_pid" ]] && kill -0 "$node_pid" 2>/dev/null; then kill -KILL "$node_pid"; fi
  rm -rf "$work"
}
trap cleanup EXIT

ns="interop_${mode}_$$"
cat > "$work/node.yaml" <<YAML
domain_id: $domain
namespace: $ns
map:
  durability: $durability
network:
  localhost_only: $localhost
YAML
if [[ "$localhost" == true ]]; then
  # Cyclone on the loopback interface only, discovering by unicast to localhost (no multicast on
  # lo), as a ROS 2 system with ROS_LOCALHOST_ONLY=1 on rmw_cyclonedds does.
  export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'
fi
"$node_bin" --config "$work/node.yaml" > "$work/node.log" 2>&1 &
node_pid=$!
status=0
"$client_bin" --domain "$domain" --namespace "$ns" --map-durability "$durability" "$@" || status=$?
kill -TERM "$node_pid"
node_status=0
wait "$node_pid" || node_status=$?
node_pid=
if [[ $status -ne 0 || $node_status -ne 0 ]]; then
  echo "--- client exit $status, node exit $node_status; the node's log:" >&2
  cat "$work/node.log" >&2
  exit 1
fi
