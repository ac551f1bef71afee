// Why DDS Security refused something, said after the fact; neither decides anything.
// - diagnose_enclave (security.hpp): after Fast DDS refused a secured participant of ours, the
//   checks its PKI-DH and Access-Permissions plugins make on local files, repeated with the same
//   OpenSSL calls, only to name the file at fault.
// - RefusedPeers (refused_peers.hpp): the remote participants Fast DDS keeps out, one warning
//   each, with the reason Fast DDS logged.
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <deque>
#include <fastdds/dds/log/Log.hpp>
#include <filesystem>
#include <memory>
#include <sstream>

#include "vnsba/node/convert.hpp"
#include "vnsba/node/dds.hpp"
#include "vnsba/node/refused_peers.hpp"
#include "vnsba/node/security.hpp"
#include "vnsba/node/service_wire.hpp"

namespace vnsba::node {

namespace {

namespace fs = std::filesystem;

template <class T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const { Free(p); }
};
using X509Ptr = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using KeyPtr = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using BioPtr = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;
using Pkcs7Ptr = std::unique_ptr<PKCS7, Deleter<PKCS7, PKCS7_free>>;
using StorePtr = std::unique_ptr<X509_STORE, Deleter<X509_STORE, X509_STORE_free>>;
using StoreContextPtr =
    std::unique_ptr<X509_STORE_CTX, Deleter<X509_STORE_CTX, X509_STORE_CTX_free>>;

// OpenSSL's last error in words (and the queue cleared), or `fallback`.
std::string openssl_error(const char* fallback) {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return fallback;
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return text;
}

X509Ptr read_certificate(const fs::path& path) {
  BioPtr in(BIO_new_file(path.c_str(), "r"));
  return X509Ptr(in ? PEM_read_bio_X509(in.get(), nullptr, nullptr, nullptr) : nullptr);
}

// "" when `certificate` is valid now, else why not.
std::string validity_problem(X509* certificate) {
  if (X509_cmp_current_time(X509_get0_notAfter(certificate)) < 0) return "expired";
  if (X509_cmp_current_time(X509_get0_notBefore(certificate)) > 0) return "not valid yet";
  return "";
}

// "" when `certificate` verifies against `ca` (signature, validity, chain), else why not.
std::string verify_problem(X509* certificate, X509* ca) {
  StorePtr store(X509_STORE_new());
  StoreContextPtr context(X509_STORE_CTX_new());
  if (!store || !context || X509_STORE_add_cert(store.get(), ca) != 1 ||
      X509_STORE_CTX_init(context.get(), store.get(), certificate, nullptr) != 1)
    return openssl_error("cannot set up the verification");
  if (X509_verify_cert(context.get()) == 1) return "";
  const int error = X509_STORE_CTX_get_error(context.get());
  ERR_clear_error();
  return X509_verify_cert_error_string(error);
}

// "" when the S/MIME document at `path` verifies against `ca` as Fast DDS verifies it, else why.
std::string smime_problem(const fs::path& path, X509* ca) {
  BioPtr in(BIO_new_file(path.c_str(), "r"));
  BIO* content = nullptr;
  Pkcs7Ptr pkcs7(in ? SMIME_read_PKCS7(in.get(), &content) : nullptr);
  BioPtr content_owner(content);
  if (!pkcs7) return "not an S/MIME signed document (" + openssl_error("unreadable") + ")";
  StorePtr store(X509_STORE_new());
  if (!store || X509_STORE_add_cert(store.get(), ca) != 1)
    return openssl_error("cannot set up the verification");
  BioPtr out(BIO_new(BIO_s_mem()));
  if (PKCS7_verify(pkcs7.get(), nullptr, store.get(), content, out.get(), PKCS7_TEXT) == 1)
    return "";
  return "its signature does not verify against permissions_ca.cert.pem (tampered with, or "
         "signed by another CA: " +
         openssl_error("verification failed") + ")";
}

}  // namespace

