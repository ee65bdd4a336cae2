// The command line shared by horus-idlgen (standard messages) and the generators that
// horus_generate_interfaces() builds for a user's own messages:
//
//   <gen> --out DIR             write every file (a file is rewritten only when it changes)
//   <gen> --print FILE          print one file ("geometry.idl")
//   <gen> --list                list files and types
//   <gen> --check-lock LOCK     exit 1 when an emitted type differs from the lock file
//   <gen> --update-lock LOCK    rewrite the lock (refused when a type changed and
//                               kInterfaceVersion was not bumped)
#pragma once

#include "horus/idlgen/emit.hpp"
#include "horus/idlgen/model.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::idlgen {

int run_cli(const Model& model, int argc, char** argv, const IdlOptions& options = {});

}  // namespace horus::idlgen

HORUS_API_END
