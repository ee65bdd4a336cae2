// LCM URLs and channel names for the LCM transport: check_url (what liblcm's lcm_create would
// only complain about on stderr), url_from (the URL of a net::Config),
// check_channel and channel_name, provider_hint (what to check when LCM cannot start). Nothing here
// touches the network.
#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "horus/names.hpp"
#include "lcm_internal.hpp"

namespace horus::lcm {
namespace detail {

std::optional<std::uint64_t> parse_decimal(std::string_view s, std::uint64_t max) noexcept {
  const bool digits = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits || s.size() > 19) return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v > max) return std::nullopt;
  return v;
}

namespace {

constexpr std::string_view kUdpmExpected =
    "udpm://<IPv4 224.0.0.0-239.255.255.255>:<port>[?ttl=0..255&recv_buf_size=N]";
constexpr std::string_view kUdpmOptionsExpected =
    "udpm options ttl=0..255, recv_buf_size=<bytes, at least 1> and transmit_only=true|false, separated by '&'";
constexpr std::string_view kFileExpected = "file://<path>[?mode=r|w|a&speed=<number>&start_timestamp=<integer>]";
constexpr std::string_view kTcpqExpected = "tcpq://[<host>[:<port 1..65535>]] with no options";
constexpr std::string_view kSchemesExpected = "udpm://..., memq://, file://... or tcpq://...";

std::string url_error(std::string_view url, std::string_view problem, std::string_view expected) {
  std::string m = "LCM URL '";
  m += url;
  m += "': ";
  m += problem;
  m += "; expected ";
  m += expected;
  m += " (the default is ";
  m += kDefaultUrl;
  m += ")";
  return m;
}

std::string quoted(std::string_view s) { return "'" + std::string(s) + "'"; }

bool all_digits(std::string_view s) noexcept {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}


// Dotted-quad IPv4, decimal octets 0..255 without leading zeros (inet_aton would read "010"
// as octal and "1.2" as a short form: both are refused).
std::optional<std::array<std::uint8_t, 4>> parse_ipv4(std::string_view s) noexcept {
  std::array<std::uint8_t, 4> out{};
  for (std::size_t i = 0; i < 4; i++) {
    const std::size_t dot = s.find('.');
    const std::string_view part = i < 3 ? s.substr(0, dot) : s;
    if (i < 3 && dot == std::string_view::npos) return std::nullopt;
    if (part.size() > 3 || (part.size() > 1 && part[0] == '0')) return std::nullopt;
    const auto v = parse_decimal(part, 255);
    if (!v) return std::nullopt;
    out[i] = static_cast<std::uint8_t>(*v);
    if (i < 3) s.remove_prefix(dot + 1);
  }
  return out;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t at = s.find(sep);
    out.push_back(s.substr(0, at));
    if (at == std::string_view::npos) return out;
    s.remove_prefix(at + 1);
  }
}

// Splits "k=v&k=v" into pairs; problems are reported with `expected`.
Result<std::vector<std::pair<std::string_view, std::string_view>>> parse_options(std::string_view url,
                                                                                 std::string_view options,
                                                                                 std::string_view expected) {
  std::vector<std::pair<std::string_view, std::string_view>> out;
  if (options.empty()) return fail(Errc::Config, url_error(url, "'?' is followed by no option", expected));
  for (std::string_view item : split(options, '&')) {
    if (item.empty()) return fail(Errc::Config, url_error(url, "an empty option (a stray '&')", expected));
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0)
      return fail(Errc::Config, url_error(url, "option " + quoted(item) + " is not of the form name=value", expected));
    const std::string_view key = item.substr(0, eq);
    for (const auto& [k, v] : out)
      if (k == key) return fail(Errc::Config, url_error(url, "option '" + std::string(key) + "' is given twice", expected));
    out.emplace_back(key, item.substr(eq + 1));
  }
  return out;
}

