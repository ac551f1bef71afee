// DDS Security with an SROS2 keystore, without DDS: where the settings come from (the config's
// security section and SROS2's ROS_SECURITY_* environment), which enclave directory and files a
// participant uses, and the participant properties that turn Fast DDS's builtin plugins on
// (PKI-DH, Access-Permissions, AES-GCM-GMAC), exactly as rmw_fastrtps sets them for an SROS2
// enclave. Participant::create (dds.hpp) applies them; no security code of our own.
#pragma once

#include <cstdlib>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "vnsba/core/status.hpp"
#include "vnsba/node/config.hpp"

namespace vnsba::node {

// Each executable's own enclave, used when neither security.enclave nor the environment names
// one (tools/make_keystore.sh makes these four).
inline constexpr const char* kNodeEnclave = "/vnsba/node";
inline constexpr const char* kSlicerEnclave = "/vnsba/slicer";
inline constexpr const char* kRecorderEnclave = "/vnsba/recorder";
inline constexpr const char* kSendGoalEnclave = "/vnsba/send_goal";

// "" when `name` is an enclave name ("/" or "/a/b_c": '/'-separated parts of letters, digits and
// '_', none starting with a digit), else what was expected instead.
std::string enclave_name_problem(const std::string& name);

// Looks up an environment variable (std::getenv by default; tests pass their own).
using Environment = std::function<const char*(const char*)>;

// Applies SROS2's variables to `security` (set and non-empty ones only; unset or empty leaves
// the config's value):
// - ROS_SECURITY_ENABLE: "true" turns security on (as rcl reads it); any other value leaves
//   security.enable as the config has it, so a typo never turns a secured config off;
// - ROS_SECURITY_STRATEGY: "Enforce" gives Enforce, any other value Permissive (as rcl);
// - ROS_SECURITY_KEYSTORE: the keystore directory;
// - ROS_SECURITY_ENCLAVE_OVERRIDE (rcl's name), else ROS_SECURITY_ENCLAVE: the enclave name.
// Returns one line per variable applied, for the log, or an error naming a variable whose value
// is unusable (an enclave name that is not one).
core::Expected<std::vector<std::string>> apply_security_environment(
    SecurityConfig& security, const Environment& environment = std::getenv);

// `security` with `default_enclave` where it names no enclave: each executable's call.
SecurityConfig with_default_enclave(SecurityConfig security, const std::string& default_enclave);

// The six files of an enclave, in SROS2's layout, and the property each one goes to.
struct EnclaveFile {
  const char* name;      // "key.pem"
  const char* property;  // "dds.sec.auth.builtin.PKI-DH.private_key"
};
inline constexpr EnclaveFile kEnclaveFiles[] = {
    {"identity_ca.cert.pem", "dds.sec.auth.builtin.PKI-DH.identity_ca"},
    {"cert.pem", "dds.sec.auth.builtin.PKI-DH.identity_certificate"},
    {"key.pem", "dds.sec.auth.builtin.PKI-DH.private_key"},
    {"permissions_ca.cert.pem", "dds.sec.access.builtin.Access-Permissions.permissions_ca"},
    {"governance.p7s", "dds.sec.access.builtin.Access-Permissions.governance"},
    {"permissions.p7s", "dds.sec.access.builtin.Access-Permissions.permissions"},
};

// What a participant does about security.
struct SecurityPlan {
  bool secured = false;           // false: an open participant (security off, or Permissive
                                  // without an enclave); `notes` says why when it was asked for
  std::string enclave;            // "/vnsba/node"
  std::string enclave_directory;  // absolute: <keystore>/enclaves/vnsba/node
  std::vector<std::pair<std::string, std::string>> properties;  // name, value
  std::vector<std::string> notes;  // warnings to log (Permissive running unsecured)
};

// Checks the enclave before any participant exists. Security off: an open plan. On: the keystore
// must be set and the enclave directory <keystore>/enclaves/<enclave> must hold the six files,
// each a readable regular file (symbolic links followed, as SROS2's layout has them).
// - Enforce: anything missing or unreadable is an error naming the file (every one of them) or
//   the directory, and the key or variable that set it; never an open plan.
// - Permissive (as SROS2 defines it): no keystore, no enclave directory or a missing file runs
//   unsecured, with a note naming what is missing; a file that exists but cannot be read is an
//   error all the same (rmw_fastrtps would hand it to Fast DDS, which fails).
core::Expected<SecurityPlan> plan_security(const SecurityConfig& security);

// Why the enclave's files would be refused, one line per file at fault ("<path>: <why>"):
// certificates that do not parse, are expired or not yet valid, or are not signed by the
// identity CA; a private key that does not parse or does not match cert.pem; a governance or
// permissions document whose S/MIME signature does not verify against the permissions CA. Fast
// DDS 2.9 says none of this (only "Problem creating RTPSParticipant"), so after it refuses a
// participant this repeats its checks with the same OpenSSL calls (X509_verify_cert,
// X509_check_private_key, PKCS7_verify) to name the file. Empty when every check passes.
// Defined in the node library (security_diagnosis.cpp, libcrypto).
std::vector<std::string> diagnose_enclave(const SecurityPlan& plan);

// The message for a secured participant Fast DDS refused to create: the enclave, then the files
// `diagnosis` (diagnose_enclave) names, or all six when it names none, then what Fast DDS
// logged meanwhile.
std::string security_failure_message(const SecurityPlan& plan,
                                     const std::vector<std::string>& diagnosis,
                                     const std::vector<std::string>& fastdds_messages);

}  // namespace vnsba::node
