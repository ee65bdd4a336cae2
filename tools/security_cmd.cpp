#include "security_cmd.hpp"

#include <fmt/format.h>

#include <fstream>

#include <optional>
#include <string>
#include <vector>

#include "horus/config.hpp"
#include "horus/security/dds_config.hpp"

namespace horus::tools {

struct SecurityCommands {
  CLI::App* init = nullptr;
  CLI::App* host = nullptr;
  CLI::App* permissions = nullptr;
  CLI::App* governance = nullptr;
  CLI::App* check = nullptr;
  CLI::App* dds_config = nullptr;
  std::string dir, name, config_file, not_before, not_after, organization = "horus", library, output;
  std::vector<std::string> publish, subscribe;
  std::uint32_t days = 0;
  std::optional<std::uint32_t> domain;
  bool one_ca = false, replace = false, no_fleet_topics = false;
};

std::vector<const TopicRule*> protection_rules(const Config* config) {
  std::vector<const TopicRule*> out;
  if (config != nullptr)
    for (const TopicRule& r : config->rules())
      if (r.protection) out.push_back(&r);
  return out;
}

security::GovernanceSpec governance_spec(const Config* config) {
  security::GovernanceSpec spec;
  for (const TopicRule* r : protection_rules(config)) spec.rules.push_back({r->match, *r->protection});
  return spec;
}

namespace {

// The validity the options give; an error message, or empty.
std::string validity_of(const SecurityCommands& c, std::uint32_t default_days, security::Validity& out) {
  out.days = c.days > 0 ? c.days : default_days;
  if (!c.not_before.empty()) {
    out.not_before = security::parse_utc(c.not_before);
    if (!out.not_before) return fmt::format("--not-before '{}': expected a UTC date, 2026-11-27 or 2026-11-27T13:05:00", c.not_before);
  }
  if (!c.not_after.empty()) {
    out.not_after = security::parse_utc(c.not_after);
    if (!out.not_after) return fmt::format("--not-after '{}': expected a UTC date, 2026-11-27 or 2026-11-27T13:05:00", c.not_after);
  }
  if (!(out.start() < out.end())) return "the validity ends before it starts (--not-before, --not-after, --days)";
  return {};
}

int report(const Result<std::vector<std::string>>& done, std::string_view command) {
  if (!done) {
    fmt::print(stderr, "horus security {}: {}\n", command, done.error().message());
    return 1;
  }
  for (const std::string& line : *done) fmt::print("{}\n", line);
  return 0;
}

int run_governance(const SecurityCommands& c, const security::Keystore& ks) {
  const Config* config = nullptr;
  std::optional<Config> loaded;
  if (!c.config_file.empty()) {
    auto got = Config::load(c.config_file);
    if (!got) {
      fmt::print(stderr, "horus security governance: {}\n", got.error().message());
      return 1;
    }
    loaded = std::move(*got);
    config = &*loaded;
  } else {
    auto got = config_from_environment();
    if (!got) {
      fmt::print(stderr, "horus security governance: {}\n", got.error().message());
      return 1;
    }
    config = *got;
  }
  security::GovernanceSpec spec = governance_spec(config);
  spec.domain = c.domain;
  const int rc = report(security::write_governance(ks, spec), "governance");
  if (rc != 0) return rc;
  fmt::print("topics: ");
  for (const auto& r : spec.rules) fmt::print("{} {}, ", r.pattern, to_string(r.protection));
  fmt::print("every other topic encrypt{}\n",
             config == nullptr ? " (no configuration file: HORUS_CONFIG is unset and no --config)"
                               : fmt::format(" (rules with `protection:` of {})", config->file()));
  return 0;
}

int run_check(const security::Keystore& ks) {
  const security::CheckReport r = security::check_keystore(ks, security::Clock::now());
  for (const security::CheckLine& l : r.lines) {
    const char* state = l.state == security::CheckLine::State::Ok        ? "ok     "
                        : l.state == security::CheckLine::State::Warning ? "WARNING"
                                                                         : "ERROR  ";
    fmt::print("{} {}: {}\n", state, l.item, l.text);
  }
  fmt::print("{}: {} error{}, {} warning{}\n", ks.dir().string(), r.errors, r.errors == 1 ? "" : "s", r.warnings,
             r.warnings == 1 ? "" : "s");
  return r.errors > 0 ? 1 : 0;
}

// The configuration another DDS program reads to join with identity `name`: checked first, so
// an expired or unsigned identity is an error here and not a silent handshake failure there.
int run_dds_config(const SecurityCommands& c) {
  const net::Security identity{net::SecurityMode::Enforce, c.dir, c.name, "horus security dds-config"};
  auto files = security::participant_files(identity);
  if (!files) {
    fmt::print(stderr, "horus security dds-config: {}\n", files.error().message());
    return 1;
  }
  auto text = security::third_party_config(*files, c.library);
  if (!text) {
    fmt::print(stderr, "horus security dds-config: {}\n", text.error().message());
    return 2;
  }
  if (c.output.empty()) {
    fmt::print("{}", *text);
    return 0;
  }
  std::ofstream out(c.output, std::ios::trunc);
  out << *text;
  out.close();
  if (!out) {
    fmt::print(stderr, "horus security dds-config: cannot write '{}'\n", c.output);
    return 1;
  }
  fmt::print("wrote {} ({} configuration of identity '{}')\n", c.output, c.library, c.name);
  return 0;
}

}  // namespace

std::shared_ptr<SecurityCommands> add_security_commands(CLI::App& app) {
  auto c = std::make_shared<SecurityCommands>();
  auto* sec = app.add_subcommand("security", "DDS-Security: make and check the keystore of a fleet");
  sec->require_subcommand(1);
  const auto dir = [&](CLI::App* cmd) { cmd->add_option("dir", c->dir, "the keystore directory")->required(); };
  const auto validity = [&](CLI::App* cmd, std::string_view days) {
    cmd->add_option("--days", c->days, fmt::format("days of validity (default {})", days))->check(CLI::Range(1, 36500));
    cmd->add_option("--not-before", c->not_before, "start of validity, UTC (2026-11-27 or 2026-11-27T13:05:00)");
    cmd->add_option("--not-after", c->not_after, "end of validity, UTC (overrides --days)");
  };
  auto* keystore = sec->add_subcommand("keystore", "the keystore's CAs");
  keystore->require_subcommand(1);
  c->init = keystore->add_subcommand("init", "make a keystore: an identity CA, a permissions CA and a governance");
  dir(c->init);
  c->init->add_flag("--one-ca", c->one_ca, "one CA for identities and permissions");
  c->init->add_option("--org", c->organization, "the O= of the certificates (default horus)");
  validity(c->init, "3650");
  auto* host = sec->add_subcommand("host", "hosts' identities");
  host->require_subcommand(1);
  c->host = host->add_subcommand("create", "make a host's key and certificate (CN=NAME), signed by the identity CA");
  dir(c->host);
  c->host->add_option("name", c->name, "the host's identity name (HORUS_SECURITY_IDENTITY on that host)")->required();
  c->host->add_flag("--replace", c->replace, "renew an existing identity with a new key (rotation)");
  validity(c->host, "365");
  c->permissions = sec->add_subcommand("permissions", "sign what a host may publish and subscribe");
  dir(c->permissions);
  c->permissions->add_option("name", c->name, "the host's identity name")->required();
  c->permissions->add_option("--publish", c->publish, "topic patterns it may publish (robot1.**, fleet.map)");
  c->permissions->add_option("--subscribe", c->subscribe, "topic patterns it may subscribe to");
  c->permissions->add_flag("--no-fleet-topics", c->no_fleet_topics,
                           "do not allow the fleet layer's own topics (horus.fleet.**: heartbeats, announcements)");
  c->permissions->add_option("--domain", c->domain, "the DDS domain (default: domains 0 to 230)")->check(CLI::Range(0, 232));
  validity(c->permissions, "365");
  c->governance = sec->add_subcommand("governance", "sign the fleet's governance, from the configuration file's rules");
  dir(c->governance);
  c->governance->add_option("--config", c->config_file, "the configuration file (default: HORUS_CONFIG's)");
  c->governance->add_option("--domain", c->domain, "the DDS domain (default: domains 0 to 230)")->check(CLI::Range(0, 232));
  c->check = sec->add_subcommand("check", "check the CAs, signatures, expiry and every host's files");
  dir(c->check);
  c->dds_config = sec->add_subcommand("dds-config", "the configuration another DDS program joins the fleet with");
  dir(c->dds_config);
  c->dds_config->add_option("name", c->name, "the identity it uses (made with host create and permissions)")->required();
  c->dds_config->add_option("--for", c->library, "cyclonedds (for CYCLONEDDS_URI) or fastdds (an XML profile)")
      ->required()
      ->check(CLI::IsMember({"cyclonedds", "fastdds"}));
  c->dds_config->add_option("-o,--output", c->output, "write it to this file (default: standard output)");
  return c;
}

int run_security(const SecurityCommands& c) {
  const security::Keystore ks(c.dir);
  security::Validity validity;
  if (c.init != nullptr && *c.init) {
    if (const std::string why = validity_of(c, 3650, validity); !why.empty()) {
      fmt::print(stderr, "horus security keystore init: {}\n", why);
      return 2;
    }
    return report(security::init_keystore(ks, {c.one_ca, c.organization, validity}), "keystore init");
  }
  if (c.host != nullptr && *c.host) {
    if (const std::string why = validity_of(c, 365, validity); !why.empty()) {
      fmt::print(stderr, "horus security host create: {}\n", why);
      return 2;
    }
    return report(security::create_host(ks, c.name, validity, c.replace), "host create");
  }
  if (c.permissions != nullptr && *c.permissions) {
    if (const std::string why = validity_of(c, 365, validity); !why.empty()) {
      fmt::print(stderr, "horus security permissions: {}\n", why);
      return 2;
    }
    if (c.publish.empty() && c.subscribe.empty() && c.no_fleet_topics) {
      fmt::print(stderr, "horus security permissions: nothing to allow; expected --publish or --subscribe patterns\n");
      return 2;
    }
    security::PermissionsSpec spec;
    spec.publish = c.publish;
    spec.subscribe = c.subscribe;
    spec.fleet_topics = !c.no_fleet_topics;
    spec.domain = c.domain;
    return report(security::write_permissions(ks, c.name, spec, validity), "permissions");
  }
  if (c.governance != nullptr && *c.governance) return run_governance(c, ks);
  if (c.check != nullptr && *c.check) return run_check(ks);
  if (c.dds_config != nullptr && *c.dds_config) return run_dds_config(c);
  return -1;
}

}  // namespace horus::tools
