// DDS-Security's two access-control documents, made from horus's topic patterns: the governance
// (how each topic is protected, for the whole fleet) and a host's permissions (what it may
// publish and subscribe). Text only: signing is keystore.hpp's.
//
// A horus topic `a.b.c` is the DDS topic `horus/a/b/c` (backend_dds); a pattern is turned into
// the fnmatch expressions DDS-Security matches topic names with. `**` maps exactly (each one
// becomes two expressions: nothing, or `*` for one or more segments). A single `*` (one
// segment) cannot be said in fnmatch, whose `*` also crosses '/': where a wider match would
// grant more than asked (a permission, or a `sign` rule that would weaken protection) it is
// refused; in an `encrypt` rule it is widened (a stronger protection for more topics).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::security {

/// The DDS topic-name expressions (fnmatch) of a horus pattern (checked with
/// check_topic_pattern); `widen_single`: a `*` segment may become fnmatch's `*` (which also
/// matches several segments), else such a pattern is an error saying so.
Result<std::vector<std::string>> dds_topic_expressions(std::string_view pattern, bool widen_single);

/// `text` with XML's five special characters escaped.
std::string xml_escape(std::string_view text);

/// The fleet layer's own topics (heartbeats, announcements, requests): `horus.fleet.**`.
inline constexpr std::string_view kFleetTopics = "horus.fleet.**";

struct GovernanceRule {
  std::string pattern;  // a horus topic pattern
  net::Protection protection = net::Protection::Encrypt;
};
struct GovernanceSpec {
  /// The rules in order (the first that matches a topic wins); every other topic is encrypted.
  std::vector<GovernanceRule> rules;
  std::optional<std::uint32_t> domain;  // nullopt: every domain (0..230, Cyclone DDS's)
};
/// The governance document: authenticated participants only (join access control), discovery
/// and liveliness encrypted, read and write access control on every topic, each topic's data
/// encrypted or signed per `spec`.
Result<std::string> governance_xml(const GovernanceSpec& spec);

/// How the governance of `spec` protects horus topic `topic`, as DDS-Security matches it (the
/// first rule whose expressions match its DDS name): the protection, and the rule's index in
/// spec.rules (nullopt: no rule matches, the topic is encrypted).
struct TopicProtection {
  net::Protection protection = net::Protection::Encrypt;
  std::optional<std::size_t> rule;
};
TopicProtection protection_of(const GovernanceSpec& spec, std::string_view topic);

struct PermissionsSpec {
  std::string grant;    // the grant's name (the host's identity name)
  std::string subject;  // the subject name of the host's certificate ("CN=robot1,O=horus", RFC 2253)
  std::vector<std::string> publish;    // horus topic patterns
  std::vector<std::string> subscribe;  // horus topic patterns
  bool fleet_topics = true;            // also allow kFleetTopics both ways
  std::optional<std::uint32_t> domain;  // nullopt: every domain (0..230, Cyclone DDS's)
  std::chrono::system_clock::time_point not_before, not_after;
};
/// A host's permissions document: one grant allowing what `spec` lists, denying the rest.
Result<std::string> permissions_xml(const PermissionsSpec& spec);

}  // namespace horus::security

HORUS_API_END
