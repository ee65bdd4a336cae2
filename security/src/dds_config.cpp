#include "horus/security/dds_config.hpp"

#include <link.h>

#include <fmt/format.h>

#include <string>
#include <system_error>

namespace horus::security {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kAuthPlugin = "libdds_security_auth.so";

// The plug-ins' directory beside (or in libddsc0debian/ beside) `libddsc`; empty if not there.
fs::path plugins_beside(const fs::path& libddsc) {
  std::error_code ec;
  const fs::path dir = libddsc.parent_path();
  for (const fs::path& candidate : {dir / "libddsc0debian", dir})
    if (fs::exists(candidate / kAuthPlugin, ec)) return candidate;
  return {};
}

int find_loaded_libddsc(dl_phdr_info* info, size_t, void* out) {
  if (info->dlpi_name == nullptr) return 0;
  const std::string_view name(info->dlpi_name);
  const auto slash = name.rfind('/');
  if (!name.substr(slash == std::string_view::npos ? 0 : slash + 1).starts_with("libddsc.so")) return 0;
  *static_cast<fs::path*>(out) = fs::path(name);
  return 1;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> dds_security_properties(const ParticipantFiles& f) {
  return {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {"dds.sec.auth.builtin.PKI-DH.identity_ca", file_uri(f.identity_ca)},
      {"dds.sec.auth.builtin.PKI-DH.identity_certificate", file_uri(f.certificate)},
      {"dds.sec.auth.builtin.PKI-DH.private_key", file_uri(f.private_key)},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {"dds.sec.access.builtin.Access-Permissions.permissions_ca", file_uri(f.permissions_ca)},
      {"dds.sec.access.builtin.Access-Permissions.governance", file_uri(f.governance)},
      {"dds.sec.access.builtin.Access-Permissions.permissions", file_uri(f.permissions)},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
}

fs::path cyclone_plugin_dir() {
  fs::path loaded;
  ::dl_iterate_phdr(find_loaded_libddsc, &loaded);
  if (!loaded.empty()) {
    std::error_code ec;
    const fs::path real = fs::canonical(loaded, ec);
    if (fs::path dir = plugins_beside(ec ? loaded : real); !dir.empty()) return dir;
  }
  // Not loaded here (a program without the Cyclone transport): Debian's multiarch directories.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/usr/lib", ec))
    if (fs::path dir = plugins_beside(entry.path() / "libddsc.so"); !dir.empty()) return dir;
  return {};
}

std::string cyclone_security_xml(const ParticipantFiles& f, const fs::path& plugin_dir) {
  const auto library = [&](std::string_view name, std::string_view function) {
    const std::string file = fmt::format("libdds_security_{}.so", name);
    const std::string path = plugin_dir.empty() ? fmt::format("dds_security_{}", name) : (plugin_dir / file).string();
    return fmt::format(R"(<Library path="{}" initFunction="init_{}" finalizeFunction="finalize_{}"/>)", xml_escape(path),
                       function, function);
  };
  const auto uri = [](const fs::path& p) { return xml_escape(file_uri(p)); };
  return fmt::format(
      "<Security><Authentication>{}<IdentityCA>{}</IdentityCA><IdentityCertificate>{}</IdentityCertificate>"
      "<PrivateKey>{}</PrivateKey></Authentication><AccessControl>{}<Governance>{}</Governance>"
      "<PermissionsCA>{}</PermissionsCA><Permissions>{}</Permissions></AccessControl>"
      "<Cryptographic>{}</Cryptographic></Security>",
      library("auth", "authentication"), uri(f.identity_ca), uri(f.certificate), uri(f.private_key),
      library("ac", "access_control"), uri(f.governance), uri(f.permissions_ca), uri(f.permissions),
      library("crypto", "crypto"));
}

Result<std::string> third_party_config(const ParticipantFiles& f, std::string_view library) {
  if (library == "cyclonedds")
    return fmt::format(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<!-- DDS-Security of identity {}: add it after your own configuration,\n"
        "     CYCLONEDDS_URI=\"file:///your/cyclonedds.xml,file:///this/file.xml\" -->\n"
        "<CycloneDDS><Domain Id=\"any\">{}</Domain></CycloneDDS>\n",
        xml_escape(f.subject), cyclone_security_xml(f, cyclone_plugin_dir()));
  if (library == "fastdds") {
    std::string properties;
    for (const auto& [name, value] : dds_security_properties(f))
      properties += fmt::format("          <property><name>{}</name><value>{}</value></property>\n", name, xml_escape(value));
    return fmt::format(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<!-- DDS-Security of identity {}: FASTRTPS_DEFAULT_PROFILES_FILE=/this/file.xml, or copy the\n"
        "     properties into your participant's profile -->\n"
        "<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\">\n"
        "  <participant profile_name=\"horus_secure\" is_default_profile=\"true\">\n"
        "    <rtps>\n"
        "      <propertiesPolicy>\n"
        "        <properties>\n{}"
        "        </properties>\n"
        "      </propertiesPolicy>\n"
        "    </rtps>\n"
        "  </participant>\n"
        "</profiles>\n",
        xml_escape(f.subject), properties);
  }
  return fail(Errc::InvalidArgument,
              fmt::format("DDS library '{}': expected cyclonedds (a CYCLONEDDS_URI document) or fastdds (an XML profile)",
                          library));
}

}  // namespace horus::security
