#include "hub.hpp"

#include <algorithm>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../fleet_cmd.hpp"
#include "../remote_reader.hpp"
#include "../ros2_cmd.hpp"
#include "../typed_reader.hpp"
#include "catalogue.hpp"
#include "horus/fleet.hpp"
#include "horus/names.hpp"
#include "horus/waitset.hpp"
#include "protocol.hpp"
#include "schemas.hpp"

namespace horus::tools::fox {
namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

// The one subscription that feeds a channel's clients.
struct Active {
  std::unique_ptr<RecordSource> source;
  std::unique_ptr<RemoteReader> remote;
  bool remote_json = false;
  std::set<std::pair<std::uint64_t, std::uint32_t>> subscribers;  // (client, subscription)
  std::uint64_t messages = 0, bytes = 0, dropped_before = 0;
};

struct ClientState {
  std::shared_ptr<Client> client;
  std::string peer;
  std::map<std::uint32_t, std::uint32_t> subscriptions;  // subscription id -> channel id
  bool graph = false;
  struct Pub {
    ClientChannel channel;
    std::unique_ptr<PlaySink> sink;       // cdr
    std::unique_ptr<TypedWriter> writer;  // json
    std::uint64_t messages = 0;
  };
  std::map<std::uint32_t, Pub> published;
  Clock::time_point since = Clock::now();
};

class HubImpl final : public Hub {
 public:
  explicit HubImpl(HubOptions o) : o_(std::move(o)), catalogue_(o_.patterns, o_.ns) {}

  bool start(std::string& error) {
    if (!o_.transport.empty()) {
      fleet_ = open_fleet(o_.transport, error);
      if (!fleet_) return false;
    }
    if (!o_.ros2_transport.empty()) {
      auto t = open_ros2_transport(o_.ros2_transport);
      if (!t) {
        error = "--ros2: " + t.error().message();
        return false;
      }
      ros2_ = std::move(*t);
    }
    scan();
    scan_thread_ = std::thread([this] { scan_loop(); });
    pump_thread_ = std::thread([this] { pump_loop(); });
    return true;
  }

  ~HubImpl() override {
    {
      std::lock_guard lock(mu_);
      stopping_ = true;
    }
    cv_.notify_all();
    wake_.fire();
    if (scan_thread_.joinable()) scan_thread_.join();
    if (pump_thread_.joinable()) pump_thread_.join();
    std::lock_guard lock(mu_);
    clients_.clear();
    active_.clear();
    graveyard_.clear();
  }

  std::uint64_t add_client(std::shared_ptr<Client> client, std::string peer) override {
    std::lock_guard lock(mu_);
    const std::uint64_t id = ++next_client_;
    client->send_text(server_info(o_.name, session_, {}));
    std::vector<ServerChannel> all;
    for (const auto& [cid, d] : channels_) all.push_back(d.adv);
    client->send_text(advertise(all));
    auto& st = clients_[id];
    st.client = std::move(client);
    st.peer = std::move(peer);
    return id;
  }

  void remove_client(std::uint64_t id) override {
    std::lock_guard lock(mu_);
    auto it = clients_.find(id);
    if (it == clients_.end()) return;
    for (const auto& [sub, ch] : it->second.subscriptions) drop_subscriber(ch, id, sub);
    for (auto& [cid, pub] : it->second.published) retire(std::move(pub));
    clients_.erase(it);
  }

  void on_text(std::uint64_t id, std::string_view text) override {
    auto op = parse_client_text(text);
    if (!op) {
      reject(id, 1007, op.error());
      return;
    }
    std::visit([&](auto& v) { handle(id, v); }, *op);
  }

  void on_binary(std::uint64_t id, std::span<const std::byte> frame) override {
    auto data = parse_client_binary(frame);
    if (!data) {
      reject(id, 1003, data.error());
      return;
    }
    std::lock_guard lock(mu_);
    ClientState* st = find_client(id);
    if (st == nullptr) return;
    auto pub = st->published.find(data->channel);
    if (pub == st->published.end()) {
      tell(*st, Level::Error,
           fmt::format("client message data on channel {}: no such channel of yours (advertise it first)",
                       data->channel));
      return;
    }
    auto& p = pub->second;
    std::string why;
    if (p.sink) {
      if (auto ok = p.sink->publish(data->payload); !ok) why = ok.error().message();
    } else if (p.writer) {
      const auto* c = reinterpret_cast<const char*>(data->payload.data());
      json j = json::parse(c, c + data->payload.size(), nullptr, false);
      why = j.is_discarded() ? std::string("not JSON") : p.writer->send_json(j);
    }
    if (!why.empty()) {
      tell(*st, Level::Error,
           fmt::format("a message on '{}' ({}) was not published: {}", p.channel.topic, p.channel.schema_name, why));
      return;
    }
    ++p.messages;
  }

