#include "crypto.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/x509v3.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

namespace horus::security::crypto {
namespace {

struct BioFree {
  void operator()(BIO* b) const noexcept { BIO_free_all(b); }
};
struct Pkcs7Free {
  void operator()(PKCS7* p) const noexcept { PKCS7_free(p); }
};
struct StoreFree {
  void operator()(X509_STORE* s) const noexcept { X509_STORE_free(s); }
};
struct StoreCtxFree {
  void operator()(X509_STORE_CTX* s) const noexcept { X509_STORE_CTX_free(s); }
};
struct BnFree {
  void operator()(BIGNUM* b) const noexcept { BN_free(b); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

Bio memory_bio(std::string_view bytes) {
  return Bio(BIO_new_mem_buf(bytes.data(), static_cast<int>(bytes.size())));
}

std::string bio_text(BIO* bio) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio, &data);
  return n > 0 && data != nullptr ? std::string(data, static_cast<std::size_t>(n)) : std::string();
}

std::time_t to_time_t(Clock::time_point t) { return Clock::to_time_t(t); }

Clock::time_point from_asn1(const ASN1_TIME* t) {
  std::tm tm{};
  if (t == nullptr || ASN1_TIME_to_tm(t, &tm) != 1) return Clock::time_point{};
  return Clock::from_time_t(timegm(&tm));
}

Result<void> add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx(&ctx, issuer != nullptr ? issuer : cert, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (ext == nullptr || X509_add_ext(cert, ext, -1) != 1) {
    X509_EXTENSION_free(ext);
    return fail(Errc::Io, fmt::format("cannot add the certificate extension {} = '{}': {}", OBJ_nid2sn(nid), value,
                                      openssl_errors()));
  }
  X509_EXTENSION_free(ext);
  return {};
}

// Writes `bytes` to `file` through a temporary file renamed into place, with `mode`.
Result<void> write_file(const std::filesystem::path& file, std::string_view bytes, mode_t mode) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  ::unlink(tmp.c_str());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, mode);
  if (fd < 0) return fail(Errc::Io, fmt::format("cannot create '{}': {}", tmp.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      return fail(Errc::Io, fmt::format("cannot write '{}': {}", tmp.string(), std::strerror(e)));
    }
    done += static_cast<std::size_t>(n);
  }
  // The umask may have narrowed the mode; a public file is meant to be readable by all.
  if (::fchmod(fd, mode) != 0 || ::fsync(fd) != 0 || ::close(fd) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return fail(Errc::Io, fmt::format("cannot write '{}': {}", tmp.string(), std::strerror(e)));
  }
  if (::rename(tmp.c_str(), file.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return fail(Errc::Io, fmt::format("cannot rename '{}' to '{}': {}", tmp.string(), file.string(), std::strerror(e)));
  }
  return {};
}

}  // namespace

std::string openssl_errors(std::string_view fallback) {
  std::string out;
  while (const unsigned long e = ERR_get_error()) {
    char buf[256];
    ERR_error_string_n(e, buf, sizeof buf);
    if (!out.empty()) out += "; ";
    out += buf;
  }
  return out.empty() ? std::string(fallback) : out;
}

Result<Key> new_key() {
  Key key(EVP_EC_gen("P-256"));
  if (!key) return fail(Errc::Io, "cannot make an EC P-256 key: " + openssl_errors());
  return key;
}

