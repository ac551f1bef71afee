// diagnose_enclave (security.hpp): after Fast DDS refused a secured participant, the checks its
// PKI-DH and Access-Permissions plugins make on local files, repeated with the same OpenSSL
// calls, only to name the file at fault. It decides nothing: the participant was refused
// already.
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>

#include <filesystem>
#include <memory>

#include "vnsba/node/security.hpp"

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

}  // namespace vnsba::node