  std::string status_json() const override {
    std::lock_guard lock(status_mu_);
    return status_;
  }
  std::size_t channel_count() const override {
    std::lock_guard lock(mu_);
    return channels_.size();
  }

 private:
  // ---- client ops (the I/O thread) ----------------------------------------------------------
  void reject(std::uint64_t id, std::uint16_t code, const std::string& why) {
    std::lock_guard lock(mu_);
    ClientState* st = find_client(id);
    if (st == nullptr) return;
    tell(*st, Level::Error, why);
    st->client->close(code, close_reason(why));
  }
  // The client `id`, or null when it is gone. Holds mu_.
  ClientState* find_client(std::uint64_t id) {
    auto it = clients_.find(id);
    return it == clients_.end() ? nullptr : &it->second;
  }
  static void tell(ClientState& st, Level level, const std::string& message) {
    st.client->send_text(status(level, message));
  }

  void handle(std::uint64_t id, Subscribe& s) {
    std::vector<std::uint32_t> to_open;
    {
      std::lock_guard lock(mu_);
      ClientState* st = find_client(id);
      if (st == nullptr) return;
      for (const auto& item : s.subscriptions) {
        if (st->subscriptions.contains(item.id)) {
          tell(*st, Level::Error,
               fmt::format("subscribe: subscription id {} is in use (unsubscribe it first)", item.id));
          continue;
        }
        if (!channels_.contains(item.channel)) {
          tell(*st, Level::Error, fmt::format("subscribe: channel {} is not advertised", item.channel));
          continue;
        }
        if (std::any_of(st->subscriptions.begin(), st->subscriptions.end(),
                        [&](const auto& kv) { return kv.second == item.channel; })) {
          tell(*st, Level::Error, fmt::format("subscribe: channel {} is already subscribed", item.channel));
          continue;
        }
        st->subscriptions[item.id] = item.channel;
        auto& a = active_[item.channel];
        a.subscribers.insert({id, item.id});
        if (!a.source && !a.remote) to_open.push_back(item.channel);
      }
    }
    for (auto ch : to_open) open_channel(ch);
  }

  void handle(std::uint64_t id, Unsubscribe& u) {
    std::lock_guard lock(mu_);
    ClientState* st = find_client(id);
    if (st == nullptr) return;
    for (auto sub : u.ids) {
      auto s = st->subscriptions.find(sub);
      if (s == st->subscriptions.end()) {
        tell(*st, Level::Warning, fmt::format("unsubscribe: no subscription {}", sub));
        continue;
      }
      drop_subscriber(s->second, id, sub);
      st->subscriptions.erase(s);
    }
  }

  void handle(std::uint64_t id, ClientAdvertise& a) {
    for (auto& c : a.channels) {
      ClientState::Pub pub;
      std::string error;
      std::string type = c.schema_name;
      // horus::msg::CmdVel, horus.msg.CmdVel, horus/msg/CmdVel or CmdVel; another package's name
      // (geometry_msgs/msg/Twist) is not taken for a horus type of the same short name.
      for (std::string_view prefix : {"horus::msg::", "horus.msg.", "horus/msg/"})
        if (type.starts_with(prefix)) type.erase(0, prefix.size());
      if (type.find_first_of(":./") != std::string::npos) type.clear();
      if (!o_.client_publish) {
        error = "this server does not take client messages (horus foxglove --no-publish)";
      } else if (c.encoding != "cdr" && c.encoding != "json") {
        error = fmt::format("encoding '{}' is not supported (cdr or json)", c.encoding);
      } else if (auto ok = validate_topic_name(c.topic); !ok) {
        error = ok.error().message();
      } else if (standard_type(type).empty()) {
        error = fmt::format("schema '{}' is not a standard horus message (e.g. horus::msg::CmdVel)", c.schema_name);
      } else if (c.encoding == "cdr") {
        std::uint64_t hash = 0;
        pub.sink = open_play_sink(type, c.topic, false, nullptr, {}, hash, error);
      } else {
        pub.writer = open_writer(type, c.topic, std::nullopt, error);
      }
      std::lock_guard lock(mu_);
      ClientState* st = find_client(id);
      if (st == nullptr) return;
      if (!pub.sink && !pub.writer) {
        tell(*st, Level::Error,
             fmt::format("advertise: channel {} ('{}', {}): {}", c.id, c.topic, c.schema_name,
                         error.empty() ? std::string("the topic did not open") : error));
        continue;
      }
      if (auto old = st->published.find(c.id); old != st->published.end()) {
        retire(std::move(old->second));
        st->published.erase(old);
      }
      pub.channel = std::move(c);
      st->published.emplace(pub.channel.id, std::move(pub));
    }
  }