Result<Cert> make_certificate(const CertSpec& spec, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key) {
  Cert cert(X509_new());
  if (!cert) return fail(Errc::Io, "out of memory making a certificate");
  const auto broken = [&](std::string_view what) {
    return fail(Errc::Io, fmt::format("cannot make the certificate of '{}': {}: {}", spec.common_name, what,
                                      openssl_errors()));
  };
  if (X509_set_version(cert.get(), 2) != 1) return broken("version");
  std::unique_ptr<BIGNUM, BnFree> serial(BN_new());
  if (!serial || BN_rand(serial.get(), 63, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) != 1 ||
      BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(cert.get())) == nullptr)
    return broken("serial number");
  if (ASN1_TIME_set(X509_getm_notBefore(cert.get()), to_time_t(spec.not_before)) == nullptr ||
      ASN1_TIME_set(X509_getm_notAfter(cert.get()), to_time_t(spec.not_after)) == nullptr)
    return broken("validity");
  X509_NAME* name = X509_get_subject_name(cert.get());
  const auto add = [&](const char* field, const std::string& value) {
    return X509_NAME_add_entry_by_txt(name, field, MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(value.c_str()),
                                      -1, -1, 0) == 1;
  };
  // O first, CN last: the RFC 2253 text (last field first) is then "CN=robot1,O=horus".
  if ((!spec.organization.empty() && !add("O", spec.organization)) || !add("CN", spec.common_name))
    return broken("subject name");
  if (X509_set_issuer_name(cert.get(), issuer != nullptr ? X509_get_subject_name(issuer) : name) != 1)
    return broken("issuer name");
  if (X509_set_pubkey(cert.get(), key) != 1) return broken("public key");
  if (spec.ca) {
    if (auto ok = add_extension(cert.get(), issuer, NID_basic_constraints, "critical,CA:TRUE"); !ok) return std::unexpected(ok.error());
    // digitalSignature: the permissions CA signs governance and permissions documents itself.
    if (auto ok = add_extension(cert.get(), issuer, NID_key_usage, "critical,keyCertSign,cRLSign,digitalSignature"); !ok)
      return std::unexpected(ok.error());
  } else {
    if (auto ok = add_extension(cert.get(), issuer, NID_basic_constraints, "critical,CA:FALSE"); !ok) return std::unexpected(ok.error());
    if (auto ok = add_extension(cert.get(), issuer, NID_key_usage, "critical,digitalSignature,keyAgreement"); !ok)
      return std::unexpected(ok.error());
  }
  if (auto ok = add_extension(cert.get(), issuer, NID_subject_key_identifier, "hash"); !ok) return std::unexpected(ok.error());
  if (issuer != nullptr) {
    if (auto ok = add_extension(cert.get(), issuer, NID_authority_key_identifier, "keyid:always"); !ok)
      return std::unexpected(ok.error());
  }
  if (X509_sign(cert.get(), issuer_key != nullptr ? issuer_key : key, EVP_sha256()) <= 0) return broken("signature");
  return cert;
}

Result<void> write_text(const std::filesystem::path& file, std::string_view text, bool secret) {
  return write_file(file, text, secret ? 0600 : 0644);
}

Result<void> write_private_key(const std::filesystem::path& file, EVP_PKEY* key) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_PrivateKey(out.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1)
    return fail(Errc::Io, fmt::format("cannot encode the key of '{}': {}", file.string(), openssl_errors()));
  std::string pem = bio_text(out.get());
  auto ok = write_file(file, pem, 0600);
  OPENSSL_cleanse(pem.data(), pem.size());
  return ok;
}

Result<void> write_certificate(const std::filesystem::path& file, X509* cert) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_X509(out.get(), cert) != 1)
    return fail(Errc::Io, fmt::format("cannot encode the certificate '{}': {}", file.string(), openssl_errors()));
  return write_file(file, bio_text(out.get()), 0644);
}

Result<std::string> read_text(const std::filesystem::path& file, std::size_t max_bytes) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return fail(Errc::Config, fmt::format("'{}' cannot be read: {}", file.string(), std::strerror(errno)));
  std::string text;
  char buf[8192];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      return fail(Errc::Config, fmt::format("'{}' cannot be read: {}", file.string(), std::strerror(e)));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) {
      ::close(fd);
      return fail(Errc::Config, fmt::format("'{}' is larger than {} bytes, too large for a key, certificate or "
                                            "signed document",
                                            file.string(), max_bytes));
    }
  }
  ::close(fd);
  return text;
}

Result<Key> read_private_key(const std::filesystem::path& file) {
  auto text = read_text(file);
  if (!text) return std::unexpected(text.error());
  Bio in = memory_bio(*text);
  Key key(PEM_read_bio_PrivateKey(in.get(), nullptr, nullptr, nullptr));
  OPENSSL_cleanse(text->data(), text->size());
  if (!key) return fail(Errc::Config, fmt::format("'{}' is not a PEM private key: {}", file.string(), openssl_errors()));
  return key;
}

Result<Cert> read_certificate(const std::filesystem::path& file) {
  auto text = read_text(file);
  if (!text) return std::unexpected(text.error());
  Bio in = memory_bio(*text);
  Cert cert(PEM_read_bio_X509(in.get(), nullptr, nullptr, nullptr));
  if (!cert) return fail(Errc::Config, fmt::format("'{}' is not a PEM certificate: {}", file.string(), openssl_errors()));
  return cert;
}

