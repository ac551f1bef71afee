#!/usr/bin/env bash
# Makes an SROS2-layout DDS Security keystore for vnsba's executables (openssl, awk, coreutils):
#
#   DIR/public/ca.cert.pem             the CA (identity and permissions CA are one, as
#   DIR/private/ca.key.pem             `ros2 security create_keystore` makes them), and the
#                                      identity_ca.* / permissions_ca.* links to it
#   DIR/enclaves/governance.xml, .p7s  encrypted discovery, liveliness and data on every topic;
#                                      every RTPS message signed; no unauthenticated
#                                      participants; join access control on
#   DIR/enclaves/vnsba/node/...        one enclave per executable (/vnsba/node, /vnsba/slicer,
#                                      /vnsba/recorder, /vnsba/send_goal): cert.pem (subject
#                                      CN=<enclave> and a serialNumber that makes its identity
#                                      sort first, for Cyclone DDS peers), key.pem,
#                                      permissions.xml and permissions.p7s (only the DDS topics
#                                      that executable publishes and subscribes), and links to
#                                      identity_ca.cert.pem, permissions_ca.cert.pem and
#                                      governance.p7s
#
#   tools/make_keystore.sh DIR [--domain N] [--days N] [--enclave NAME PUBLISH SUBSCRIBE]...
#
#   --domain N      the one DDS domain the governance and the permissions allow (default: domains
#                   0..230, as sros2's templates: Cyclone DDS refuses a governance or permissions
#                   file naming a domain above 230, Fast DDS accepts up to 232)
#   --days N        validity of new certificates and of the permissions (default 3650)
#   --enclave NAME PUBLISH SUBSCRIBE
#                   one more enclave (NAME like /vnsba/viewer), allowed to publish and subscribe
#                   the comma-separated ROS topic names given ("-" for none); repeatable
#
# Idempotent: an existing CA, governance and enclave key and certificate are kept (delete DIR to
# start over); permissions are rewritten and signed again only when they change. Topic names are
# config/default.yaml's, as ROS 2 puts them on DDS (ros2_naming: "plan" is rt/plan): a config
# that renames topics needs enclaves made with --enclave.
set -euo pipefail
umask 077

usage() { sed -n '/^#   tools\/make_keystore.sh/,/^#                   the comma-separated/p' "$0" | sed 's/^# \{0,1\}//'; }
fail() { echo "make_keystore: error: $*" >&2; exit 2; }
command -v openssl >/dev/null || fail "openssl not found (Debian package openssl)"

dir=""
domain=""
days=3650
extra=()  # NAME PUBLISH SUBSCRIBE triples
while [ $# -gt 0 ]; do
  case "$1" in
    --domain)
      [ $# -ge 2 ] || fail "--domain needs a number"
      [[ "$2" =~ ^[0-9]+$ ]] && [ "$2" -le 232 ] || fail "--domain: found '$2', expected 0..232"
      domain="$2"; shift ;;
    --days)
      [ $# -ge 2 ] || fail "--days needs a number"
      [[ "$2" =~ ^[1-9][0-9]*$ ]] || fail "--days: found '$2', expected a whole number > 0"
      days="$2"; shift ;;
    --enclave)
      [ $# -ge 4 ] || fail "--enclave needs NAME PUBLISH SUBSCRIBE"
      extra+=("$2" "$3" "$4"); shift 3 ;;
    -h|--help) usage; exit 0 ;;
    -*) fail "unknown option '$1' (see --help)" ;;
    *) [ -z "$dir" ] || fail "one DIR only (found '$dir' and '$1')"; dir="$1" ;;
  esac
  shift
done
[ -n "$dir" ] || { usage >&2; exit 2; }

mkdir -p "$dir"
dir="$(cd "$dir" && pwd)"  # absolute: the script may run from anywhere
mkdir -p "$dir/public" "$dir/private" "$dir/enclaves"

if [ -n "$domain" ]; then
  domains_xml="<id>$domain</id>"
else
  domains_xml="<id_range><min>0</min><max>230</max></id_range>"
fi