  void handle(std::uint64_t id, ClientUnadvertise& u) {
    std::lock_guard lock(mu_);
    ClientState* st = find_client(id);
    if (st == nullptr) return;
    for (auto cid : u.ids) {
      auto p = st->published.find(cid);
      if (p == st->published.end()) {
        tell(*st, Level::Warning, fmt::format("unadvertise: no channel {} of yours", cid));
        continue;
      }
      retire(std::move(p->second));
      st->published.erase(p);
    }
  }

  void handle(std::uint64_t id, SubscribeGraph&) {
    std::lock_guard lock(mu_);
    ClientState* st = find_client(id);
    if (st == nullptr) return;
    st->graph = true;
    if (auto u = graph_update(Graph{}, graph_)) st->client->send_text(*u);
  }
  void handle(std::uint64_t id, UnsubscribeGraph&) {
    std::lock_guard lock(mu_);
    if (auto it = clients_.find(id); it != clients_.end()) it->second.graph = false;
  }
  void handle(std::uint64_t id, Unsupported& u) {
    std::lock_guard lock(mu_);
    if (auto it = clients_.find(id); it != clients_.end())
      tell(
          it->second, Level::Warning,
          fmt::format("'{}' is not offered by this server (capabilities: clientPublish, time, connectionGraph)", u.op));
  }

  // A client publisher's topic is closed by the pump thread (only it destroys topics).
  void retire(ClientState::Pub&& p) {
    graveyard_pubs_.push_back(std::move(p));
    wake_.fire();
  }

  // Holds mu_.
  void drop_subscriber(std::uint32_t channel, std::uint64_t client, std::uint32_t sub) {
    auto a = active_.find(channel);
    if (a == active_.end()) return;
    a->second.subscribers.erase({client, sub});
    if (a->second.subscribers.empty()) {
      graveyard_.push_back(std::move(a->second));
      active_.erase(a);
      dirty_ = true;
      wake_.fire();
    }
  }

  // Opens the subscription that feeds channel `ch` (outside mu_: a network topic takes a while).
  void open_channel(std::uint32_t ch) {
    Desc d;
    {
      std::lock_guard lock(mu_);
      auto it = channels_.find(ch);
      if (it == channels_.end()) return;
      d = it->second;
    }
    Active fresh;
    std::string error;
    std::optional<Backend> backend = Backend::SharedMemory;
    if (!d.via.empty()) backend = Backend::network(*transports_.insert(d.via).first);
    if (d.converted) {
      TopicOptions to;
      to.backend = backend;
      fresh.source = open_foxglove_source(d.type, d.horus_topic, to, o_.frame, error);
    } else if (!d.ros2_type.empty()) {
      fresh.remote = RemoteReader::open_ros2(d.adv.topic, d.via, d.ros2_type, error);
    } else if (d.remote_raw) {
      fresh.remote = RemoteReader::open(d.horus_topic, d.via, d.type, d.hash, d.signature, error);
      fresh.remote_json = d.adv.encoding == "json";
    } else {
      fresh.source = open_record_source(d.type, d.horus_topic, backend, error);
      if (!fresh.source && error.empty()) error = d.type + " is not a standard message";
    }
    std::lock_guard lock(mu_);
    auto a = active_.find(ch);
    if (a == active_.end() || a->second.source || a->second.remote) {
      if (fresh.source || fresh.remote) graveyard_.push_back(std::move(fresh));
      return;
    }
    if (!fresh.source && !fresh.remote) {
      for (const auto& [client, sub] : a->second.subscribers)
        if (auto c = clients_.find(client); c != clients_.end()) {
          tell(c->second, Level::Error, fmt::format("channel {} ('{}') cannot be read: {}", ch, d.adv.topic, error));
          c->second.subscriptions.erase(sub);
        }
      active_.erase(a);
      return;
    }
    fresh.subscribers = std::move(a->second.subscribers);
    a->second = std::move(fresh);
    dirty_ = true;
    wake_.fire();
  }

