// A horus keystore: the CAs, the hosts' identities and the signed access-control documents of
// DDS-Security, in one directory (what `horus security` makes; SROS2's keystore is the model):
//
//   DIR/public/identity_ca.cert.pem      the CA that signs hosts' certificates
//   DIR/public/permissions_ca.cert.pem   the CA that signs governance and permissions (the same
//                                        certificate when the keystore has one CA)
//   DIR/private/*.key.pem                the CAs' keys (0600, directory 0700): keep them off robots
//   DIR/governance.xml, governance.p7s   the fleet's governance and its signed form
//   DIR/hosts/NAME/cert.pem, key.pem     a host's identity (key 0600)
//   DIR/hosts/NAME/permissions.xml, permissions.p7s   what it may publish and subscribe, signed
//
// A host needs public/, governance.p7s and its own hosts/NAME/ (not private/).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/security/policy.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::security {

using Clock = std::chrono::system_clock;

class Keystore {
 public:
  explicit Keystore(std::filesystem::path dir) : dir_(std::move(dir)) {}
  const std::filesystem::path& dir() const noexcept { return dir_; }
  std::filesystem::path identity_ca_cert() const { return dir_ / "public" / "identity_ca.cert.pem"; }
  std::filesystem::path permissions_ca_cert() const { return dir_ / "public" / "permissions_ca.cert.pem"; }
  std::filesystem::path identity_ca_key() const { return dir_ / "private" / "identity_ca.key.pem"; }
  std::filesystem::path permissions_ca_key() const { return dir_ / "private" / "permissions_ca.key.pem"; }
  std::filesystem::path governance_xml() const { return dir_ / "governance.xml"; }
  std::filesystem::path governance_p7s() const { return dir_ / "governance.p7s"; }
  std::filesystem::path host_dir(const std::string& name) const { return dir_ / "hosts" / name; }
  std::filesystem::path host_cert(const std::string& name) const { return host_dir(name) / "cert.pem"; }
  std::filesystem::path host_key(const std::string& name) const { return host_dir(name) / "key.pem"; }
  std::filesystem::path permissions_xml(const std::string& name) const { return host_dir(name) / "permissions.xml"; }
  std::filesystem::path permissions_p7s(const std::string& name) const { return host_dir(name) / "permissions.p7s"; }

 private:
  std::filesystem::path dir_;
};

/// A UTC date as `horus security` takes it and permissions documents write it: "2026-11-27" or
/// "2026-11-27T13:05:00", an optional "Z"; nullopt when it is not one.
std::optional<Clock::time_point> parse_utc(std::string_view text);

/// The validity of what is made: from `not_before` (default: now, less a minute for clocks a
/// little behind) to `not_after` (default: `days` after it).
struct Validity {
  std::optional<Clock::time_point> not_before, not_after;
  std::uint32_t days = 365;
  Clock::time_point start() const;
  Clock::time_point end() const;
};

struct InitOptions {
  bool one_ca = false;               // one CA for identities and permissions
  std::string organization = "horus";  // the O= of every certificate
  Validity validity{{}, {}, 3650};
};
/// Makes the CAs of a new keystore in `dir` (created; an existing CA is never overwritten) and
/// a governance that encrypts every topic. What was written, one line per file.
Result<std::vector<std::string>> init_keystore(const Keystore& ks, const InitOptions& options);

/// Makes (or, with `replace`, renews: a new key) a host's key and certificate, signed by the
/// identity CA; CN is the host's name. What was written.
Result<std::vector<std::string>> create_host(const Keystore& ks, const std::string& name, const Validity& validity,
                                             bool replace);

/// Writes and signs a host's permissions (its certificate's subject, `spec`'s topics).
Result<std::vector<std::string>> write_permissions(const Keystore& ks, const std::string& name, PermissionsSpec spec,
                                                   const Validity& validity);
/// Writes and signs the fleet's governance.
Result<std::vector<std::string>> write_governance(const Keystore& ks, const GovernanceSpec& spec);

/// What `horus security check` finds: one line per item, its state.
struct CheckLine {
  enum class State : std::uint8_t { Ok, Warning, Error };
  State state = State::Ok;
  std::string item;  // "identity CA", "host robot1: certificate", ...
  std::string text;  // what was found
};
struct CheckReport {
  std::vector<CheckLine> lines;
  int errors = 0, warnings = 0;
};
/// Checks a keystore at `at`: the CAs, the governance's signature, every host's certificate
/// (issuer, validity, key), and its permissions (signature, subject, validity). A validity that
/// ends within `warn_within` is a warning.
CheckReport check_keystore(const Keystore& ks, Clock::time_point at, std::chrono::hours warn_within = std::chrono::hours(24 * 30));

/// The files a DDS participant of `security`'s identity is configured with, each checked.
struct ParticipantFiles {
  std::filesystem::path identity_ca, certificate, private_key, permissions_ca, governance, permissions;
  std::string subject;        // the certificate's subject
  Clock::time_point expires;  // when the certificate or the permissions end, whichever is first
};
/// Checks `security.identity`'s files in `security.keystore` now, as check_keystore does; an
/// error (Errc::Config) names the file, what is wrong with it and the command that fixes it.
Result<ParticipantFiles> participant_files(const net::Security& security);

/// What a DDS transport does with its configuration's security: nullopt when it is off, or
/// permissive and the files are missing or invalid (logged once, as a warning); the checked
/// files otherwise; under enforce, the error. `transport` names it in messages.
Result<std::optional<ParticipantFiles>> secure_participant(const net::Security& security, std::string_view transport);

/// Why a secure participant may not `action` ("publish", "subscribe") a topic: its identity's
/// permissions, named, do not allow it, and the command that grants it.
std::string not_permitted(const net::Security& security, std::string_view action);

/// "file:///abs/path": how DDS-Security's properties name a file.
std::string file_uri(const std::filesystem::path& file);

}  // namespace horus::security

HORUS_API_END