# An EC P-256 key (what SROS2 makes; Fast DDS's PKI-DH signs with ECDSA-SHA256).
new_key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }
# A link that points where it should, made again if it does not.
link() {  # TARGET LINK
  if [ "$(readlink "$2" 2>/dev/null || true)" != "$1" ]; then
    rm -f "$2"
    ln -s "$1" "$2"
  fi
}
# S/MIME, detached, text: what SROS2 writes and Fast DDS's Access-Permissions plugin verifies.
sign() {  # IN OUT
  openssl smime -sign -text -in "$1" -out "$2.tmp" \
    -signer "$dir/public/ca.cert.pem" -inkey "$dir/private/ca.key.pem"
  mv "$2.tmp" "$2"
}

# The CA.
if [ ! -f "$dir/public/ca.cert.pem" ] || [ ! -f "$dir/private/ca.key.pem" ]; then
  new_key "$dir/private/ca.key.pem"
  openssl req -new -x509 -sha256 -key "$dir/private/ca.key.pem" -out "$dir/public/ca.cert.pem" \
    -days "$days" -subj "/CN=vnsba keystore CA" \
    -addext "basicConstraints=critical,CA:true,pathlen:1"
  echo "make_keystore: new CA in $dir/public/ca.cert.pem"
fi
chmod 644 "$dir/public/ca.cert.pem"
for role in identity_ca permissions_ca; do
  link ca.cert.pem "$dir/public/$role.cert.pem"
  link ca.key.pem "$dir/private/$role.key.pem"
done

# The governance document: every topic's discovery, liveliness and data encrypted (metadata too),
# read and write access control on every topic; RTPS messages as a whole are signed (their
# contents are encrypted at the levels above: encrypting them again would only cost time).
governance="$dir/enclaves/governance.xml"
if [ ! -f "$governance" ]; then
  cat >"$governance" <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>$domains_xml</domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF
  rm -f "$dir/enclaves/governance.p7s"
fi
[ -f "$dir/enclaves/governance.p7s" ] || sign "$governance" "$dir/enclaves/governance.p7s"
chmod 644 "$governance" "$dir/enclaves/governance.p7s"

# "plan,/tf" -> <topic>rt/plan</topic><topic>rt/tf</topic> (ROS 2's DDS names). A name that
# already has a DDS prefix (rq/, rr/: a service's request and reply) is taken as it is.
topics_xml() {
  local list="$1" out="" t
  [ "$list" = "-" ] && return 0
  IFS=',' read -r -a names <<<"$list"
  for t in "${names[@]}"; do
    [[ "$t" =~ ^/?[A-Za-z_][A-Za-z0-9_/]*$ ]] || fail "topic '$t': expected a ROS topic name"
    if [[ "$t" =~ ^(rq|rr)/ ]]; then out+="<topic>$t</topic>"; else out+="<topic>rt/${t#/}</topic>"; fi
  done
  printf '%s' "$out"
}

# The DDS topics of ROS 2 action NAME on one side (rcl_action): "server out", "server in",
# "client out" or "client in". Requests go rq/<name>/_action/<service>Request, replies
# rr/.../<service>Reply; the status and feedback topics are the server's.
action_topics() {
  local name="$1" side="$2" s out=""
  for s in send_goal get_result cancel_goal; do
    case "$side" in
      "server out" | "client in") out+=",rr/$name/_action/${s}Reply" ;;
      "server in" | "client out") out+=",rq/$name/_action/${s}Request" ;;
    esac
  done
  case "$side" in "server out" | "client in") out+=",$name/_action/status,$name/_action/feedback" ;; esac
  printf '%s' "${out#,}"
}

# The DDS topics of ROS 2 service NAME on one side: "server out" or "client in" its reply
# rr/<name>Reply, "server in" or "client out" its request rq/<name>Request.
service_topics() {
  case "$2" in
    "server out" | "client in") printf 'rr/%sReply' "$1" ;;
    "server in" | "client out") printf 'rq/%sRequest' "$1" ;;
  esac
}

# The subject of a certificate as DDS Security compares it (RFC 2253: "CN=/vnsba/node").
subject_of() { openssl x509 -in "$1" -noout -subject -nameopt RFC2253 | sed 's/^subject=//'; }

