#!/usr/bin/env bash
# One interop run: vnsba_node (Fast DDS) with a temporary config and a Cyclone DDS client on a
# domain and a namespace of their own; then the node is stopped with SIGTERM and must exit 0.
# Prints the node's log when anything failed.
#   run_interop.sh NODE CLIENT MODE [client args...]
#   MODE: transient_local | volatile | localhost | debug_layers | fresh_clients, CLIENT
#         vnsba_cyclone_client; action | action_cancel | action_fresh, CLIENT
#         vnsba_cyclone_action_client;
#         lifecycle | lifecycle_self, CLIENT vnsba_cyclone_lifecycle_client: the node managed
#         (lifecycle: managed, --name cyclone_lifecycle) walked through its lifecycle, or
#         self-activating and reporting active; distro_kilted | distro_humble, CLIENT
#         vnsba_cyclone_distro_client (the node with that ros.distro);
#         bond | bond_lifecycle, CLIENT vnsba_cyclone_bond_client: the node bonds from start to
#         stop (bond.mode always), or is the managed planner_server (lifecycle: managed, --name
#         planner_server) that bonds while active; the client plays nav2_lifecycle_manager (its
#         lifecycle calls, then its side of the bond) and freezes the node (SIGSTOP, then
#         SIGCONT) to see its watchdog fire;
#         secure | secure_open | secure_other_ca, CLIENT vnsba_cyclone_client: the node secured
#         with a keystore of tools/make_keystore.sh, the client secured with an enclave of the
#         same keystore (it plans: every check of a default run), without security or with an
#         enclave of another keystore (refused: nothing matches, and the node logs the refusal
#         once, naming the Cyclone DDS participant). Cyclone's security plugins are looked for in
#         $VNSBA_CYCLONE_SECURITY_LIBS (a folder), else found by the dynamic loader.
# Measurements (nothing asserted), over loopback:
#   run_interop.sh NODE CLIENT localhost --bench 2000 --fresh 40
#   run_interop.sh NODE ACTION_CLIENT action --bench 1000
#   run_interop.sh NODE ACTION_CLIENT action_fresh --fresh 200 --fresh-parallel 2
#   run_interop.sh NODE CLIENT secure --bench 2000 (against transient_local --bench 2000)
# secure also sends the Cyclone client's request from vnsba_send_goal ($VNSBA_SEND_GOAL).
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
  action_fresh) domain=222 durability=transient_local localhost=false ;;
  lifecycle) domain=223 durability=transient_local localhost=false ;;
  lifecycle_self) domain=224 durability=transient_local localhost=false ;;
  bond) domain=225 durability=transient_local localhost=false ;;
  bond_lifecycle) domain=226 durability=transient_local localhost=false ;;
  secure) domain=219 durability=transient_local localhost=false ;;
  secure_open) domain=220 durability=transient_local localhost=false ;;
  secure_other_ca) domain=221 durability=transient_local localhost=false ;;
  distro_kilted) domain=227 durability=transient_local localhost=false ;;
  distro_humble) domain=228 durability=transient_local localhost=false ;;
  *)
    echo "mode: found '$mode', expected transient_local, volatile, localhost, debug_layers," \
      "fresh_clients, action, action_cancel, action_fresh, lifecycle, lifecycle_self, bond," \
      "bond_lifecycle, secure, secure_open, secure_other_ca, distro_kilted or distro_humble" >&2
    exit 2
    ;;
esac
case "$mode" in
  action) client_args=(--domain "$domain") ;;
  action_cancel) client_args=(--domain "$domain" --cancel) ;;
  # 40 fresh action clients one after another, each sending its goal the moment the action
  # server is available (no settle time), beside an idle resident client (a navigator's), over
  # Cyclone's default configuration (the machine's interface, multicast locators): every one
  # must get its send_goal and get_result replies. Arguments after the mode add to these (the
  # last --fresh wins): --fresh N, --fresh-parallel P.
  action_fresh) client_args=(--domain "$domain" --fresh 40 --fresh-resident) ;;
  lifecycle) client_args=(--domain "$domain" --node-name cyclone_lifecycle) ;;
  lifecycle_self) client_args=(--domain "$domain" --node-name cyclone_lifecycle --self-activating) ;;
  # The manager's bond_timeout 2 s (Nav2's default is 4): the watchdog is measured in 2 s.
  bond) client_args=(--domain "$domain" --id vnsba_node --bond-timeout 2 --period 0.1) ;;
  # Nav2's default bond_timeout, 4 s: the first bond forms with endpoints the node creates at
  # configure, on a participant Cyclone discovers then; the manager waits half of it (2 s) for
  # the first heartbeat, and 1 s was once too short here.
  bond_lifecycle)
    client_args=(--domain "$domain" --id planner_server --bond-timeout 4 --period 0.1 --lifecycle)
    ;;
  distro_*) client_args=(--domain "$domain" --distro "${mode#distro_}") ;;
  *) client_args=(--domain "$domain" --map-durability "$durability") ;;