Result<UrlInfo> check_udpm(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::Udpm;
  const std::size_t q = rest.find('?');
  const std::string_view host = rest.substr(0, q);
  if (host.empty()) return fail(Errc::Config, url_error(url, "no multicast address and port", kUdpmExpected));
  const std::size_t colon = host.rfind(':');
  const std::string_view addr = host.substr(0, colon);
  if (addr.empty()) return fail(Errc::Config, url_error(url, "no multicast address", kUdpmExpected));
  const auto ip = parse_ipv4(addr);
  if (!ip) return fail(Errc::Config, url_error(url, quoted(addr) + " is not an IPv4 address", kUdpmExpected));
  if ((*ip)[0] < 224 || (*ip)[0] > 239)
    return fail(Errc::Config, url_error(url, std::string(addr) + " is not a multicast address", kUdpmExpected));
  if (colon == std::string_view::npos || colon + 1 == host.size())
    return fail(Errc::Config, url_error(url, "the port is missing (liblcm would start but never receive)", kUdpmExpected));
  const std::string_view port = host.substr(colon + 1);
  if (!all_digits(port)) return fail(Errc::Config, url_error(url, "port " + quoted(port) + " is not a decimal number", kUdpmExpected));
  const auto p = parse_decimal(port, 65535);
  if (!p || *p == 0) return fail(Errc::Config, url_error(url, "port " + std::string(port) + " is out of range 1..65535", kUdpmExpected));
  info.port = static_cast<std::uint16_t>(*p);
  info.group = *ip;
  if (q == std::string_view::npos) return info;

  auto options = parse_options(url, rest.substr(q + 1), kUdpmOptionsExpected);
  if (!options) return std::unexpected(std::move(options.error()));
  for (const auto& [key, value] : *options) {
    if (key == "ttl") {
      if (!parse_decimal(value, 255))
        return fail(Errc::Config, url_error(url, "ttl=" + std::string(value) + " is not an integer 0..255", kUdpmOptionsExpected));
    } else if (key == "recv_buf_size") {
      const auto v = parse_decimal(value, static_cast<std::uint64_t>(INT_MAX));
      if (!v || *v == 0)
        return fail(Errc::Config, url_error(url, "recv_buf_size=" + std::string(value) + " is not a positive integer (bytes, at most " +
                                                     std::to_string(INT_MAX) + ")",
                                            kUdpmOptionsExpected));
      info.recv_buf_size = static_cast<std::uint32_t>(*v);
    } else if (key == "transmit_only") {
      if (value != "true" && value != "false")
        return fail(Errc::Config, url_error(url, "transmit_only=" + std::string(value) + " is neither true nor false", kUdpmOptionsExpected));
      info.transmit_only = value == "true";
    } else {
      return fail(Errc::Config, url_error(url, "unknown udpm option '" + std::string(key) + "'", kUdpmOptionsExpected));
    }
  }
  return info;
}

Result<UrlInfo> check_file(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::File;
  const std::size_t q = rest.find('?');
  if (rest.substr(0, q).empty()) return fail(Errc::Config, url_error(url, "no file path", kFileExpected));
  if (q == std::string_view::npos) return info;
  auto options = parse_options(url, rest.substr(q + 1), kFileExpected);
  if (!options) return std::unexpected(std::move(options.error()));
  for (const auto& [key, value] : *options) {
    if (key == "mode") {
      if (value != "r" && value != "w" && value != "a")
        return fail(Errc::Config, url_error(url, "mode=" + std::string(value) + " is not r, w or a", kFileExpected));
      info.file_read = value == "r";
    } else if (key == "speed") {
      double v = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (value.empty() || ec != std::errc() || end != value.data() + value.size() || !std::isfinite(v))
        return fail(Errc::Config, url_error(url, "speed=" + std::string(value) + " is not a number", kFileExpected));
    } else if (key == "start_timestamp") {
      std::int64_t v = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (value.empty() || ec != std::errc() || end != value.data() + value.size())
        return fail(Errc::Config,
                    url_error(url, "start_timestamp=" + std::string(value) + " is not an integer (microseconds)", kFileExpected));
    } else {
      return fail(Errc::Config, url_error(url, "unknown file option '" + std::string(key) + "'", kFileExpected));
    }
  }
  return info;
}

Result<UrlInfo> check_tcpq(std::string_view url, std::string_view rest) {
  UrlInfo info;
  info.provider = Provider::Tcpq;
  if (rest.find('?') != std::string_view::npos)
    return fail(Errc::Config, url_error(url, "tcpq takes no options", kTcpqExpected));
  if (rest.empty()) return info;  // liblcm's default, 127.0.0.1:7700
  const std::size_t colon = rest.find(':');
  const std::string_view host = rest.substr(0, colon);
  const bool host_ok = !host.empty() && std::all_of(host.begin(), host.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-';
  });
  if (!host_ok) return fail(Errc::Config, url_error(url, quoted(host) + " is not a host name or IPv4 address", kTcpqExpected));
  if (colon != std::string_view::npos) {
    const std::string_view port = rest.substr(colon + 1);
    const auto p = parse_decimal(port, 65535);
    if (!p || *p == 0) return fail(Errc::Config, url_error(url, "port " + quoted(port) + " is not a number 1..65535", kTcpqExpected));
  }
  return info;
}

}  // namespace

Result<UrlInfo> parse_url(std::string_view url) {
  if (url.empty()) return fail(Errc::Config, url_error(url, "the URL is empty", kSchemesExpected));
  if (url.find('\0') != std::string_view::npos)
    return fail(Errc::Config, url_error(url, "the URL contains a NUL byte", kSchemesExpected));
  const std::size_t sep = url.find("://");
  if (sep == std::string_view::npos || sep == 0)
    return fail(Errc::Config, url_error(url, "no '<scheme>://' at the start", kSchemesExpected));
  const std::string_view scheme = url.substr(0, sep);
  const std::string_view rest = url.substr(sep + 3);
  if (scheme == "udpm") return check_udpm(url, rest);
  if (scheme == "file") return check_file(url, rest);
  if (scheme == "tcpq") return check_tcpq(url, rest);
  if (scheme == "memq") {
    if (!rest.empty()) return fail(Errc::Config, url_error(url, "memq takes no host part and no options", "memq://"));
    UrlInfo info;
    info.provider = Provider::Memq;
    return info;
  }
  return fail(Errc::Config, url_error(url, "unknown scheme '" + std::string(scheme) + "'", kSchemesExpected));
}