std::vector<std::string> diagnose_enclave(const SecurityPlan& plan) {
  std::vector<std::string> found;
  const fs::path directory(plan.enclave_directory);
  auto fault = [&](const char* file, const std::string& why) {
    found.push_back((directory / file).string() + ": " + why);
  };
  ERR_clear_error();

  // The two CAs: each must parse and be valid now.
  X509Ptr identity_ca = read_certificate(directory / "identity_ca.cert.pem");
  X509Ptr permissions_ca = read_certificate(directory / "permissions_ca.cert.pem");
  for (const auto& [file, ca] : {std::pair{"identity_ca.cert.pem", identity_ca.get()},
                                 std::pair{"permissions_ca.cert.pem", permissions_ca.get()}}) {
    if (ca == nullptr)
      fault(file, "not a PEM certificate (" + openssl_error("unreadable") + ")");
    else if (const std::string why = validity_problem(ca); !why.empty())
      fault(file, "the CA certificate is " + why);
  }

  // The identity: cert.pem signed by the identity CA and valid, key.pem its private key.
  X509Ptr certificate = read_certificate(directory / "cert.pem");
  if (certificate == nullptr) {
    fault("cert.pem", "not a PEM certificate (" + openssl_error("unreadable") + ")");
  } else if (identity_ca != nullptr) {
    if (const std::string why = verify_problem(certificate.get(), identity_ca.get()); !why.empty())
      fault("cert.pem", "does not verify against identity_ca.cert.pem: " + why);
  }
  BioPtr key_in(BIO_new_file((directory / "key.pem").c_str(), "r"));
  KeyPtr key(key_in ? PEM_read_bio_PrivateKey(key_in.get(), nullptr, nullptr, nullptr) : nullptr);
  if (key == nullptr) {
    fault("key.pem",
          "not a PEM private key without a passphrase (" + openssl_error("unreadable") + ")");
  } else if (certificate != nullptr && X509_check_private_key(certificate.get(), key.get()) != 1) {
    ERR_clear_error();
    fault("key.pem", "is not the private key of cert.pem");
  }

  // Governance and permissions: S/MIME signed by the permissions CA.
  if (permissions_ca != nullptr) {
    for (const char* file : {"governance.p7s", "permissions.p7s"}) {
      if (const std::string why = smime_problem(directory / file, permissions_ca.get());
          !why.empty())
        fault(file, why);
    }
  }
  ERR_clear_error();
  return found;
}

// ---------------------------------------------------------------------------------------------
// Remote participants refused.

