#include "protocol.hpp"

#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace horus::tools::fox {
namespace {

using json = nlohmann::json;
using Fail = std::unexpected<std::string>;

constexpr std::string_view kOps =
    "subscribe, unsubscribe, advertise, unadvertise, subscribeConnectionGraph, unsubscribeConnectionGraph";

std::string shown(const json& v) {
  std::string s = v.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

// `v` as an unsigned 32-bit integer, or nothing (a float, a negative number, a larger one).
std::optional<std::uint32_t> as_u32(const json& v) {
  if (!v.is_number_integer() || (!v.is_number_unsigned() && v.get<std::int64_t>() < 0) ||
      v.get<std::uint64_t>() > 0xffffffffULL)
    return std::nullopt;
  return static_cast<std::uint32_t>(v.get<std::uint64_t>());
}

// A field of `obj` that must be an unsigned 32-bit integer; `where` names it in the error.
std::expected<std::uint32_t, std::string> u32(const json& obj, const char* key, const std::string& where) {
  auto it = obj.find(key);
  if (it == obj.end()) return Fail(fmt::format("{}.{} is missing (an unsigned 32-bit integer)", where, key));
  if (auto v = as_u32(*it)) return *v;
  return Fail(fmt::format("{}.{} must be an unsigned 32-bit integer, not {}", where, key, shown(*it)));
}

std::expected<std::string, std::string> str(const json& obj, const char* key, const std::string& where) {
  auto it = obj.find(key);
  if (it == obj.end()) return Fail(fmt::format("{}.{} is missing (a string)", where, key));
  if (!it->is_string()) return Fail(fmt::format("{}.{} must be a string, not {}", where, key, shown(*it)));
  return it->get<std::string>();
}

std::expected<const json*, std::string> array(const json& obj, const char* key, const std::string& op) {
  auto it = obj.find(key);
  if (it == obj.end()) return Fail(fmt::format("{}: '{}' is missing (an array)", op, key));
  if (!it->is_array()) return Fail(fmt::format("{}: '{}' must be an array, not {}", op, key, shown(*it)));
  if (it->size() > 65536) return Fail(fmt::format("{}: '{}' has {} entries (at most 65536)", op, key, it->size()));
  return &*it;
}

std::expected<std::vector<std::uint32_t>, std::string> ids(const json& obj, const char* key, const std::string& op) {
  auto a = array(obj, key, op);
  if (!a) return Fail(a.error());
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < (*a)->size(); ++i) {
    const json& v = (**a)[i];
    auto id = as_u32(v);
    if (!id) return Fail(fmt::format("{}: {}[{}] must be an unsigned 32-bit integer, not {}", op, key, i, shown(v)));
    out.push_back(*id);
  }
  return out;
}

std::expected<ClientOp, std::string> parse_subscribe(const json& j) {
  auto a = array(j, "subscriptions", "subscribe");
  if (!a) return Fail(a.error());
  Subscribe s;
  for (std::size_t i = 0; i < (*a)->size(); ++i) {
    const json& e = (**a)[i];
    const std::string where = fmt::format("subscribe: subscriptions[{}]", i);
    if (!e.is_object()) return Fail(fmt::format("{} must be an object {{id, channelId}}, not {}", where, shown(e)));
    auto id = u32(e, "id", where);
    if (!id) return Fail(id.error());
    auto ch = u32(e, "channelId", where);
    if (!ch) return Fail(ch.error());
    s.subscriptions.push_back({*id, *ch});
  }
  return s;
}

std::expected<ClientOp, std::string> parse_advertise(const json& j) {
  auto a = array(j, "channels", "advertise");
  if (!a) return Fail(a.error());
  ClientAdvertise adv;
  for (std::size_t i = 0; i < (*a)->size(); ++i) {
    const json& e = (**a)[i];
    const std::string where = fmt::format("advertise: channels[{}]", i);
    if (!e.is_object())
      return Fail(fmt::format("{} must be an object {{id, topic, encoding, schemaName}}, not {}", where, shown(e)));
    ClientChannel c;
    auto id = u32(e, "id", where);
    if (!id) return Fail(id.error());
    c.id = *id;
    for (auto [key, out] : {std::pair{"topic", &c.topic}, {"encoding", &c.encoding}, {"schemaName", &c.schema_name}}) {
      auto v = str(e, key, where);
      if (!v) return Fail(v.error());
      *out = std::move(*v);
    }
    for (auto [key, out] : {std::pair{"schema", &c.schema}, {"schemaEncoding", &c.schema_encoding}}) {
      if (!e.contains(key) || e[key].is_null()) continue;
      auto v = str(e, key, where);
      if (!v) return Fail(v.error());
      *out = std::move(*v);
    }
    adv.channels.push_back(std::move(c));
  }
  return adv;
}

void put_le(std::byte* p, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xff);
}

}  // namespace