std::string provider_hint(const std::string& url, const UrlInfo& info) {
  switch (info.provider) {
    case Provider::Udpm:
      return "; for udpm the usual cause is a host with no multicast route: add one with "
             "`ip route add 224.0.0.0/4 dev <interface>` (or `dev lo` for one host)";
    case Provider::File:
      return info.file_read ? "; check that the log file exists, is readable and holds at least one event"
                            : "; check that the log file's directory exists and is writable";
    case Provider::Tcpq:
      return "; check that an LCM TCP queue server listens at " +
             (url.size() > 7 ? url.substr(7) : std::string("127.0.0.1:7700"));
    case Provider::Memq: break;
  }
  return "";
}

}  // namespace detail

using detail::parse_url;

Result<void> check_url(std::string_view url) {
  auto info = parse_url(url);
  if (!info) return std::unexpected(std::move(info.error()));
  return {};
}

Result<std::string> url_from(const net::Config& config) {
  if (config.security.mode == net::SecurityMode::Enforce)
    return fail(Errc::Config, config.security.origin +
                                  " is enforce, but LCM has no security (no authentication, access control or "
                                  "encryption): a fleet topic on LCM cannot be protected. Put the fleet topics on "
                                  "cyclonedds or fastdds, or make security permissive to let LCM topics run unprotected");
  const std::string url = config.lcm_url.empty() ? std::string(kDefaultUrl) : config.lcm_url;
  if (!config.lcm_url.empty())
    if (auto ok = check_url(config.lcm_url); !ok)
      return fail(Errc::Config, config.lcm_url_origin + ": " + ok.error().message());
  if (!config.peers.empty() && url.starts_with("udpm://"))
    return fail(Errc::Config, config.peers_origin + " lists peers (unicast to those hosts, multicast off), but LCM's "
                              "udpm transport needs multicast: LCM has no unicast discovery. Use cyclonedds or "
                              "fastdds for the fleet topics on a network without multicast, or remove the peers");
  return url;
}

std::string control_url(std::string_view url) {
  auto info = parse_url(url);
  if (!info || info->provider != detail::Provider::Udpm) return std::string(url);
  // udpm://A.B.C.D:PORT[?opts] (parse_url checked it): the port is the digits before '?' or the end.
  const std::size_t q = std::min(url.find('?'), url.size());
  const std::size_t colon = url.rfind(':', q);
  const unsigned port = info->port == 65535 ? 65534u : info->port + 1u;
  return std::string(url.substr(0, colon + 1)) + std::to_string(port) + std::string(url.substr(q));
}

Result<std::string> check_channel(std::string_view channel) {
  if (channel.empty())
    return fail(Errc::InvalidName, "empty LCM channel name; expected 1.." + std::to_string(kMaxChannelLength) +
                                       " bytes, e.g. 'horus/fleet/robot_1/pose'");
  if (channel.size() > kMaxChannelLength)
    return fail(Errc::InvalidName, "LCM channel '" + std::string(channel) + "' is " + std::to_string(channel.size()) +
                                       " bytes; LCM channel names are at most " + std::to_string(kMaxChannelLength) +
                                       " bytes (a longer one is neither sent nor received)");
  for (std::size_t i = 0; i < channel.size(); i++) {
    const auto c = static_cast<unsigned char>(channel[i]);
    if (c < 0x20 || c >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", c);
      std::string shown(channel);
      std::replace_if(shown.begin(), shown.end(), [](char ch) { return ch == '\0'; }, '?');
      return fail(Errc::InvalidName, "LCM channel '" + shown + "' has byte " + hex + " at offset " + std::to_string(i) +
                                         "; expected printable ASCII (liblcm matches channels as UTF-8 regexes "
                                         "and C strings)");
    }
  }
  return std::string(channel);
}

Result<std::string> channel_name(std::string_view topic) {
  if (auto ok = validate_topic_name(topic); !ok) return std::unexpected(std::move(ok.error()));
  if (topic.size() > kMaxChannelLength)
    return fail(Errc::InvalidName,
                "topic '" + std::string(topic) + "': " + std::to_string(topic.size()) +
                    " characters is too long for an LCM channel (the channel is the topic name, and LCM channels "
                    "are at most " + std::to_string(kMaxChannelLength) + " bytes); use a name of at most " +
                    std::to_string(kMaxChannelLength) + " characters on the lcm backend");
  return std::string(topic);
}

}  // namespace horus::lcm
