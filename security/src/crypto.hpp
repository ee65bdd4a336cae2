// OpenSSL (libcrypto 3) behind a few calls: EC keys, X.509 certificates, S/MIME signatures.
// Private to horus_security; every failure is a Result naming what failed and OpenSSL's reason.
#pragma once

#include <openssl/evp.h>
#include <openssl/x509.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "horus/error.hpp"

namespace horus::security::crypto {

struct KeyFree {
  void operator()(EVP_PKEY* k) const noexcept { EVP_PKEY_free(k); }
};
struct CertFree {
  void operator()(X509* c) const noexcept { X509_free(c); }
};
using Key = std::unique_ptr<EVP_PKEY, KeyFree>;
using Cert = std::unique_ptr<X509, CertFree>;
using Clock = std::chrono::system_clock;

/// OpenSSL's queued errors as text ("error:...: reason; ..."), the queue emptied; `fallback`
/// when it is empty.
std::string openssl_errors(std::string_view fallback = "no reason given");

/// A new ECDSA key on P-256 (prime256v1), the curve DDS-Security's PKI-DH signs with.
Result<Key> new_key();

/// What a certificate says. The issuer is the CA's certificate and key, or none (self-signed:
/// `key` signs it).
struct CertSpec {
  std::string common_name;
  std::string organization;  // empty: no O=
  Clock::time_point not_before;
  Clock::time_point not_after;
  bool ca = false;  // a CA: basicConstraints CA:TRUE, and it may sign certificates and S/MIME documents
};
Result<Cert> make_certificate(const CertSpec& spec, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key);

/// PEM files. A private key is written with mode 0600 (through a file of its own, renamed into
/// place), a certificate or a document with 0644.
Result<void> write_private_key(const std::filesystem::path& file, EVP_PKEY* key);
Result<void> write_certificate(const std::filesystem::path& file, X509* cert);
Result<void> write_text(const std::filesystem::path& file, std::string_view text, bool secret = false);
Result<std::string> read_text(const std::filesystem::path& file, std::size_t max_bytes = 1 << 20);
Result<Key> read_private_key(const std::filesystem::path& file);
Result<Cert> read_certificate(const std::filesystem::path& file);

/// A certificate's subject as DDS-Security's documents write it, RFC 2253 ("CN=robot1,O=horus").
std::string subject(X509* cert);
/// The text of one field of the subject (NID_organizationName, ...); empty when absent.
std::string subject_field(X509* cert, int nid);
Clock::time_point not_before(X509* cert);
Clock::time_point not_after(X509* cert);
/// Whether `key` is the private key of `cert`.
bool key_matches(X509* cert, EVP_PKEY* key) noexcept;
/// Checks that `ca` issued `cert` and both are valid at `at`; the reason when not.
Result<void> verify_issued(X509* cert, X509* ca, Clock::time_point at);

/// An S/MIME signature (multipart/signed, detached, text/plain content) of `document` by
/// `signer` (a CA certificate) and its key: the .p7s files DDS-Security reads.
Result<std::string> smime_sign(std::string_view document, X509* signer, EVP_PKEY* key);
/// The signed document inside `smime`, after checking that `ca` signed it (at `at`).
Result<std::string> smime_verify(std::string_view smime, X509* ca, Clock::time_point at);

/// "2026-11-27 13:05:00 UTC".
std::string utc_text(Clock::time_point t);

}  // namespace horus::security::crypto