  // ---- the pump thread -----------------------------------------------------------------------
  void pump_loop() {
    std::unique_ptr<WaitSet> ws;
    std::vector<std::byte> buf;
    bool polled = false;
    while (true) {
      {
        std::unique_lock lock(mu_);
        if (stopping_) break;
        if (dirty_ || !ws) {
          ws.reset();  // before the topics it watches go
          graveyard_.clear();
          ws = std::make_unique<WaitSet>();
          ws->attach(wake_);
          polled = false;
          for (auto& [id, a] : active_) {
            if (a.remote || !a.source || !a.source->attach(*ws)) polled = true;
          }
          dirty_ = false;
        }
        graveyard_pubs_.clear();
      }
      (void)ws->wait(polled ? std::chrono::milliseconds(2) : std::chrono::milliseconds(200));
      wake_.reset();
      std::lock_guard lock(mu_);
      for (auto& [id, a] : active_) drain(a, buf);
    }
  }

  // Takes what channel `a` has (at most 64 messages a turn) to its subscribers. Holds mu_.
  void drain(Active& a, std::vector<std::byte>& buf) {
    for (int n = 0; n < 64; ++n) {
      if (a.source) {
        if (!a.source->next(RecordFormat::Mcap, buf)) return;
      } else if (a.remote) {
        auto s = a.remote->recv(a.remote_json);
        if (!s) return;
        if (a.remote_json) {
          if (s->value.is_null()) continue;
          const std::string text = s->value.dump(-1, ' ', false, json::error_handler_t::replace);
          const auto* p = reinterpret_cast<const std::byte*>(text.data());
          buf.assign(p, p + text.size());
        } else {
          buf.assign({std::byte{0}, std::byte{s->little_endian ? std::uint8_t{1} : std::uint8_t{0}}, std::byte{0},
                      std::byte{0}});
          buf.insert(buf.end(), s->body.begin(), s->body.end());
        }
      } else {
        return;
      }
      const std::uint64_t now = unix_ns();
      ++a.messages;
      a.bytes += buf.size();
      auto payload = std::make_shared<const std::vector<std::byte>>(std::move(buf));
      buf = {};
      for (const auto& [client, sub] : a.subscribers)
        if (auto c = clients_.find(client); c != clients_.end()) c->second.client->send_data(sub, now, payload);
    }
  }

  // ---- the scan thread -----------------------------------------------------------------------
  void scan_loop() {
    auto next_scan = Clock::now() + std::chrono::milliseconds(500);
    while (true) {
      {
        std::unique_lock lock(mu_);
        if (cv_.wait_for(lock, std::chrono::milliseconds(100), [&] { return stopping_; })) return;
        const auto now = unix_ns();
        for (auto& [id, st] : clients_) st.client->send_time(now);
      }
      if (Clock::now() >= next_scan) {
        scan();
        next_scan = Clock::now() + std::chrono::milliseconds(500);
      }
    }
  }

  // Unadvertises the channels that went (or changed), advertises those that came, and sends the
  // graph's changes to the clients that asked for it. Holds mu_.
  void update_channels(Scan& s) {
    auto& want = s.channels;
    auto& graph = s.graph;
    // unadvertise what went (or changed), advertise what came
    std::vector<std::uint32_t> gone;
    for (auto it = channels_.begin(); it != channels_.end();) {
      auto w = want.find(it->second.adv.topic);
      if (w != want.end() && w->second == it->second) {
        want.erase(w);
        ++it;
        continue;
      }
      gone.push_back(it->first);
      if (auto a = active_.find(it->first); a != active_.end()) {
        for (const auto& [client, sub] : a->second.subscribers)
          if (auto c = clients_.find(client); c != clients_.end()) c->second.subscriptions.erase(sub);
        graveyard_.push_back(std::move(a->second));
        active_.erase(a);
        dirty_ = true;
      }
      it = channels_.erase(it);
    }
    std::vector<ServerChannel> added;
    for (auto& [topic, d] : want) {
      const std::string key = d.adv.topic + "\n" + d.adv.schema_name + "\n" + d.adv.schema + "\n" + d.via;
      auto& id = ids_[key];
      if (id == 0) id = ++next_channel_;
      d.adv.id = id;
      added.push_back(d.adv);
      channels_[id] = std::move(d);
    }
    for (auto& [id, st] : clients_) {
      if (!gone.empty()) st.client->send_text(unadvertise(gone));
      if (!added.empty()) st.client->send_text(advertise(added));
      if (st.graph)
        if (auto u = graph_update(graph_, graph)) st.client->send_text(*u);
    }
    graph_ = std::move(graph);
  }