esac
if [[ "$mode" == debug_layers ]]; then client_args+=(--debug-layers); fi
# Refused clients wait this long (s) for a match that must not come: longer than the node's 10 s
# handshake timeout, after which it logs the refusal of a peer that stayed silent.
if [[ "$mode" == secure_open || "$mode" == secure_other_ca ]]; then client_args+=(--refused 12); fi
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

# The environment must not change the run: ROS_DOMAIN_ID would replace the domain_id below,
# ROS_LOCALHOST_ONLY=1 would turn localhost_only on
# for the node, ROS_DISCOVERY_SERVER would make it a Discovery Server client and
# ROS_SECURITY_ENABLE a secured participant (neither reachable by this client), a CYCLONEDDS_URI
# would reconfigure the client.
unset ROS_DOMAIN_ID ROS_LOCALHOST_ONLY ROS_DISCOVERY_SERVER ROS_SECURITY_ENABLE CYCLONEDDS_URI
ns="interop_${mode}_$$"
# Secured runs use the default topic names (a keystore's permissions name topics; the domains
# 219..221 are these runs' alone among the interop runs; participants of other suites there
# are refused, having other CAs).
if [[ "$mode" == secure* ]]; then ns=""; fi
# robot_radius 0 and no cost gradient (the node's built-in defaults, the paper's binary grid,
# spelled out): paths pass the ends of the client's wall within a few centimetres, where an
# oracle that sampled segments instead of walking them exactly could miss a clipped corner.
cat >"$work/node.yaml" <<YAML
domain_id: $domain
namespace: "$ns"
map:
  durability: $durability
  robot_radius: 0
  inflation_radius: 0
network:
  localhost_only: $localhost
YAML
if [[ "$mode" == distro_* ]]; then
  # The distribution whose types the node serves; goal_tolerance 0 as for the actions (a goal in
  # the wall is refused, not moved).
  cat >>"$work/node.yaml" <<YAML
