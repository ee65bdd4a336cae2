#include "horus/security/policy.hpp"

#include <fmt/format.h>

#include <fnmatch.h>

#include <algorithm>
#include <ctime>

#include "horus/names.hpp"

namespace horus::security {
namespace {

constexpr std::size_t kMaxDoubleStars = 4;       // 2^4 expressions at most per pattern
constexpr std::uint32_t kMaxRangeDomain = 230;  // "every domain": Cyclone DDS's largest domain id

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

namespace {

std::string domains_xml(const std::optional<std::uint32_t>& domain, std::string_view indent) {
  if (domain) return fmt::format("{}<domains><id>{}</id></domains>\n", indent, *domain);
  // Every domain Cyclone DDS has: 0 to 230 (Cyclone 0.10 refuses to parse a range that ends
  // above its largest domain id, and reads a range without an end as its start alone).
  return fmt::format("{}<domains><id_range><min>0</min><max>{}</max></id_range></domains>\n", indent, kMaxRangeDomain);
}

std::string xml_time(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

constexpr std::string_view kHeader = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";

// The expressions of several patterns, in order, without repeats.
Result<std::vector<std::string>> expressions_of(const std::vector<std::string>& patterns, bool widen) {
  std::vector<std::string> out;
  for (const std::string& p : patterns) {
    auto e = dds_topic_expressions(p, widen);
    if (!e) return std::unexpected(std::move(e.error()));
    for (std::string& x : *e)
      if (std::find(out.begin(), out.end(), x) == out.end()) out.push_back(std::move(x));
  }
  return out;
}

}  // namespace

namespace {

// A governance rule's expressions: an encrypt rule may widen a single '*' (more topics
// encrypted), a sign rule may not (it would weaken protection). governance_xml writes them,
// protection_of matches them: the two agree by construction.
Result<std::vector<std::string>> rule_expressions(const GovernanceRule& r) {
  return dds_topic_expressions(r.pattern, r.protection == net::Protection::Encrypt);
}

}  // namespace

Result<std::vector<std::string>> dds_topic_expressions(std::string_view pattern, bool widen_single) {
  if (auto ok = check_topic_pattern(pattern); !ok) return std::unexpected(std::move(ok.error()));
  std::vector<std::string_view> segs;
  for (std::size_t at = 0;;) {
    const std::size_t dot = pattern.find('.', at);
    segs.push_back(pattern.substr(at, dot == std::string_view::npos ? std::string_view::npos : dot - at));
    if (dot == std::string_view::npos) break;
    at = dot + 1;
  }
  std::size_t stars = 0;
  for (std::string_view s : segs) {
    if (s == "**") ++stars;
    if (s == "*" && !widen_single)
      return fail(Errc::Config,
                  fmt::format("pattern '{}': '*' (exactly one segment) cannot be granted exactly, because DDS-Security "
                              "matches topic names with fnmatch, whose '*' also matches several segments; name the "
                              "segment, or use '**' (any number of segments) if that is what you mean",
                              pattern));
  }
  if (stars > kMaxDoubleStars)
    return fail(Errc::Config, fmt::format("pattern '{}' has {} '**' segments; at most {} (each doubles the DDS topic "
                                          "expressions it needs)",
                                          pattern, stars, kMaxDoubleStars));
  // Each '**' is either no segment at all or fnmatch's '*' standing for one or more segments.
  std::vector<std::string> out;
  for (std::size_t choice = 0; choice < (std::size_t{1} << stars); ++choice) {
    std::string e = "horus";
    std::size_t star = 0;
    for (std::string_view s : segs) {
      if (s == "**" && ((choice >> star++) & 1) == 0) continue;
      e += '/';
      e += (s == "**" || s == "*") ? std::string_view("*") : s;
    }
    if (std::find(out.begin(), out.end(), e) == out.end()) out.push_back(std::move(e));
  }
  return out;
}

Result<std::string> governance_xml(const GovernanceSpec& spec) {
  std::string rules;
  const auto rule = [&](const std::string& expression, net::Protection p) {
    // Signed: the submessage carries a MAC (GMAC), the data is readable on the wire. Encrypted:
    // the data is AES-GCM encrypted and the submessage signed.
    const std::string_view data = p == net::Protection::Sign ? "NONE" : "ENCRYPT";
    rules += fmt::format(
        "      <topic_rule>\n"
        "        <topic_expression>{}</topic_expression>\n"
        "        <enable_discovery_protection>true</enable_discovery_protection>\n"
        "        <enable_liveliness_protection>true</enable_liveliness_protection>\n"
        "        <enable_read_access_control>true</enable_read_access_control>\n"
        "        <enable_write_access_control>true</enable_write_access_control>\n"
        "        <metadata_protection_kind>SIGN</metadata_protection_kind>\n"
        "        <data_protection_kind>{}</data_protection_kind>\n"
        "      </topic_rule>\n",
        xml_escape(expression), data);
  };
  for (const GovernanceRule& r : spec.rules) {
    auto e = rule_expressions(r);
    if (!e) return std::unexpected(Error(Errc::Config, fmt::format("protection: {}: {}", to_string(r.protection), e.error().message())));
    for (const std::string& x : *e) rule(x, r.protection);
  }
  rule("*", net::Protection::Encrypt);  // every other topic
  return fmt::format(
      "{}<!-- horus governance: made by `horus security governance`; sign it again after an edit -->\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
      "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd\">\n"
      "  <domain_access_rules>\n"
      "    <domain_rule>\n"
      "{}"
      "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
      "      <enable_join_access_control>true</enable_join_access_control>\n"
      "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
      "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
      "      <rtps_protection_kind>NONE</rtps_protection_kind>\n"
      "      <topic_access_rules>\n"
      "{}"
      "      </topic_access_rules>\n"
      "    </domain_rule>\n"
      "  </domain_access_rules>\n"
      "</dds>\n",
      kHeader, domains_xml(spec.domain, "      "), rules);
}

Result<std::string> permissions_xml(const PermissionsSpec& spec) {
  std::vector<std::string> publish = spec.publish, subscribe = spec.subscribe;
  if (spec.fleet_topics) {
    publish.emplace_back(kFleetTopics);
    subscribe.emplace_back(kFleetTopics);
  }
  auto pubs = expressions_of(publish, false);
  if (!pubs) return std::unexpected(Error(Errc::Config, "--publish: " + pubs.error().message()));
  auto subs = expressions_of(subscribe, false);
  if (!subs) return std::unexpected(Error(Errc::Config, "--subscribe: " + subs.error().message()));
  if (!(spec.not_before < spec.not_after))
    return fail(Errc::Config, "the permissions' validity ends before it starts");
  const auto topics = [](const std::vector<std::string>& list, std::string_view what) {
    if (list.empty()) return std::string();
    std::string out = fmt::format("        <{}>\n          <topics>\n", what);
    for (const std::string& t : list) out += fmt::format("            <topic>{}</topic>\n", xml_escape(t));
    return out + fmt::format("          </topics>\n        </{}>\n", what);
  };
  std::string allow;
  if (!pubs->empty() || !subs->empty())
    allow = fmt::format("      <allow_rule>\n{}{}{}      </allow_rule>\n", domains_xml(spec.domain, "        "),
                        topics(*pubs, "publish"), topics(*subs, "subscribe"));
  return fmt::format(
      "{}<!-- horus permissions of '{}': made by `horus security permissions` -->\n"
      "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
      "     xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd\">\n"
      "  <permissions>\n"
      "    <grant name=\"{}\">\n"
      "      <subject_name>{}</subject_name>\n"
      "      <validity>\n"
      "        <not_before>{}</not_before>\n"
      "        <not_after>{}</not_after>\n"
      "      </validity>\n"
      "{}"
      "      <default>DENY</default>\n"
      "    </grant>\n"
      "  </permissions>\n"
      "</dds>\n",
      kHeader, xml_escape(spec.grant), xml_escape(spec.grant), xml_escape(spec.subject), xml_time(spec.not_before),
      xml_time(spec.not_after), allow);
}

TopicProtection protection_of(const GovernanceSpec& spec, std::string_view topic) {
  std::string dds = "horus/";
  for (char c : topic) dds += c == '.' ? '/' : c;
  for (std::size_t i = 0; i < spec.rules.size(); ++i) {
    auto expressions = rule_expressions(spec.rules[i]);
    if (!expressions) continue;  // governance_xml refuses such a rule
    for (const std::string& e : *expressions)
      if (::fnmatch(e.c_str(), dds.c_str(), 0) == 0) return {spec.rules[i].protection, i};
  }
  return {net::Protection::Encrypt, std::nullopt};
}

}  // namespace horus::security
