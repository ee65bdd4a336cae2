#include "horus/security/keystore.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <openssl/objects.h>

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <mutex>
#include <set>

#include "crypto.hpp"
#include "horus/log.hpp"

namespace horus::security {
namespace fs = std::filesystem;
namespace {

Result<void> make_dir(const fs::path& dir, mode_t mode) {
  std::error_code ec;
  if (dir.has_parent_path() && !dir.parent_path().empty()) fs::create_directories(dir.parent_path(), ec);
  if (::mkdir(dir.c_str(), mode) != 0 && errno != EEXIST)
    return fail(Errc::Io, fmt::format("cannot create the directory '{}': {}", dir.string(), std::strerror(errno)));
  struct stat st{};
  if (::stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    return fail(Errc::Io, fmt::format("'{}' is not a directory", dir.string()));
  return {};
}

bool file_exists(const fs::path& file) {
  std::error_code ec;
  return fs::exists(file, ec);
}

using Lines = std::vector<std::string>;

Result<void> add_line(Lines& lines, Result<void> ok, const fs::path& file, std::string_view what) {
  if (!ok) return ok;
  lines.push_back(fmt::format("wrote {} ({})", file.string(), what));
  return {};
}

struct Ca {
  crypto::Cert cert;
  crypto::Key key;
};

Result<Ca> read_ca(const fs::path& cert_file, const fs::path& key_file, std::string_view which) {
  auto cert = crypto::read_certificate(cert_file);
  if (!cert)
    return fail(Errc::Config, fmt::format("the {} CA: {} (make a keystore with `horus security keystore init DIR`)", which,
                                          cert.error().message()));
  auto key = crypto::read_private_key(key_file);
  if (!key)
    return fail(Errc::Config, fmt::format("the {} CA's key: {} (it is needed to sign; it stays on the machine that "
                                          "made the keystore)",
                                          which, key.error().message()));
  if (!crypto::key_matches(cert->get(), key->get()))
    return fail(Errc::Config, fmt::format("'{}' is not the key of '{}'", key_file.string(), cert_file.string()));
  return Ca{std::move(*cert), std::move(*key)};
}

// The text between <tag> and </tag>, or nullopt.
std::optional<std::string> element(std::string_view xml, std::string_view tag) {
  const std::string open = fmt::format("<{}>", tag), close = fmt::format("</{}>", tag);
  const std::size_t a = xml.find(open);
  if (a == std::string_view::npos) return std::nullopt;
  const std::size_t b = xml.find(close, a + open.size());
  if (b == std::string_view::npos) return std::nullopt;
  std::string_view v = xml.substr(a + open.size(), b - a - open.size());
  while (!v.empty() && (v.front() == ' ' || v.front() == '\n' || v.front() == '\r' || v.front() == '\t')) v.remove_prefix(1);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\n' || v.back() == '\r' || v.back() == '\t')) v.remove_suffix(1);
  return std::string(v);
}

long long days_until(Clock::time_point end, Clock::time_point at) {
  return std::chrono::duration_cast<std::chrono::hours>(end - at).count() / 24;
}

// What a check of one host's files found (check_keystore and participant_files share it).
struct HostCheck {
  std::vector<CheckLine> lines;
  ParticipantFiles files;
  bool ok = true;
};

void note(HostCheck& h, CheckLine::State state, std::string item, std::string text) {
  if (state == CheckLine::State::Error) h.ok = false;
  h.lines.push_back(CheckLine{state, std::move(item), std::move(text)});
}

// Checks a document signed by the permissions CA; its content, or nullopt (an error noted).
std::optional<std::string> check_signed(HostCheck& h, const fs::path& file, X509* ca, Clock::time_point at,
                                        const std::string& item, std::string_view fix) {
  auto text = crypto::read_text(file);
  if (!text) {
    note(h, CheckLine::State::Error, item, fmt::format("{}; {}", text.error().message(), fix));
    return std::nullopt;
  }
  auto content = crypto::smime_verify(*text, ca, at);
  if (!content) {
    note(h, CheckLine::State::Error, item,
         fmt::format("'{}': {}; {}", file.string(), content.error().message(), fix));
    return std::nullopt;
  }
  return std::move(*content);
}

HostCheck check_host(const Keystore& ks, const std::string& name, Clock::time_point at, std::chrono::hours warn_within,
                     X509* identity_ca, X509* permissions_ca) {
  HostCheck h;
  const std::string who = "host " + name;
  const std::string recreate = fmt::format("make it with `horus security host create {} {}`", ks.dir().string(), name);
  h.files.identity_ca = ks.identity_ca_cert();
  h.files.permissions_ca = ks.permissions_ca_cert();
  h.files.governance = ks.governance_p7s();
  h.files.certificate = ks.host_cert(name);
  h.files.private_key = ks.host_key(name);
  h.files.permissions = ks.permissions_p7s(name);
  auto cert = crypto::read_certificate(ks.host_cert(name));
  if (!cert) {
    note(h, CheckLine::State::Error, who + ": certificate", fmt::format("{}; {}", cert.error().message(), recreate));
    return h;
  }
  h.files.subject = crypto::subject(cert->get());
  const auto end = crypto::not_after(cert->get());
  h.files.expires = end;
  if (auto ok = crypto::verify_issued(cert->get(), identity_ca, at); !ok) {
    const bool expired = at > end;
    note(h, CheckLine::State::Error, who + ": certificate",
         expired ? fmt::format("'{}' expired on {}; renew it with `horus security host create {} {} --replace`",
                               ks.host_cert(name).string(), crypto::utc_text(end), ks.dir().string(), name)
                 : fmt::format("'{}' is not valid with the keystore's identity CA: {}", ks.host_cert(name).string(),
                               ok.error().message()));
  } else {
    note(h, at + warn_within > end ? CheckLine::State::Warning : CheckLine::State::Ok, who + ": certificate",
         fmt::format("{}, issued by the identity CA, valid until {} ({} days)", h.files.subject, crypto::utc_text(end),
                     days_until(end, at)));
  }
  struct stat st{};
  if (::stat(ks.host_key(name).c_str(), &st) == 0 && (st.st_mode & 077) != 0) {
    note(h, CheckLine::State::Error, who + ": key",
         fmt::format("'{}' can be read by other users (mode {:04o}); `chmod 600` it", ks.host_key(name).string(),
                     st.st_mode & 07777));
  } else if (auto key = crypto::read_private_key(ks.host_key(name)); !key) {
    note(h, CheckLine::State::Error, who + ": key", fmt::format("{}; {}", key.error().message(), recreate));
  } else if (!crypto::key_matches(cert->get(), key->get())) {
    note(h, CheckLine::State::Error, who + ": key",
         fmt::format("'{}' is not the key of '{}'; {}", ks.host_key(name).string(), ks.host_cert(name).string(), recreate));
  } else {
    note(h, CheckLine::State::Ok, who + ": key", "matches the certificate, mode 0600");
  }
  const std::string sign_again =
      fmt::format("sign them again with `horus security permissions {} {} --publish ... --subscribe ...`", ks.dir().string(), name);
  auto content = check_signed(h, ks.permissions_p7s(name), permissions_ca, at, who + ": permissions", sign_again);
  if (!content) return h;
  const auto subject = element(*content, "subject_name");
  const auto from = element(*content, "not_before");
  const auto until = element(*content, "not_after");
  const auto from_t = from ? parse_utc(*from) : std::nullopt;
  const auto until_t = until ? parse_utc(*until) : std::nullopt;
  if (!subject || *subject != h.files.subject) {
    note(h, CheckLine::State::Error, who + ": permissions",
         fmt::format("their subject '{}' is not the certificate's '{}'; {}", subject.value_or("(none)"), h.files.subject,
                     sign_again));
  } else if (!from_t || !until_t) {
    note(h, CheckLine::State::Error, who + ": permissions", fmt::format("no readable validity; {}", sign_again));
  } else if (at < *from_t || at > *until_t) {
    note(h, CheckLine::State::Error, who + ": permissions",
         fmt::format("valid from {} to {}, not now; {}", crypto::utc_text(*from_t), crypto::utc_text(*until_t), sign_again));
  } else {
    h.files.expires = std::min(h.files.expires, *until_t);
    note(h, at + warn_within > *until_t ? CheckLine::State::Warning : CheckLine::State::Ok, who + ": permissions",
         fmt::format("signed by the permissions CA for {}, valid until {} ({} days)", *subject, crypto::utc_text(*until_t),
                     days_until(*until_t, at)));
  }
  return h;
}

}  // namespace

std::optional<Clock::time_point> parse_utc(std::string_view text) {
  std::tm tm{};
  int n = 0;
  const std::string str(text);
  if (std::sscanf(str.c_str(), "%4d-%2d-%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &n) != 3) return std::nullopt;
  std::string_view rest = text.substr(static_cast<std::size_t>(n));
  if (!rest.empty()) {
    int m = 0;
    const std::string time(rest);
    if (std::sscanf(time.c_str(), "T%2d:%2d:%2d%n", &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &m) != 3) return std::nullopt;
    rest = rest.substr(static_cast<std::size_t>(m));
  }
  if ((!rest.empty() && rest != "Z") || tm.tm_mon < 1 || tm.tm_mon > 12 || tm.tm_mday < 1 || tm.tm_mday > 31 ||
      tm.tm_hour > 23 || tm.tm_min > 59 || tm.tm_sec > 60)
    return std::nullopt;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return Clock::from_time_t(timegm(&tm));
}

Clock::time_point Validity::start() const { return not_before.value_or(Clock::now() - std::chrono::minutes(1)); }
Clock::time_point Validity::end() const { return not_after.value_or(start() + std::chrono::hours(24) * days); }

std::string not_permitted(const net::Security& security, std::string_view action) {
  const Keystore ks(security.keystore);
  return fmt::format("identity '{}' may not {} this topic: its permissions ({}) do not allow it; `horus security "
                     "permissions {} {} --publish ... --subscribe ...` grants it",
                     security.identity, action, ks.permissions_p7s(security.identity).string(), security.keystore,
                     security.identity);
}

std::string file_uri(const fs::path& file) {
  std::error_code ec;
  const fs::path abs = fs::absolute(file, ec);
  return "file://" + (ec ? file : abs).lexically_normal().string();  // "file:///abs": what Fast DDS accepts
}

Result<std::vector<std::string>> init_keystore(const Keystore& ks, const InitOptions& options) {
  Lines lines;
  if (file_exists(ks.identity_ca_cert()) || file_exists(ks.permissions_ca_cert()))
    return fail(Errc::Config, fmt::format("'{}' already has its CAs; a keystore's CAs are not replaced (every host's "
                                          "certificate depends on them): use another directory for a new keystore",
                                          ks.dir().string()));
  for (const auto& [dir, mode] : {std::pair{ks.dir(), 0755}, {ks.dir() / "public", 0755}, {ks.dir() / "private", 0700},
                                  {ks.dir() / "hosts", 0755}})
    if (auto ok = make_dir(dir, static_cast<mode_t>(mode)); !ok) return std::unexpected(ok.error());
  const auto make_ca = [&](const std::string& cn) -> Result<Ca> {
    auto key = crypto::new_key();
    if (!key) return std::unexpected(key.error());
    crypto::CertSpec spec{cn, options.organization, options.validity.start(), options.validity.end(), true};
    auto cert = crypto::make_certificate(spec, key->get(), nullptr, nullptr);
    if (!cert) return std::unexpected(cert.error());
    return Ca{std::move(*cert), std::move(*key)};
  };
  auto identity = make_ca(options.one_ca ? "horus CA" : "horus identity CA");
  if (!identity) return std::unexpected(identity.error());
  if (auto ok = add_line(lines, crypto::write_private_key(ks.identity_ca_key(), identity->key.get()), ks.identity_ca_key(),
                         "the identity CA's key, 0600");
      !ok)
    return std::unexpected(ok.error());
  if (auto ok = add_line(lines, crypto::write_certificate(ks.identity_ca_cert(), identity->cert.get()), ks.identity_ca_cert(),
                         "the identity CA");
      !ok)
    return std::unexpected(ok.error());
  Ca permissions;
  if (!options.one_ca) {
    auto made = make_ca("horus permissions CA");
    if (!made) return std::unexpected(made.error());
    permissions = std::move(*made);
  }
  EVP_PKEY* pkey = options.one_ca ? identity->key.get() : permissions.key.get();
  X509* pcert = options.one_ca ? identity->cert.get() : permissions.cert.get();
  if (auto ok = add_line(lines, crypto::write_private_key(ks.permissions_ca_key(), pkey), ks.permissions_ca_key(),
                         options.one_ca ? "the CA's key again: one CA" : "the permissions CA's key, 0600");
      !ok)
    return std::unexpected(ok.error());
  if (auto ok = add_line(lines, crypto::write_certificate(ks.permissions_ca_cert(), pcert), ks.permissions_ca_cert(),
                         options.one_ca ? "the same CA" : "the permissions CA");
      !ok)
    return std::unexpected(ok.error());
  auto gov = write_governance(ks, GovernanceSpec{});
  if (!gov) return std::unexpected(gov.error());
  lines.insert(lines.end(), gov->begin(), gov->end());
  return lines;
}

Result<std::vector<std::string>> create_host(const Keystore& ks, const std::string& name, const Validity& validity,
                                             bool replace) {
  if (auto ok = net::validate_identity_name(name); !ok) return std::unexpected(ok.error());
  if (!replace && file_exists(ks.host_cert(name)))
    return fail(Errc::Config, fmt::format("host '{}' already has an identity in '{}'; `--replace` makes a new key and "
                                          "certificate (a key rotation: copy them to the host, restart its processes)",
                                          name, ks.dir().string()));
  auto ca = read_ca(ks.identity_ca_cert(), ks.identity_ca_key(), "identity");
  if (!ca) return std::unexpected(ca.error());
  if (auto ok = make_dir(ks.dir() / "hosts", 0755); !ok) return std::unexpected(ok.error());
  if (auto ok = make_dir(ks.host_dir(name), 0755); !ok) return std::unexpected(ok.error());
  auto key = crypto::new_key();
  if (!key) return std::unexpected(key.error());
  crypto::CertSpec spec{name, crypto::subject_field(ca->cert.get(), NID_organizationName), validity.start(), validity.end(),
                        false};
  if (spec.not_after > crypto::not_after(ca->cert.get()))
    spec.not_after = crypto::not_after(ca->cert.get());  // a certificate never outlives its CA
  auto cert = crypto::make_certificate(spec, key->get(), ca->cert.get(), ca->key.get());
  if (!cert) return std::unexpected(cert.error());
  Lines lines;
  if (auto ok = add_line(lines, crypto::write_private_key(ks.host_key(name), key->get()), ks.host_key(name), "its key, 0600");
      !ok)
    return std::unexpected(ok.error());
  if (auto ok = add_line(lines, crypto::write_certificate(ks.host_cert(name), cert->get()), ks.host_cert(name),
                         fmt::format("{}, until {}", crypto::subject(cert->get()), crypto::utc_text(spec.not_after)));
      !ok)
    return std::unexpected(ok.error());
  return lines;
}

Result<std::vector<std::string>> write_permissions(const Keystore& ks, const std::string& name, PermissionsSpec spec,
                                                   const Validity& validity) {
  if (auto ok = net::validate_identity_name(name); !ok) return std::unexpected(ok.error());
  auto cert = crypto::read_certificate(ks.host_cert(name));
  if (!cert)
    return fail(Errc::Config, fmt::format("host '{}': {}; make its identity first with `horus security host create {} {}`",
                                          name, cert.error().message(), ks.dir().string(), name));
  auto ca = read_ca(ks.permissions_ca_cert(), ks.permissions_ca_key(), "permissions");
  if (!ca) return std::unexpected(ca.error());
  spec.grant = name;
  spec.subject = crypto::subject(cert->get());
  spec.not_before = validity.start();
  spec.not_after = std::min(validity.end(), crypto::not_after(ca->cert.get()));
  auto xml = permissions_xml(spec);
  if (!xml) return std::unexpected(xml.error());
  auto signed_xml = crypto::smime_sign(*xml, ca->cert.get(), ca->key.get());
  if (!signed_xml) return std::unexpected(signed_xml.error());
  Lines lines;
  if (auto ok = add_line(lines, crypto::write_text(ks.permissions_xml(name), *xml), ks.permissions_xml(name), "readable copy");
      !ok)
    return std::unexpected(ok.error());
  if (auto ok = add_line(lines, crypto::write_text(ks.permissions_p7s(name), *signed_xml), ks.permissions_p7s(name),
                         "signed by the permissions CA");
      !ok)
    return std::unexpected(ok.error());
  return lines;
}

Result<std::vector<std::string>> write_governance(const Keystore& ks, const GovernanceSpec& spec) {
  auto ca = read_ca(ks.permissions_ca_cert(), ks.permissions_ca_key(), "permissions");
  if (!ca) return std::unexpected(ca.error());
  auto xml = governance_xml(spec);
  if (!xml) return std::unexpected(xml.error());
  auto signed_xml = crypto::smime_sign(*xml, ca->cert.get(), ca->key.get());
  if (!signed_xml) return std::unexpected(signed_xml.error());
  Lines lines;
  if (auto ok = add_line(lines, crypto::write_text(ks.governance_xml(), *xml), ks.governance_xml(), "readable copy"); !ok)
    return std::unexpected(ok.error());
  if (auto ok = add_line(lines, crypto::write_text(ks.governance_p7s(), *signed_xml), ks.governance_p7s(),
                         "signed by the permissions CA");
      !ok)
    return std::unexpected(ok.error());
  return lines;
}

CheckReport check_keystore(const Keystore& ks, Clock::time_point at, std::chrono::hours warn_within) {
  CheckReport report;
  const auto add = [&](CheckLine line) {
    if (line.state == CheckLine::State::Error) ++report.errors;
    if (line.state == CheckLine::State::Warning) ++report.warnings;
    report.lines.push_back(std::move(line));
  };
  const auto ca = [&](const fs::path& file, std::string_view which) -> crypto::Cert {
    auto cert = crypto::read_certificate(file);
    const std::string item = fmt::format("{} CA", which);
    if (!cert) {
      add({CheckLine::State::Error, item, cert.error().message()});
      return nullptr;
    }
    const auto end = crypto::not_after(cert->get());
    if (auto ok = crypto::verify_issued(cert->get(), cert->get(), at); !ok) {
      add({CheckLine::State::Error, item, fmt::format("'{}': {}", file.string(), ok.error().message())});
      return nullptr;
    }
    add({at + warn_within > end ? CheckLine::State::Warning : CheckLine::State::Ok, item,
         fmt::format("{}, valid until {} ({} days)", crypto::subject(cert->get()), crypto::utc_text(end), days_until(end, at))});
    return std::move(*cert);
  };
  crypto::Cert identity = ca(ks.identity_ca_cert(), "identity");
  crypto::Cert permissions = ca(ks.permissions_ca_cert(), "permissions");
  if (!identity || !permissions) return report;
  HostCheck gov;
  if (check_signed(gov, ks.governance_p7s(), permissions.get(), at, "governance",
                   fmt::format("sign it again with `horus security governance {}`", ks.dir().string())))
    note(gov, CheckLine::State::Ok, "governance", "signed by the permissions CA");
  for (CheckLine& l : gov.lines) add(std::move(l));
  std::set<std::string> hosts;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(ks.dir() / "hosts", ec))
    if (entry.is_directory(ec)) hosts.insert(entry.path().filename().string());
  if (hosts.empty())
    add({CheckLine::State::Warning, "hosts",
         fmt::format("none yet; make one with `horus security host create {} NAME`", ks.dir().string())});
  for (const std::string& name : hosts) {
    HostCheck h = check_host(ks, name, at, warn_within, identity.get(), permissions.get());
    for (CheckLine& l : h.lines) add(std::move(l));
  }
  return report;
}

Result<ParticipantFiles> participant_files(const net::Security& security) {
  const Keystore ks(security.keystore);
  const std::string where = fmt::format("security ({}): identity '{}' in keystore '{}'", security.origin,
                                        security.identity, security.keystore);
  const auto at = Clock::now();
  auto identity = crypto::read_certificate(ks.identity_ca_cert());
  if (!identity) return fail(Errc::Config, fmt::format("{}: the identity CA: {}", where, identity.error().message()));
  auto permissions = crypto::read_certificate(ks.permissions_ca_cert());
  if (!permissions) return fail(Errc::Config, fmt::format("{}: the permissions CA: {}", where, permissions.error().message()));
  HostCheck h = check_host(ks, security.identity, at, std::chrono::hours(0), identity->get(), permissions->get());
  (void)check_signed(h, ks.governance_p7s(), permissions->get(), at, "governance",
                     fmt::format("sign it again with `horus security governance {}`", ks.dir().string()));
  for (const CheckLine& l : h.lines)
    if (l.state == CheckLine::State::Error) return fail(Errc::Config, fmt::format("{}: {}: {}", where, l.item, l.text));
  return h.files;
}

Result<std::optional<ParticipantFiles>> secure_participant(const net::Security& security, std::string_view transport) {
  if (security.mode == net::SecurityMode::Off) return std::optional<ParticipantFiles>{};
  auto files = participant_files(security);
  if (files) return std::optional<ParticipantFiles>(std::move(*files));
  if (security.mode == net::SecurityMode::Enforce) return std::unexpected(std::move(files.error()));
  static std::mutex mutex;
  static std::set<std::string> warned;
  std::lock_guard lock(mutex);
  if (warned.insert(files.error().message()).second)
    detail::log().warn("{}: security is permissive and the identity cannot be used, so this participant is NOT secure "
                       "(it reaches only hosts without security): {}",
                       transport, files.error().message());
  return std::optional<ParticipantFiles>{};
}

}  // namespace horus::security
