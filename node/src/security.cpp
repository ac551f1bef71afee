#include "vnsba/node/security.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace vnsba::node {

namespace fs = std::filesystem;

std::string enclave_name_problem(const std::string& name) {
  const std::string expected =
      "an enclave name such as /vnsba/node ('/' then parts of letters, digits and '_', none "
      "starting with a digit)";
  if (name == "/") return "";
  if (name.empty() || name.front() != '/' || name.back() == '/') return expected;
  bool part_start = true;
  for (size_t i = 1; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (c == '/') {
      if (part_start) return expected;  // "//"
      part_start = true;
      continue;
    }
    if (!(std::isalnum(c) || c == '_') || c >= 0x80) return expected;
    if (part_start && std::isdigit(c)) return expected;
    part_start = false;
  }
  return "";
}

core::Expected<std::vector<std::string>> apply_security_environment(
    SecurityConfig& security, const Environment& environment) {
  std::vector<std::string> applied;
  auto value_of = [&](const char* variable) -> std::string {
    const char* value = environment ? environment(variable) : nullptr;
    return value != nullptr ? value : "";
  };
  if (const std::string v = value_of("ROS_SECURITY_ENABLE"); v == "true") {
    security.enable = true;
    applied.push_back("ROS_SECURITY_ENABLE=true: security on");
  } else if (!v.empty() && !security.enable) {
    applied.push_back("ROS_SECURITY_ENABLE=" + v + " is not \"true\": security stays off");
  }
  if (const std::string v = value_of("ROS_SECURITY_STRATEGY"); !v.empty()) {
    security.strategy = v == "Enforce" ? SecurityStrategy::kEnforce : SecurityStrategy::kPermissive;
    applied.push_back(
        "ROS_SECURITY_STRATEGY=" + v + ": " +
        (v == "Enforce" ? "Enforce" : "Permissive (anything but \"Enforce\", as SROS2)"));
  }
  if (const std::string v = value_of("ROS_SECURITY_KEYSTORE"); !v.empty()) {
    security.keystore = v;
    applied.push_back("ROS_SECURITY_KEYSTORE=" + v);
  }
  for (const char* variable : {"ROS_SECURITY_ENCLAVE_OVERRIDE", "ROS_SECURITY_ENCLAVE"}) {
    const std::string v = value_of(variable);
    if (v.empty()) continue;
    if (const std::string problem = enclave_name_problem(v); !problem.empty()) {
      return core::Status::error(
          core::StatusCode::kInvalidRequest,
          std::string(variable) + ": found \"" + v + "\", expected " + problem);
    }
    security.enclave = v;
    applied.push_back(std::string(variable) + "=" + v);
    break;  // the override wins, as in rcl
  }
  return applied;
}

SecurityConfig with_default_enclave(SecurityConfig security, const std::string& default_enclave) {
  if (security.enclave.empty()) security.enclave = default_enclave;
  return security;
}

namespace {

std::string join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

// "" when `path` is a readable regular file (links followed), else why not.
std::string unreadable(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::is_regular_file(status)) return "is not a regular file";
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::string("cannot be read (") + std::strerror(errno) + ")";
  if (in.peek() == std::ifstream::traits_type::eof()) return "is empty";
  return "";
}

}  // namespace

core::Expected<SecurityPlan> plan_security(const SecurityConfig& security) {
  SecurityPlan plan;
  if (!security.enable) return plan;
  plan.enclave = security.enclave;
  const bool enforce = security.strategy == SecurityStrategy::kEnforce;
  // Enforce: an error. Permissive: an open participant and a note saying why.
  auto refuse_or_open = [&](const std::string& why) -> core::Expected<SecurityPlan> {
    if (enforce) {
      return core::Status::error(
          core::StatusCode::kInvalidRequest,
          "security (strategy Enforce): " + why + "; refusing to run without it");
    }
    plan.notes.push_back("security (strategy Permissive): " + why +
                         "; running WITHOUT security (Enforce would stop here)");
    return plan;
  };
  if (security.keystore.empty())
    return refuse_or_open("no keystore: set security.keystore or ROS_SECURITY_KEYSTORE");
  if (const std::string problem = enclave_name_problem(security.enclave); !problem.empty()) {
    return core::Status::error(
        core::StatusCode::kInvalidRequest,
        "security.enclave: found \"" + security.enclave + "\", expected " + problem);
  }
  std::error_code ec;
  fs::path directory = fs::absolute(fs::path(security.keystore) / "enclaves", ec);
  if (security.enclave != "/") directory /= security.enclave.substr(1);
  directory = directory.lexically_normal();
  plan.enclave_directory = directory.string();
  const std::string which = "enclave '" + security.enclave + "' of keystore '" + security.keystore +
                            "' (security.keystore, ROS_SECURITY_KEYSTORE)";
  if (!fs::is_directory(directory, ec))
    return refuse_or_open(which + ": no directory " + plan.enclave_directory);

  std::vector<std::string> missing, bad;
  for (const EnclaveFile& file : kEnclaveFiles) {
    const fs::path path = directory / file.name;
    if (!fs::exists(path, ec)) {
      missing.push_back(
          path.string() +
          (fs::is_symlink(path, ec)
               ? " (a link to " + fs::read_symlink(path, ec).string() + ", which does not exist)"
               : ""));
    } else if (const std::string why = unreadable(path); !why.empty()) {
      bad.push_back(path.string() + " " + why);
    }
    plan.properties.emplace_back(file.property, "file://" + path.string());
  }
  if (!bad.empty()) {
    for (const std::string& m : missing) bad.push_back(m + " is missing");
    return core::Status::error(core::StatusCode::kInvalidRequest,
                               "security: " + which + ": " + join(bad, "; "));
  }
  if (!missing.empty()) return refuse_or_open(which + ": missing " + join(missing, ", "));

  // As rmw_fastrtps sets them for an SROS2 enclave.
  plan.properties.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  plan.properties.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  plan.properties.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  plan.secured = true;
  return plan;
}

std::string security_failure_message(const SecurityPlan& plan,
                                     const std::vector<std::string>& diagnosis,
                                     const std::vector<std::string>& fastdds_messages) {
  std::string message = "security: Fast DDS refused the secured participant of enclave '" +
                        plan.enclave + "' (" + plan.enclave_directory + "): ";
  if (!diagnosis.empty()) {
    message += join(diagnosis, "; ");
  } else {
    std::vector<std::string> all;
    for (const EnclaveFile& file : kEnclaveFiles)
      all.push_back((fs::path(plan.enclave_directory) / file.name).string());
    message += "check its files (" + join(all, ", ") +
               "): a certificate, key, governance or permissions that Fast DDS does not accept "
               "(e.g. permissions for another subject, domain or time)";
  }
  if (!fastdds_messages.empty()) message += ". Fast DDS said: " + join(fastdds_messages, " | ");
  return message;
}

}  // namespace vnsba::node