std::string subject(X509* cert) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!out) return {};
  // RFC 2253 ("CN=robot1,O=horus", no spaces): the one form both Cyclone DDS and Fast DDS match
  // a permissions grant's subject_name with (Fast DDS compares in this order; Cyclone refuses a
  // space after a comma).
  if (X509_NAME_print_ex(out.get(), X509_get_subject_name(cert), 0, XN_FLAG_RFC2253) < 0) return {};
  return bio_text(out.get());
}

std::string subject_field(X509* cert, int nid) {
  X509_NAME* name = X509_get_subject_name(cert);
  const int at = X509_NAME_get_index_by_NID(name, nid, -1);
  if (at < 0) return {};
  unsigned char* utf8 = nullptr;
  const int n = ASN1_STRING_to_UTF8(&utf8, X509_NAME_ENTRY_get_data(X509_NAME_get_entry(name, at)));
  if (n < 0) return {};
  std::string out(reinterpret_cast<const char*>(utf8), static_cast<std::size_t>(n));
  OPENSSL_free(utf8);
  return out;
}

Clock::time_point not_before(X509* cert) { return from_asn1(X509_get0_notBefore(cert)); }
Clock::time_point not_after(X509* cert) { return from_asn1(X509_get0_notAfter(cert)); }

bool key_matches(X509* cert, EVP_PKEY* key) noexcept { return X509_check_private_key(cert, key) == 1; }

Result<void> verify_issued(X509* cert, X509* ca, Clock::time_point at) {
  std::unique_ptr<X509_STORE, StoreFree> store(X509_STORE_new());
  std::unique_ptr<X509_STORE_CTX, StoreCtxFree> ctx(X509_STORE_CTX_new());
  if (!store || !ctx || X509_STORE_add_cert(store.get(), ca) != 1 ||
      X509_STORE_CTX_init(ctx.get(), store.get(), cert, nullptr) != 1)
    return fail(Errc::Io, "cannot check a certificate: " + openssl_errors());
  X509_STORE_CTX_set_time(ctx.get(), 0, to_time_t(at));
  if (X509_verify_cert(ctx.get()) == 1) return {};
  const int e = X509_STORE_CTX_get_error(ctx.get());
  ERR_clear_error();
  return fail(Errc::Config, X509_verify_cert_error_string(e));
}

Result<std::string> smime_sign(std::string_view document, X509* signer, EVP_PKEY* key) {
  constexpr int kFlags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  Bio in = memory_bio(document);
  std::unique_ptr<PKCS7, Pkcs7Free> p7(PKCS7_sign(signer, key, nullptr, in.get(), kFlags));
  Bio out(BIO_new(BIO_s_mem()));
  if (!p7 || !out || SMIME_write_PKCS7(out.get(), p7.get(), in.get(), kFlags) != 1)
    return fail(Errc::Io, "cannot sign the document (S/MIME): " + openssl_errors());
  return bio_text(out.get());
}

Result<std::string> smime_verify(std::string_view smime, X509* ca, Clock::time_point at) {
  Bio in = memory_bio(smime);
  BIO* content_raw = nullptr;
  std::unique_ptr<PKCS7, Pkcs7Free> p7(SMIME_read_PKCS7(in.get(), &content_raw));
  Bio content(content_raw);
  if (!p7) return fail(Errc::Config, "not an S/MIME signed document: " + openssl_errors());
  if (!content) return fail(Errc::Config, "an S/MIME signature without the document it signs (expected a detached, "
                                          "multipart/signed file)");
  std::unique_ptr<X509_STORE, StoreFree> store(X509_STORE_new());
  Bio out(BIO_new(BIO_s_mem()));
  if (!store || !out || X509_STORE_add_cert(store.get(), ca) != 1) return fail(Errc::Io, "cannot check a signature: " + openssl_errors());
  X509_VERIFY_PARAM_set_time(X509_STORE_get0_param(store.get()), to_time_t(at));
  if (PKCS7_verify(p7.get(), nullptr, store.get(), content.get(), out.get(), PKCS7_TEXT) != 1)
    return fail(Errc::Config, "its signature does not verify with the CA: " + openssl_errors());
  return bio_text(out.get());
}

std::string utc_text(Clock::time_point t) {
  const std::time_t tt = Clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

}  // namespace horus::security::crypto