namespace {

using eprosima::fastdds::dds::Log;
using Steady = std::chrono::steady_clock;

// Fast DDS's security warnings and errors, newest last, with when they were consumed.
struct SecurityLine {
  Steady::time_point at;
  std::string text;  // "SECURITY_AUTHENTICATION: Invalidation error of certificate ..."
};
std::mutex security_lines_mutex;
std::deque<SecurityLine> security_lines;  // under security_lines_mutex, at most kKeptLines
constexpr size_t kKeptLines = 64;
std::atomic<bool> reason_log_installed{false};

class SecurityReasonLog : public eprosima::fastdds::dds::LogConsumer {
 public:
  ~SecurityReasonLog() override { reason_log_installed = false; }  // Log::ClearConsumers
  void Consume(const Log::Entry& entry) override {
    const std::string category = entry.context.category != nullptr ? entry.context.category : "";
    if (entry.kind == Log::Info || category.rfind("SECURITY", 0) != 0) return;
    std::lock_guard<std::mutex> lock(security_lines_mutex);
    security_lines.push_back({Steady::now(), category + ": " + entry.message});
    if (security_lines.size() > kKeptLines) security_lines.pop_front();
  }
};

// The security lines Fast DDS logged since `since` (all of them consumed first) that contain
// `needle` ("" for any), newest last.
std::vector<std::string> security_lines_since(Steady::time_point since, const std::string& needle) {
  Log::Flush();
  std::vector<std::string> found;
  std::lock_guard<std::mutex> lock(security_lines_mutex);
  for (const SecurityLine& line : security_lines)
    if (line.at >= since && line.text.find(needle) != std::string::npos) found.push_back(line.text);
  return found;
}

VendorId vendor_of(const eprosima::fastrtps::rtps::ParticipantProxyData& data) {
  return {data.m_VendorId[0], data.m_VendorId[1]};
}

// How a remote participant announced itself: its name, and its certificate's and CA's subjects
// from its identity token, or that it has none (an unsecured participant).
std::string announced(const eprosima::fastrtps::rtps::ParticipantProxyData& data) {
  const std::string name = printable(data.m_participantName.to_string());
  std::string out = (name.empty() ? std::string("no participant name") : "'" + name + "'") +
                    " on " + vendor_name(vendor_of(data));
  std::string certificate, ca;
  // X509_NAME_oneline's subjects ("/CN=\/vnsba\/node"), shown without its escapes.
  auto subject = [](std::string text) {
    for (size_t at = 0; (at = text.find("\\/", at)) != std::string::npos;) text.erase(at, 1);
    return printable(text);
  };
  for (const auto& property : data.identity_token_.properties()) {
    if (property.name() == "dds.cert.sn") certificate = subject(property.value());
    if (property.name() == "dds.ca.sn") ca = subject(property.value());
  }
  if (data.identity_token_.class_id().empty()) return out + ", no DDS Security identity";
  // A token without the subjects (Cyclone DDS's carries its class only): said so, never blank.
  auto named = [](const std::string& subject) {
    return subject.empty() ? std::string("(subject not in its identity token)") : subject;
  };
  return out + ", certificate " + named(certificate) + " of CA " + named(ca);
}

constexpr const char* kWithoutSecurity =
    "it runs without DDS Security, which this participant's governance refuses";

std::string seconds_text(std::chrono::milliseconds duration) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", duration.count() / 1000.0);
  return text;
}

}  // namespace

void install_security_reason_log() {
  if (!reason_log_installed.exchange(true))
    Log::RegisterConsumer(std::make_unique<SecurityReasonLog>());
}

RefusedPeers::RefusedPeers(std::chrono::milliseconds handshake_timeout)
    : timeout_(handshake_timeout), watcher_([this] { watch(); }) {
  install_security_reason_log();
}

RefusedPeers::~RefusedPeers() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  watcher_.join();
}

void RefusedPeers::on_participant_discovery(
    const eprosima::fastdds::dds::DomainParticipant* local,
    const eprosima::fastrtps::rtps::ParticipantDiscoveryInfo& info) {
  using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
  const std::string prefix = guid_prefix_text(info.info.m_guid.guidPrefix);
  std::lock_guard<std::mutex> lock(mutex_);
  if (!secured_ && local != nullptr) {
    // The authentication plugin is a property of the participant's QoS (security.cpp sets it).
    const auto& properties = local->get_qos().properties().properties();
    secured_ = std::any_of(properties.begin(), properties.end(), [](const auto& p) {
      return p.name() == "dds.sec.auth.plugin" && !p.value().empty();
    });
  }
  if (secured_ == false) return;
  if (info.status != Status::DISCOVERED_PARTICIPANT) {
    if (info.status != Status::CHANGED_QOS_PARTICIPANT) pending_.erase(prefix);  // it left
    return;
  }
  if (reported_.count(prefix) > 0 || pending_.count(prefix) > 0) return;
  if (pending_.size() >= kMaxPending) {
    if (!flooded_)
      spdlog::warn(
          "security: more than {} remote participants waiting for authentication at once; "
          "those beyond are not followed (refusals of them are not logged)",
          kMaxPending);
    flooded_ = true;
    return;
  }
  // Of two participants the one with the smaller GUID starts the handshake (DDS Security 1.1,
  // 9.3.2; both vendors' PKI-DH plugins).
  const bool cyclone = vendor_of(info.info) == kVendorCyclone;
  const bool we_start = local != nullptr && local->guid().guidPrefix < info.info.m_guid.guidPrefix;
  pending_[prefix] = {announced(info.info), !info.info.identity_token_.class_id().empty(),
                      cyclone && we_start, Steady::now() + timeout_};
  wake_.notify_all();
}