# A subject "/CN=NAME/serialNumber=NNNNNNNN" (the smallest such 8-digit number) whose SHA-256 (of
# its DER encoding) starts with 12 one bits. Why: DDS Security makes a participant's GUID prefix
# from that hash (its first bit set, then the hash's first 47 bits), and of two participants the
# one with the smaller GUID starts the authentication handshake. Fast DDS 2.9 starts it with a
# DH+MODP-2048-256 key in an encoding Cyclone DDS 0.10 cannot read; started by Cyclone (ECDH, with
# an EC identity as here) it completes. So our Fast DDS executables' identities sort above nearly
# every other; a Cyclone DDS peer whose identity still sorts higher (about 1 in 4,000 with a plain
# "CN=name" subject as sros2 makes them) cannot authenticate with them. Deterministic: the same
# NAME always gets the same number. The candidates are hashed by coreutils' sha256sum.
high_sorting_subject() {  # NAME
  local name="$1" tmp start found=""
  # The DER below uses one-byte lengths: the whole name must stay under 128 bytes.
  [ "${#name}" -le 97 ] || fail "enclave '$name': longer than the 97 characters this script orders"
  # In memory where there is /dev/shm: thousands of 50-byte files.
  tmp="$(mktemp -d -p "$([ -w /dev/shm ] && echo /dev/shm || echo "${TMPDIR:-/tmp}")")"
  start=0
  while [ -z "$found" ] && [ "$start" -lt 100000000 ]; do
    # DER: SEQUENCE { SET { SEQUENCE { OID commonName, UTF8String NAME } },
    #                 SET { SEQUENCE { OID serialNumber, PrintableString 8 digits } } }
    LC_ALL=C awk -v dir="$tmp" -v start="$start" -v count=1024 -v name="$name" 'BEGIN {
      n = length(name)
      der = sprintf("%c%c%c%c%c%c%c%c%c%c%c%c%c%s%c%c%c%c%c%c%c%c%c%c%c",
                    48, 30 + n, 49, 9 + n, 48, 7 + n, 6, 3, 85, 4, 3, 12, n, name,
                    49, 17, 48, 15, 6, 3, 85, 4, 5, 19, 8)
      for (i = 0; i < count; ++i) {
        f = sprintf("%s/%08d", dir, start + i)
        printf "%s%08d", der, start + i > f
        close(f)
      }
    }'
    found="$(cd "$tmp" && sha256sum -- * | awk '/^fff/ { print $2; exit }')"
    rm -f "$tmp"/*
    start=$((start + 1024))
  done
  rmdir "$tmp"
  [ -n "$found" ] || fail "no ordering serial number found for '$name'"
  printf '/CN=%s/serialNumber=%s' "${name//\//\\/}" "$found"
}

# An ISO 8601 time (UTC) from an openssl date ("Jun  1 16:57:53 2034 GMT").
iso_date() { date -u -d "$1" +%Y-%m-%dT%H:%M:%S; }

enclave() {  # NAME PUBLISH SUBSCRIBE [ordered]
  local name="$1" subject
  [[ "$name" =~ ^(/[A-Za-z_][A-Za-z0-9_]*)+$ ]] || fail "enclave '$name': expected a name like /vnsba/node"
  local d="$dir/enclaves${name}"
  local up
  mkdir -p "$d"
  up="$(realpath --relative-to="$d" "$dir")"
  # The subject is the enclave name, as SROS2 has it (its '/' escaped for -subj); for our own
  # executables ("ordered") with a serial number that makes it sort high (see above).
  # An ordered enclave's certificate from an older keystore (a plain "CN=name") is made again,
  # with the same key.
  if [ "${4:-}" = ordered ] && [ -f "$d/cert.pem" ] &&
    [[ "$(subject_of "$d/cert.pem")" != serialNumber=* ]]; then
    rm -f "$d/cert.pem"
  fi
  if [ ! -f "$d/cert.pem" ] || [ ! -f "$d/key.pem" ]; then
    [ -f "$d/key.pem" ] || new_key "$d/key.pem"
    if [ "${4:-}" = ordered ]; then
      subject="$(high_sorting_subject "$name")"
    else
      subject="/CN=${name//\//\\/}"
    fi
    openssl req -new -sha256 -key "$d/key.pem" -subj "$subject" |
      openssl x509 -req -sha256 -days "$days" -CA "$dir/public/ca.cert.pem" \
        -CAkey "$dir/private/ca.key.pem" -set_serial "0x$(openssl rand -hex 16)" \
        -extfile <(printf 'basicConstraints=critical,CA:false\n') -out "$d/cert.pem" 2>/dev/null
    chmod 644 "$d/cert.pem"
  fi
  link "$up/public/identity_ca.cert.pem" "$d/identity_ca.cert.pem"
  link "$up/public/permissions_ca.cert.pem" "$d/permissions_ca.cert.pem"
  link "$up/enclaves/governance.p7s" "$d/governance.p7s"

  local publish subscribe not_before not_after
  publish="$(topics_xml "$2")"
  subscribe="$(topics_xml "$3")"
  not_before="$(iso_date "$(openssl x509 -in "$d/cert.pem" -noout -startdate | cut -d= -f2)")"
  not_after="$(iso_date "$(openssl x509 -in "$d/cert.pem" -noout -enddate | cut -d= -f2)")"
  local xml="$d/permissions.xml.new"
  {
    echo '<?xml version="1.0" encoding="UTF-8"?>'
    echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
    echo '    xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
    echo '  <permissions>'
    echo "    <grant name=\"$name\">"
    echo "      <subject_name>$(subject_of "$d/cert.pem")</subject_name>"
    echo "      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>"
    echo '      <allow_rule>'
    echo "        <domains>$domains_xml</domains>"
    [ -z "$publish" ] || echo "        <publish><topics>$publish</topics></publish>"
    [ -z "$subscribe" ] || echo "        <subscribe><topics>$subscribe</topics></subscribe>"
    echo '      </allow_rule>'
    echo '      <default>DENY</default>'
    echo '    </grant>'
    echo '  </permissions>'
    echo '</dds>'
  } >"$xml"
  if [ -f "$d/permissions.p7s" ] && cmp -s "$xml" "$d/permissions.xml"; then
    rm -f "$xml"
  else
    mv "$xml" "$d/permissions.xml"
    sign "$d/permissions.xml" "$d/permissions.p7s"
    echo "make_keystore: enclave $name"
  fi
  chmod 644 "$d/permissions.xml" "$d/permissions.p7s"
}

# What each executable publishes and subscribes with config/default.yaml's topic names.
node_out="plan,plan_status,planner_debug,plan_raw,plan_pruned"
node_out+=",planner_expansions_forward,planner_expansions_backward,planner_meeting_point"
node_in="projected_map,goal_pose,robot_pose,plan_request,tf,tf_static,clock"
# Nav2's planner actions (actions.enabled): the node serves them, vnsba_send_goal --action calls.
send_goal_out="plan_request" send_goal_in="plan_status"
for action in compute_path_to_pose compute_path_through_poses; do
  node_out+=",$(action_topics "$action" "server out")"
  node_in+=",$(action_topics "$action" "server in")"
  send_goal_out+=",$(action_topics "$action" "client out")"
  send_goal_in+=",$(action_topics "$action" "client in")"
done
# is_path_valid (nav2_msgs/srv/IsPathValid) and, under the node's name (node_name: vnsba_node),
# its lifecycle services and transition_event; the bond's heartbeats go both ways. vnsba_send_goal
# calls is_path_valid; vnsba_lifecycle (the same enclave) plays the lifecycle manager.
services="is_path_valid"
for s in change_state get_state get_available_states get_available_transitions; do
  services+=" vnsba_node/$s"
done
for s in $services; do
  node_out+=",$(service_topics "$s" "server out")"
  node_in+=",$(service_topics "$s" "server in")"
  send_goal_out+=",$(service_topics "$s" "client out")"
  send_goal_in+=",$(service_topics "$s" "client in")"
done
node_out+=",vnsba_node/transition_event,bond" node_in+=",bond"
send_goal_out+=",bond" send_goal_in+=",vnsba_node/transition_event,bond"
enclave /vnsba/node "$node_out" "$node_in" ordered
enclave /vnsba/slicer projected_map octomap_binary ordered
enclave /vnsba/recorder - "projected_map,plan_request,goal_pose,robot_pose,plan,plan_status,planner_debug" ordered
enclave /vnsba/send_goal "$send_goal_out" "$send_goal_in" ordered
for ((i = 0; i < ${#extra[@]}; i += 3)); do
  enclave "${extra[i]}" "${extra[i + 1]}" "${extra[i + 2]}"
done
echo "make_keystore: keystore ready in $dir"
