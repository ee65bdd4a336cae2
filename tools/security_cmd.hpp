// horus security: the keystore of DDS-Security (security_cmd.cpp; security/README.md).
//
//   horus security keystore init DIR [--one-ca] [--org O] [--days N]
//   horus security host create DIR NAME [--days N] [--not-before T] [--not-after T] [--replace]
//   horus security permissions DIR NAME --publish P... --subscribe P... [--domain N] [--days N]
//   horus security governance DIR [--config FILE] [--domain N]
//   horus security check DIR
//   horus security dds-config DIR NAME --for cyclonedds|fastdds [-o FILE]
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <vector>

#include "horus/config.hpp"
#include "horus/security/policy.hpp"

namespace horus::tools {

/// The configuration file's rules with `protection:`, in order (nullptr: none).
std::vector<const TopicRule*> protection_rules(const Config* config);
/// The governance those rules give (the i-th governance rule is the i-th of protection_rules):
/// what `horus security governance` signs and `horus config explain` shows.
security::GovernanceSpec governance_spec(const Config* config);

struct SecurityCommands;
/// Adds `security` and its commands to `app`; what they parse goes into the returned object.
std::shared_ptr<SecurityCommands> add_security_commands(CLI::App& app);
/// Runs the security command that was parsed: its exit status, or -1 when none was.
int run_security(const SecurityCommands& commands);

}  // namespace horus::tools