void RefusedPeers::on_participant_authentication(
    const eprosima::fastrtps::rtps::ParticipantAuthenticationInfo& info) {
  using Status = eprosima::fastrtps::rtps::ParticipantAuthenticationInfo;
  const std::string prefix = guid_prefix_text(info.guid.guidPrefix);
  Pending remote{"not announced", true, false, {}};
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = pending_.find(prefix);
    if (it != pending_.end()) {
      remote = it->second;
      pending_.erase(it);
    }
    if (info.status == Status::AUTHORIZED_PARTICIPANT) {
      // Reported after the timeout, yet authenticated: the record is put right.
      if (reported_.erase(prefix) > 0)
        spdlog::info("security: remote participant {} authenticated after all", prefix);
      return;
    }
    if (reported_.count(prefix) > 0) return;
  }
  // Fast DDS logged why on this thread just before calling (its certificate check logs at
  // warning level, which reaches consumers only when the process's Fast DDS verbosity is
  // Warning or lower; errors always do): the newest security line is it.
  const std::vector<std::string> lines =
      security_lines_since(Steady::now() - std::chrono::seconds(1), "");
  report(prefix, remote.announced,
         (remote.has_identity ? "this participant checked its certificate and handshake and "
                                "refused them (a certificate of another CA, expired or not yet "
                                "valid, or a handshake that does not verify)"
                              : std::string(kWithoutSecurity)) +
             (lines.empty() ? std::string() : "; Fast DDS: " + printable(lines.back(), 512)));
}

void RefusedPeers::report(const std::string& prefix, const std::string& remote,
                          const std::string& why) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (reported_.size() >= kMaxReported) {
      if (!flooded_)
        spdlog::warn("security: more than {} remote participants refused; no more are logged",
                     kMaxReported);
      flooded_ = true;
      return;
    }
    if (!reported_.insert(prefix).second) return;
  }
  spdlog::warn("security: refused remote participant {} ({}): {}", prefix, remote, why);
}

void RefusedPeers::watch() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    const Steady::time_point now = Steady::now();
    std::vector<std::pair<std::string, Pending>> expired;  // by GUID prefix
    Steady::time_point next = Steady::time_point::max();
    for (auto it = pending_.begin(); it != pending_.end();) {
      if (it->second.deadline <= now) {
        expired.emplace_back(it->first, it->second);
        it = pending_.erase(it);
      } else {
        next = std::min(next, it->second.deadline);
        ++it;
      }
    }
    if (!expired.empty()) {
      lock.unlock();
      for (const auto& [prefix, remote] : expired) {
        // Fast DDS names the remote's GUID in the lines of a refusal after authentication
        // (permissions); a handshake the remote never answered leaves nothing.
        const std::vector<std::string> lines =
            security_lines_since(Steady::now() - 2 * timeout_, prefix);
        std::string why = "not authenticated " + seconds_text(timeout_) + " after its discovery: ";
        if (!lines.empty())
          why += printable(lines.back(), 512);
        else if (!remote.has_identity)
          why += kWithoutSecurity;
        else if (remote.cyclone_waits_for_us)
          why +=
              "it is a Cyclone DDS participant whose GUID prefix sorts above this one's, so this "
              "participant started the handshake, and Fast DDS 2.9 starts it with a "
              "DH+MODP-2048-256 key in an encoding Cyclone DDS 0.10 cannot read (Cyclone started "
              "handshakes complete); identities from tools/make_keystore.sh sort first, see "
              "docs/security.md";
        else
          why +=
              "it has not answered this participant's handshake (it refuses this participant's "
              "certificate, e.g. one of another CA), or its governance differs";
        report(prefix, remote.announced, why);
      }
      lock.lock();
      continue;
    }
    if (next == Steady::time_point::max())
      wake_.wait(lock);
    else
      wake_.wait_until(lock, next);
  }
}

}  // namespace vnsba::node