  // The status page's channels. Holds mu_.
  json channels_status() const {
    json channels = json::array();
    for (const auto& [id, d] : channels_) {
      json c{{"id", id},
             {"topic", d.adv.topic},
             {"schema", d.adv.schema_name},
             {"encoding", d.adv.encoding},
             {"subscribers", 0},
             {"messages", 0},
             {"bytes", 0}};
      if (auto a = active_.find(id); a != active_.end()) {
        c["subscribers"] = a->second.subscribers.size();
        c["messages"] = a->second.messages;
        c["bytes"] = a->second.bytes;
      }
      channels.push_back(std::move(c));
    }
    return channels;
  }

  // The status page's clients. Holds mu_.
  json clients_status() const {
    json clients = json::array();
    for (const auto& [id, st] : clients_) {
      const auto cs = st.client->stats();
      std::uint64_t published = 0;
      for (const auto& [cid, p] : st.published) published += p.messages;
      clients.push_back({{"id", id},
                         {"peer", st.peer},
                         {"subscriptions", st.subscriptions.size()},
                         {"sent", cs.sent},
                         {"dropped", cs.dropped},
                         {"queued_bytes", cs.queued_bytes},
                         {"published", published},
                         {"connected_s", std::chrono::duration<double>(Clock::now() - st.since).count()}});
    }
    return clients;
  }

  void scan() {
    Scan s = catalogue_.scan(fleet_.get(), ros2_.get());
    std::lock_guard lock(mu_);
    update_channels(s);
    if (dirty_) wake_.fire();

    // the status page's figures
    json channels = channels_status();
    json clients = clients_status();
    json all{{"server",
              {{"name", o_.name},
               {"host", s.host},
               {"transport", o_.transport},
               {"namespace", o_.ns},
               {"unix_ms", unix_ns() / 1'000'000}}},
             {"hosts", s.hosts},
             {"topics", s.topics},
             {"channels", channels},
             {"clients", clients},
             {"unserved", s.unserved}};
    std::lock_guard slock(status_mu_);
    status_ = all.dump(-1, ' ', false, json::error_handler_t::replace);
  }

  HubOptions o_;
  Catalogue catalogue_;  // the scan thread's
  std::string session_ = std::to_string(unix_ns());
  std::unique_ptr<Fleet> fleet_;
  std::shared_ptr<net::Transport> ros2_;  // --ros2: the domain's discovery
  std::set<std::string, std::less<>> transports_;  // Backend keeps a view of the name

  mutable std::mutex mu_;  // what follows
  std::condition_variable cv_;
  bool stopping_ = false;
  std::map<std::uint64_t, ClientState> clients_;
  std::uint64_t next_client_ = 0;
  std::map<std::uint32_t, Desc> channels_;
  std::map<std::string, std::uint32_t> ids_;  // a channel that comes back gets its id back
  std::uint32_t next_channel_ = 0;
  std::map<std::uint32_t, Active> active_;
  std::vector<Active> graveyard_;  // closed by the pump thread, after its wait set
  std::vector<ClientState::Pub> graveyard_pubs_;
  bool dirty_ = false;
  Graph graph_;
  Trigger wake_;

  mutable std::mutex status_mu_;
  std::string status_ = "{}";

  std::thread scan_thread_, pump_thread_;
};

}  // namespace

std::unique_ptr<Hub> Hub::start(HubOptions options, std::string& error) {
  auto hub = std::make_unique<HubImpl>(std::move(options));
  if (!hub->start(error)) return nullptr;
  return hub;
}

}  // namespace horus::tools::fox
