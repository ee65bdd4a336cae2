#include "remote_reader.hpp"

#include <condition_variable>
#include <deque>
#include <mutex>
#include <vector>

#include "horus/backend.hpp"
#include "horus/config.hpp"
#include "horus/network.hpp"
#include "horus/transport_registry.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus::tools {

namespace {

constexpr std::size_t kQueue = 4096;

class NetworkReader final : public RemoteReader, public net::Listener {
 public:
  NetworkReader(wire::DynType type, net::WireFormat format) : type_(std::move(type)), format_(format) {}
  ~NetworkReader() override { endpoint_.reset(); }  // no callback after this

  bool start(const net::TransportInfo& info, const net::EndpointSpec& spec, std::string& error) {
    auto config = net::config_from_environment();
    if (!config) {
      error = config.error().message();
      return false;
    }
    // The fleet layer's own topics (fleet_messages.hpp) travel on the transport's control
    // instance where it has one (LCM: the next port), as the fleet layer sends them.
    auto t = info.open_for(spec.topic, *config);
    if (!t) {
      error = t.error().message();
      return false;
    }
    transport_ = std::move(*t);
    auto ep = transport_->open(spec, *this);
    if (!ep) {
      error = ep.error().message();
      return false;
    }
    endpoint_ = std::move(*ep);
    return true;
  }

  void on_sample(const net::Sample& s) override {
    std::lock_guard lock(mutex_);
    if (queue_.size() >= kQueue) {
      queue_.pop_front();
      ++overflowed_;
    }
    queue_.push_back({std::vector<std::byte>(s.body.begin(), s.body.end()), s.little_endian});
    cv_.notify_one();
  }
  void on_error(std::string_view) override {}

  std::optional<Sample> recv(bool decode) override {
    Raw raw;
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) return std::nullopt;
      raw = std::move(queue_.front());
      queue_.pop_front();
    }
    Sample out;
    out.bytes = raw.body.size();
    if (decode) {
      auto j = wire::decode_json(type_, format_ == net::WireFormat::Lcm ? wire::DynFormat::Lcm : wire::DynFormat::Xcdr1,
                                 raw.body, raw.little_endian);
      if (j) out.value = std::move(*j);
      else out.error = j.error();
    }
    out.body = std::move(raw.body);
    out.little_endian = raw.little_endian;
    return out;
  }

  bool wait(std::chrono::nanoseconds timeout) override {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return !queue_.empty(); });
  }

  std::uint64_t overflowed() const override {
    std::lock_guard lock(mutex_);
    return overflowed_;
  }

 private:
  struct Raw {
    std::vector<std::byte> body;
    bool little_endian = true;
  };
  wire::DynType type_;
  net::WireFormat format_;
  std::shared_ptr<net::Transport> transport_;
  std::unique_ptr<net::Endpoint> endpoint_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Raw> queue_;
  std::uint64_t overflowed_ = 0;
};

}  // namespace

std::unique_ptr<RemoteReader> RemoteReader::open(const std::string& topic, const std::string& transport,
                                                 const std::string& type_name, std::uint64_t type_hash,
                                                 const std::string& signature, std::string& error) {
  const auto* info = net::find_transport(transport);
  if (info == nullptr) {
    error = "this build of horus has no " + transport + " backend";
    return nullptr;
  }
  auto type = wire::parse_signature(signature, type_hash);
  if (!type) {
    error = "cannot decode " + type_name + ": " + type.error();
    return nullptr;
  }
  const auto format = info->format == net::WireFormat::Lcm ? wire::DynFormat::Lcm : wire::DynFormat::Xcdr1;
  if (auto ok = wire::check_expressible(*type, format); !ok) {
    error = ok.error();
    return nullptr;
  }
  auto wire_topic = wire_name(Backend::network(info->name), topic);
  if (!wire_topic) {
    error = wire_topic.error().message();
    return nullptr;
  }
  net::EndpointSpec spec;
  spec.topic = topic;
  spec.wire_topic = *wire_topic;
  spec.type_name = type_name;
  spec.type_hash = type_hash;
  spec.qos.reliability = net::Reliability::BestEffort;  // matches reliable and best-effort writers
  spec.qos.depth = 64;
  auto r = std::make_unique<NetworkReader>(std::move(*type), info->format);
  if (!r->start(*info, spec, error)) return nullptr;
  return r;
}

}  // namespace horus::tools