ros:
  distro: ${mode#distro_}
planner:
  goal_tolerance: 0
YAML
fi
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
node_args=()
if [[ "$mode" == lifecycle* ]]; then
  # The node under another name (--name), managed or self-activating; requests wait for the map.
  node_args=(--name cyclone_lifecycle)
  lifecycle=managed
  [[ "$mode" == lifecycle_self ]] && lifecycle=self_activating
  cat >>"$work/node.yaml" <<YAML
lifecycle: $lifecycle
requests:
  map_wait: 20
YAML
fi
if [[ "$mode" == bond ]]; then
  cat >>"$work/node.yaml" <<YAML
bond:
  mode: always
  heartbeat_period: 0.1
YAML
elif [[ "$mode" == bond_lifecycle ]]; then
  node_args=(--name planner_server)
  cat >>"$work/node.yaml" <<YAML
lifecycle: managed
bond:
  mode: managed
  heartbeat_period: 0.1
YAML
fi
if [[ "$localhost" == true ]]; then
  # Cyclone on the loopback interface only; loopback has no multicast, so discovery is unicast
  # to the node's well-known ports on 127.0.0.1 (Peer), as for a ROS 2 system on rmw_cyclonedds
  # restricted to localhost.
  export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'
fi

if [[ "$mode" == secure* ]]; then
  make_keystore="$(dirname "$0")/../../tools/make_keystore.sh"
  # The client's enclave: what it publishes and reads (both ways: it also reads back its own
  # samples to check their encapsulation).
  client_topics=projected_map,plan_request,robot_pose,goal_pose,plan_status,plan
  bash "$make_keystore" "$work/keystore" --domain "$domain" \
    --enclave /vnsba/cyclone_client "$client_topics" "$client_topics" >/dev/null
  cat >>"$work/node.yaml" <<YAML
security:
  enable: true
  keystore: $work/keystore
YAML
  client_keystore="$work/keystore"
  if [[ "$mode" == secure_other_ca ]]; then
    client_keystore="$work/other_keystore"
    bash "$make_keystore" "$client_keystore" --domain "$domain" \
      --enclave /vnsba/cyclone_client "$client_topics" "$client_topics" >/dev/null
  fi
  if [[ "$mode" != secure_open ]]; then
    # Cyclone DDS's DDS Security configuration, as rmw_cyclonedds writes it from an SROS2
    # enclave: the builtin plugins, the enclave's identity, permissions and governance.
    e="$client_keystore/enclaves/vnsba/cyclone_client"
    lib() { echo "${VNSBA_CYCLONE_SECURITY_LIBS:+$VNSBA_CYCLONE_SECURITY_LIBS/}libdds_security_$1.so"; }
    export CYCLONEDDS_URI="<CycloneDDS><Domain id=\"any\"><Security>
<Authentication><Library path=\"$(lib auth)\" initFunction=\"init_authentication\" finalizeFunction=\"finalize_authentication\"/>
<IdentityCertificate>file:$e/cert.pem</IdentityCertificate><IdentityCA>file:$e/identity_ca.cert.pem</IdentityCA>
<PrivateKey>file:$e/key.pem</PrivateKey></Authentication>
<AccessControl><Library path=\"$(lib ac)\" initFunction=\"init_access_control\" finalizeFunction=\"finalize_access_control\"/>
<PermissionsCA>file:$e/permissions_ca.cert.pem</PermissionsCA><Governance>file:$e/governance.p7s</Governance>
<Permissions>file:$e/permissions.p7s</Permissions></AccessControl>
<Cryptographic><Library path=\"$(lib crypto)\" initFunction=\"init_crypto\" finalizeFunction=\"finalize_crypto\"/></Cryptographic>
</Security></Domain></CycloneDDS>"
  fi
fi

"$node_bin" --config "$work/node.yaml" "${node_args[@]}" >"$work/node.log" 2>&1 &
node_pid=$!
# The bond client freezes the node to see the manager's watchdog fire.
if [[ "$mode" == bond* ]]; then client_args+=(--node-pid "$node_pid"); fi
status=0
"$client_bin" "${client_args[@]}" --namespace "$ns" "$@" > >(tee "$work/client.out") || status=$?
if [[ "$mode" == secure && $status -eq 0 ]] && grep -q "^request ends: " "$work/client.out"; then
  # The same request from a secured Fast DDS client (vnsba_send_goal, enclave /vnsba/send_goal)
  # on the map the Cyclone client left latched: the node must plan it exactly as it planned the
  # Cyclone client's (its log line: planner, code, length, clearance, turns, expansions).
  read -r sx sy gx gy < <(sed -n 's/^request ends: //p' "$work/client.out")
  "$VNSBA_SEND_GOAL" --config "$work/node.yaml" --id fastdds-same-request --start "$sx" "$sy" \
    --goal "$gx" "$gy" --wait 20 || status=$?
  plan_line() { grep "plan '$1'" "$work/node.log" | sed "s/.*plan '$1' //; s/, [0-9]* us planning.*//"; }
  cyclone_plan="$(plan_line "$(sed -n 's/^plan_request \([^:]*\): OK.*/\1/p' "$work/client.out")")"
  fastdds_plan="$(plan_line fastdds-same-request)"
  if [[ -z "$cyclone_plan" || "$cyclone_plan" != "$fastdds_plan" ]]; then
    echo "FAILED: the same request planned differently: Cyclone DDS client '$cyclone_plan'," \
      "Fast DDS client '$fastdds_plan'" >&2
    status=1
  else
    echo "same request from both vendors' secured clients: $cyclone_plan"
  fi
fi
# A node left frozen (a bond run whose client died during the SIGSTOP) must run to hear SIGTERM.
kill -CONT "$node_pid" 2>/dev/null || true
kill -TERM "$node_pid" 2>/dev/null || true
node_status=0
wait "$node_pid" || node_status=$?
node_pid=
if [[ "$mode" == secure* && $status -eq 0 ]]; then
  # The node's side: a refused Cyclone DDS client is one log line naming it; an admitted one
  # none, and the node's identity sorts above it (no warning about that). Participants of other
  # suites on the domain may be refused too: only lines naming this client count.
  client_prefix="$(sed -n 's/^participant GUID prefix: //p' "$work/client.out")"
  refusals=$(grep -c "refused remote participant $client_prefix (.* on Cyclone DDS" "$work/node.log" || true)
  [[ -n "$client_prefix" ]] || refusals=-1
  expected=1
  [[ "$mode" == secure ]] && expected=0
  if [[ "$refusals" -ne "$expected" ]]; then
    echo "FAILED: $refusals refusal lines naming the Cyclone DDS client '$client_prefix'," \
      "expected $expected" >&2
    status=1
  elif grep "refused remote participant $client_prefix" "$work/node.log" |
    grep -q "''\|certificate  of\|of CA )"; then
    # Every field of the line says something (Cyclone DDS announces no participant name, and
    # its identity token carries no subjects).
    echo "FAILED: the refusal line has an empty field" >&2
    status=1
  elif grep -q "sorts below most" "$work/node.log"; then
    echo "FAILED: the node's identity does not sort first" >&2
    status=1
  else
    echo "node: $refusals refusal line(s) naming the Cyclone DDS client $client_prefix, as expected"
    grep "refused remote participant $client_prefix" "$work/node.log" || true
  fi
fi
if [[ $status -ne 0 || $node_status -ne 0 ]]; then
  echo "--- client exit $status, node exit $node_status (0 expected); the node's log:" >&2
  cat "$work/node.log" >&2
  exit 1
fi