std::expected<ClientOp, std::string> parse_client_text(std::string_view text) {
  json j = json::parse(text, nullptr, false);
  if (j.is_discarded())
    return Fail(
        fmt::format("a text frame must be a JSON object with an \"op\"; this one ({} bytes) is not JSON", text.size()));
  if (!j.is_object()) return Fail(fmt::format("a text frame must be a JSON object with an \"op\", not {}", shown(j)));
  auto op_it = j.find("op");
  if (op_it == j.end() || !op_it->is_string())
    return Fail(fmt::format("a text frame needs \"op\", a string (one of {})", kOps));
  const std::string op = op_it->get<std::string>();
  if (op == "subscribe") return parse_subscribe(j);
  if (op == "unsubscribe") {
    auto v = ids(j, "subscriptionIds", op);
    if (!v) return Fail(v.error());
    return Unsubscribe{std::move(*v)};
  }
  if (op == "advertise") return parse_advertise(j);
  if (op == "unadvertise") {
    auto v = ids(j, "channelIds", op);
    if (!v) return Fail(v.error());
    return ClientUnadvertise{std::move(*v)};
  }
  if (op == "subscribeConnectionGraph") return SubscribeGraph{};
  if (op == "unsubscribeConnectionGraph") return UnsubscribeGraph{};
  // The protocol's other client ops (parameters, assets; a service call is binary).
  static constexpr std::array<std::string_view, 5> kOthers = {
      "getParameters", "setParameters", "subscribeParameterUpdates", "unsubscribeParameterUpdates", "fetchAsset"};
  if (std::find(kOthers.begin(), kOthers.end(), op) != kOthers.end()) return Unsupported{op};
  return Fail(fmt::format("unknown op {} (expected one of {})", shown(*op_it), kOps));
}

std::expected<ClientData, std::string> parse_client_binary(std::span<const std::byte> frame) {
  if (frame.empty()) return Fail("an empty binary frame (expected opcode 0x01, client message data)");
  const auto opcode = std::to_integer<unsigned>(frame[0]);
  if (opcode == 0x02) return Fail("binary opcode 0x02 (a service call): this server offers no services");
  if (opcode != 0x01)
    return Fail(fmt::format("unknown binary opcode 0x{:02x} (expected 0x01, client message data)", opcode));
  if (frame.size() < 5)
    return Fail(fmt::format("client message data of {} bytes: shorter than its 5-byte header", frame.size()));
  std::uint32_t ch = 0;
  for (int i = 0; i < 4; ++i) ch |= std::to_integer<std::uint32_t>(frame[1 + i]) << (8 * i);
  return ClientData{ch, frame.subspan(5)};
}

std::string server_info(std::string_view name, std::string_view session_id, std::span<const std::string> metadata_kv) {
  json meta = json::object();
  for (std::size_t i = 0; i + 1 < metadata_kv.size(); i += 2) meta[metadata_kv[i]] = metadata_kv[i + 1];
  json j{{"op", "serverInfo"},
         {"name", name},
         {"capabilities", {"clientPublish", "time", "connectionGraph"}},
         {"supportedEncodings", {"cdr", "json"}},
         {"metadata", meta},
         {"sessionId", session_id}};
  return j.dump();
}

std::string advertise(std::span<const ServerChannel> channels) {
  json list = json::array();
  for (const auto& c : channels)
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise(std::span<const std::uint32_t> ids) {
  return json{{"op", "unadvertise"}, {"channelIds", std::vector<std::uint32_t>(ids.begin(), ids.end())}}.dump();
}

std::string status(Level level, std::string_view message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::optional<std::string> graph_update(const Graph& before, const Graph& now) {
  const auto side = [](const std::vector<GraphTopic>& b, const std::vector<GraphTopic>& n, const char* key,
                       json& changed, std::set<std::string>& removed, std::set<std::string>& present) {
    std::map<std::string, const GraphTopic*> old;
    for (const auto& t : b) old[t.name] = &t;
    for (const auto& t : n) {
      present.insert(t.name);
      auto it = old.find(t.name);
      if (it != old.end() && *it->second == t) continue;
      changed.push_back({{"name", t.name}, {key, t.ids}});
    }
    for (const auto& t : b) removed.insert(t.name);
  };
  json pub = json::array(), sub = json::array();
  std::set<std::string> gone, present;
  side(before.published, now.published, "publisherIds", pub, gone, present);
  side(before.subscribed, now.subscribed, "subscriberIds", sub, gone, present);
  json removed = json::array();
  for (const auto& name : gone)
    if (!present.contains(name)) removed.push_back(name);
  if (pub.empty() && sub.empty() && removed.empty()) return std::nullopt;
  return json{{"op", "connectionGraphUpdate"},       {"publishedTopics", pub},   {"subscribedTopics", sub},
              {"advertisedServices", json::array()}, {"removedTopics", removed}, {"removedServices", json::array()}}
      .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::array<std::byte, 13> message_data_header(std::uint32_t subscription, std::uint64_t receive_ns) {
  std::array<std::byte, 13> h{};
  h[0] = std::byte{0x01};
  put_le(h.data() + 1, subscription, 4);
  put_le(h.data() + 5, receive_ns, 8);
  return h;
}

std::array<std::byte, 9> time_frame(std::uint64_t ns) {
  std::array<std::byte, 9> h{};
  h[0] = std::byte{0x02};
  put_le(h.data() + 1, ns, 8);
  return h;
}

std::string close_reason(std::string_view why) {
  if (why.size() <= 123) return std::string(why);
  std::string s(why.substr(0, 120));
  while (!s.empty() && (static_cast<unsigned char>(s.back()) & 0xc0) == 0x80) s.pop_back();  // whole UTF-8
  if (!s.empty() && (static_cast<unsigned char>(s.back()) & 0x80)) s.pop_back();
  return s + "...";
}

}  // namespace horus::tools::fox
