#include "remote_reader.hpp"

#include <condition_variable>
#include <expected>
#include <functional>
#include <span>
#include <deque>
#include <mutex>
#include <vector>

#include "horus/backend.hpp"
#include "horus/config.hpp"
#include "horus/network.hpp"
#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/transport_registry.hpp"
#include "horus/wire/dynamic.hpp"

namespace horus::tools {

namespace {

constexpr std::size_t kQueue = 4096;

// A sample's body (and its byte order) as JSON, or why it does not decode.
using Decoder = std::function<std::expected<nlohmann::json, std::string>(std::span<const std::byte>, bool)>;

class NetworkReader final : public RemoteReader, public net::Listener {
 public:
  explicit NetworkReader(Decoder decode) : decode_(std::move(decode)) {}
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
      auto j = decode_(raw.body, raw.little_endian);
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
  Decoder decode_;
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
  spec.send = false;  // an observer: no writer that the topic's readers would match
  auto r = std::make_unique<NetworkReader>([type = std::move(*type), format](std::span<const std::byte> body, bool le) {
    return wire::decode_json(type, format, body, le);
  });
  if (!r->start(*info, spec, error)) return nullptr;
  return r;
}

std::unique_ptr<RemoteReader> RemoteReader::open_ros2(const std::string& ros_name, const std::string& transport,
                                                      const std::string& ros_type, std::string& error) {
  const auto* info = net::find_transport(transport);
  if (info == nullptr || info->format != net::WireFormat::Xcdr1) {
    error = info == nullptr ? "this build of horus has no " + transport + " backend"
                            : "ROS 2 topics are on DDS (cyclonedds or fastdds), not " + transport;
    return nullptr;
  }
  const auto& types = ros2::Interfaces::standard();
  auto name = ros2::parse_type_name(ros_type);
  auto hash = types.type_hash(ros_type);
  if (!name || !hash) {
    error = (!name ? name.error() : hash.error()).message();
    return nullptr;
  }
  net::EndpointSpec spec;
  spec.topic = ros_name;
  spec.wire_topic = ros2::dds_topic(ros_name);
  spec.type_name = name->dds();
  spec.user_data = ros2::user_data_of(*hash);
  spec.qos.reliability = net::Reliability::BestEffort;  // matches reliable and best-effort writers
  spec.qos.depth = 64;
  spec.send = false;
  auto r = std::make_unique<NetworkReader>([&types, ros_type](std::span<const std::byte> body, bool le) {
    auto j = ros2::decode_json(types, ros_type, body, le);
    return j ? std::expected<nlohmann::json, std::string>(std::move(*j))
             : std::unexpected(j.error().message());
  });
  if (!r->start(*info, spec, error)) return nullptr;
  return r;
}

}  // namespace horus::tools
