#!/usr/bin/env bash
# One interop run: vnsba_node (Fast DDS) with a temporary config and a Cyclone DDS client on a
# domain and a namespace of their own; then the node is stopped with SIGTERM and must exit 0.
# Prints the node's log when anything failed.
#   run_interop.sh NODE CLIENT MODE [client args...]
#   MODE: transient_local | volatile | localhost | debug_layers | fresh_clients, CLIENT
#         vnsba_cyclone_client; action | action_cancel, CLIENT vnsba_cyclone_action_client
# Measurements (nothing asserted), over loopback:
#   run_interop.sh NODE CLIENT localhost --bench 2000 --fresh 40
#   run_interop.sh NODE ACTION_CLIENT action --bench 1000
set -euo pipefail
node_bin=$1 client_bin=$2 mode=$3
shift 3
case "$mode" in
  transient_local) domain=213 durability=transient_local localhost=false ;;
  volatile) domain=214 durability=volatile localhost=false ;;
  localhost) domain=215 durability=transient_local localhost=true ;;
  debug_layers) domain=212 durability=transient_local localhost=false ;;
  fresh_clients) domain=211 durability=transient_local localhost=true ;;
  action) domain=216 durability=transient_local localhost=false ;;
  action_cancel) domain=217 durability=transient_local localhost=false ;;
  *)
    echo "mode: found '$mode', expected transient_local, volatile, localhost, debug_layers," \
      "fresh_clients, action or action_cancel" >&2
    exit 2
    ;;
esac
case "$mode" in
  action) client_args=(--domain "$domain") ;;
  action_cancel) client_args=(--domain "$domain" --cancel) ;;
  *) client_args=(--domain "$domain" --map-durability "$durability") ;;
esac
if [[ "$mode" == debug_layers ]]; then client_args+=(--debug-layers); fi
# 20 fresh client processes over loopback, each sending its request the moment it matched the
# node: every one must get its first status.
if [[ "$mode" == fresh_clients ]]; then client_args+=(--bench 0 --fresh 20 --strict-fresh); fi

work=$(mktemp -d)
node_pid=
cleanup() {
  if [[ -n "$node_pid" ]] && kill -0 "$node_pid" 2>/dev/null; then kill -KILL "$node_pid"; fi
  rm -rf "$work"
}
trap cleanup EXIT

# The environment must not change the run: ROS_LOCALHOST_ONLY=1 would turn localhost_only on
# for the node, ROS_DISCOVERY_SERVER would make it a Discovery Server client and
# ROS_SECURITY_ENABLE a secured participant (neither reachable by this client), a CYCLONEDDS_URI
# would reconfigure the client.
unset ROS_LOCALHOST_ONLY ROS_DISCOVERY_SERVER ROS_SECURITY_ENABLE CYCLONEDDS_URI
ns="interop_${mode}_$$"
# robot_radius 0 and no cost gradient (the node's built-in defaults, the paper's binary grid,
# spelled out): paths pass the ends of the client's wall within a few centimetres, where an
# oracle that sampled segments instead of walking them exactly could miss a clipped corner.
cat >"$work/node.yaml" <<YAML
domain_id: $domain
namespace: $ns
map:
  durability: $durability
  robot_radius: 0
  inflation_radius: 0
network:
  localhost_only: $localhost
YAML
if [[ "$mode" == action* ]]; then
  # goal_tolerance 0: a goal in a wall cell is GOAL_OCCUPIED, not moved to the free cell beside
  # it. action_cancel's A* plans on its 2000 x 2000 maze take 0.3-0.6 s here: a budget (s) they
  # never hit, and time (s) for its 4 MB map to arrive and be installed (0.6-1.3 s here) before
  # its first goal would be refused.
  cat >>"$work/node.yaml" <<YAML
planner:
  goal_tolerance: 0
  max_planning_time: 30
requests:
  map_wait: 30
YAML
fi
if [[ "$localhost" == true ]]; then
  # Cyclone on the loopback interface only; loopback has no multicast, so discovery is unicast
  # to the node's well-known ports on 127.0.0.1 (Peer), as for a ROS 2 system on rmw_cyclonedds
  # restricted to localhost.
  export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'
fi

"$node_bin" --config "$work/node.yaml" >"$work/node.log" 2>&1 &
node_pid=$!
status=0
"$client_bin" "${client_args[@]}" --namespace "$ns" "$@" || status=$?
kill -TERM "$node_pid"
node_status=0
wait "$node_pid" || node_status=$?
node_pid=
if [[ $status -ne 0 || $node_status -ne 0 ]]; then
  echo "--- client exit $status, node exit $node_status (0 expected); the node's log:" >&2
  cat "$work/node.log" >&2
  exit 1
fi
