// What a DDS participant is configured with to join a secured fleet, from an identity's checked
// files (keystore.hpp's ParticipantFiles): DDS-Security's standard participant properties (what
// Fast DDS takes), Cyclone DDS's <Security> element, and the two documents another DDS program
// reads the standard way (`horus security dds-config`): a Cyclone DDS configuration for
// CYCLONEDDS_URI and a Fast DDS XML profile for FASTRTPS_DEFAULT_PROFILES_FILE.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/security/keystore.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::security {

/// DDS-Security's built-in plug-ins (PKI-DH, Access-Permissions, AES-GCM-GMAC) and the files, as
/// the specification's `dds.sec.*` property names, in the order a participant is given them.
std::vector<std::pair<std::string, std::string>> dds_security_properties(const ParticipantFiles& files);

/// The directory of Cyclone DDS's security plug-ins (libdds_security_auth/ac/crypto.so). Debian
/// installs them in <libdir>/libddsc0debian/, which the dynamic loader does not search; found
/// beside the libddsc this process has loaded, else under /usr/lib's architecture directories.
/// Empty when not found: Cyclone then loads them by name, from the loader's path.
std::filesystem::path cyclone_plugin_dir();

/// Cyclone DDS's <Security> element for the files, each plug-in by absolute path in `plugin_dir`
/// (empty: by name).
std::string cyclone_security_xml(const ParticipantFiles& files, const std::filesystem::path& plugin_dir);

/// The configuration another program of `library` ("cyclonedds": a <CycloneDDS> document holding
/// only <Security>, merged after the program's own by CYCLONEDDS_URI="file://its.xml,file://this.xml";
/// "fastdds": an XML profiles document whose default participant profile holds the properties,
/// read through FASTRTPS_DEFAULT_PROFILES_FILE). An error (Errc::InvalidArgument) for another library.
Result<std::string> third_party_config(const ParticipantFiles& files, std::string_view library);

}  // namespace horus::security

HORUS_API_END
