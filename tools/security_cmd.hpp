// horus security: the keystore of DDS-Security (security_cmd.cpp; security/README.md).
//
//   horus security keystore init DIR [--one-ca] [--org O] [--days N]
//   horus security host create DIR NAME [--days N] [--not-before T] [--not-after T] [--replace]
//   horus security permissions DIR NAME --publish P... --subscribe P... [--domain N] [--days N]
//   horus security governance DIR [--config FILE] [--domain N]
//   horus security check DIR
#pragma once

#include <CLI/CLI.hpp>

#include <memory>

namespace horus::tools {

struct SecurityCommands;
/// Adds `security` and its commands to `app`; what they parse goes into the returned object.
std::shared_ptr<SecurityCommands> add_security_commands(CLI::App& app);
/// Runs the security command that was parsed: its exit status, or -1 when none was.
int run_security(const SecurityCommands& commands);

}  // namespace horus::tools
