// The per-type half of horus/standard_types.hpp: the table and the AnyTopic of one standard
// message, included by standard_types_{first,second}.cpp (two files of about as much code, built
// in parallel: the large-data types are in the first). Internal to api/src.
#pragma once

#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/standard_types.hpp"
#include "horus/topic.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/xcdr1.hpp"

namespace horus::detail::standard {

template <class T>
const StandardType& type_of() noexcept;

template <class T>
class TopicOf final : public AnyTopic {
 public:
  explicit TopicOf(Topic<T> topic) : topic_(std::move(topic)) {}
  const StandardType& type() const noexcept override { return type_of<T>(); }
  void send(const void* msg) override { topic_.send(*static_cast<const T*>(msg)); }
  bool try_send(const void* msg) override { return topic_.try_send(*static_cast<const T*>(msg)).has_value(); }
  Result<void> send_blocking(const void* msg, std::chrono::nanoseconds timeout) override {
    return topic_.send_blocking(*static_cast<const T*>(msg), timeout);
  }
  bool recv_into(void* out) override { return moved(topic_.recv(), out); }
  bool recv_for_into(void* out, std::chrono::nanoseconds timeout) override { return moved(topic_.recv_for(timeout), out); }
  bool read_latest_into(void* out) override { return moved(topic_.read_latest(), out); }
  bool wait_for(std::chrono::nanoseconds timeout) override { return topic_.wait_for(timeout); }
  bool has_message() override { return topic_.has_message(); }
  std::uint64_t pending_count() override { return topic_.pending_count(); }
  Result<void> send_json(const nlohmann::json& json, std::chrono::nanoseconds timeout) override {
    std::optional<T> m;
    try {
      m.emplace(horus::from_json<T>(json));
    } catch (const JsonError& e) {
      return std::unexpected(Error(Errc::InvalidArgument, e.what()));
    }
    return topic_.send_blocking(*m, timeout);
  }
  Result<void> send_recorded(std::span<const std::byte> data, bool lcm, std::chrono::nanoseconds timeout) override {
    std::expected<T, std::string> m = std::unexpected(std::string());
    if (lcm) {
      if constexpr (lcm::expressible<T>) m = lcm::decode<T>(data);
      else return std::unexpected(Error(Errc::TypeMismatch, std::string(horus::type_name<T>()) + " has no LCM encoding"));
    } else {
      auto sample = net::encapsulation::parse(data);
      if (const auto* why = std::get_if<std::string>(&sample)) return std::unexpected(Error(Errc::Corrupt, *why));
      const auto& s = std::get<net::Sample>(sample);
      m = cdr::decode<T>(s.body, s.little_endian);
    }
    if (!m) return std::unexpected(Error(Errc::Corrupt, m.error()));
    if (auto ok = topic_.send_blocking(*m, timeout); !ok) {
      if (ok.error().code() != Errc::Timeout) return ok;
      topic_.send(*m);
    }
    return {};
  }
  Result<void> send_filled(Result<void> (*fill)(void* ctx, void* msg), void* ctx,
                           std::chrono::nanoseconds timeout) override {
    auto m = std::make_unique<T>();  // an Image or a cloud is large for a stack
    if (auto ok = fill(ctx, m.get()); !ok) return ok;
    if (auto ok = topic_.send_blocking(*m, timeout); !ok) {
      if (ok.error().code() != Errc::Timeout) return ok;
      topic_.send(*m);
    }
    return {};
  }
  std::string_view name() const noexcept override { return topic_.name(); }
  Backend backend() const noexcept override { return topic_.backend(); }
  Scope scope() const noexcept override { return topic_.scope(); }
  std::uint32_t pub_count() const noexcept override { return topic_.pub_count(); }
  std::uint32_t sub_count() const noexcept override { return topic_.sub_count(); }
  std::uint64_t dropped_count() const noexcept override { return topic_.dropped_count(); }
  TopicMetrics metrics() const noexcept override { return topic_.metrics(); }
  std::uint64_t deadline_missed_count() const noexcept override { return topic_.deadline_missed_count(); }
  std::uint64_t expired_count() const noexcept override { return topic_.expired_count(); }
  std::uint64_t network_errors() const noexcept override { return topic_.network_errors(); }
  bool is_bridge() const noexcept override { return topic_.is_bridge(); }
  std::uint32_t capacity() const noexcept override { return topic_.capacity(); }
  std::size_t max_message_size() const noexcept override { return topic_.max_message_size(); }
  void publish_only() noexcept override { topic_.publish_only(); }
  WaitSet::Id attach(WaitSet& ws) override { return ws.attach(topic_); }

 protected:
  bool take_with(void (*fn)(void* ctx, const void* msg), void* ctx) override {
    auto m = topic_.recv();
    if (!m) return false;
    const T& msg = *m;
    fn(ctx, &msg);
    return true;
  }

 private:
  static bool moved(std::optional<T>&& m, void* out) {
    if (!m) return false;
    *static_cast<T*>(out) = std::move(*m);
    return true;
  }
  Topic<T> topic_;
};

template <class T>
std::uint64_t own_stamp(const void* p) {
  const T& m = *static_cast<const T*>(p);
  if constexpr (requires { m.timestamp_ns; }) {
    if constexpr (std::is_integral_v<std::remove_cvref_t<decltype(m.timestamp_ns)>>)
      return static_cast<std::uint64_t>(m.timestamp_ns);
  }
  return 0;
}

template <class T>
void encode_xcdr(const void* p, std::vector<std::byte>& out) {
  const T& m = *static_cast<const T*>(p);
  const std::size_t body = cdr::encoded_size(m);
  out.resize(net::encapsulation::serialized_size(body));
  cdr::encode(m, std::span<std::byte>(out).subspan(net::encapsulation::kHeaderSize, body));
  net::encapsulation::write_header_and_padding(out, body);
}

template <class T>
bool encode_lcm(const void* p, std::vector<std::byte>& out) {
  if constexpr (lcm::expressible<T>) {
    const T& m = *static_cast<const T*>(p);
    out.resize(lcm::encoded_size(m));
    lcm::encode(m, std::span<std::byte>(out));
    return true;
  } else {
    (void)p;
    (void)out;
    return false;
  }
}

template <class T>
Result<std::unique_ptr<AnyTopic>> open_topic(std::string_view name, const TopicOptions& options) {
  auto topic = Topic<T>::open(name, options);
  if (!topic) return std::unexpected(std::move(topic.error()));
  return std::unique_ptr<AnyTopic>(new TopicOf<T>(std::move(*topic)));
}

template <class T>
const StandardType& type_of() noexcept {
  static_assert(reflect::StandardMessage<T>, "a message of horus/msg/all.hpp lacks HORUS_STANDARD_MESSAGES in its header");
  static const StandardType type{
      horus::type_name<T>(),
      horus::type_hash<T>,
      [] {
        if constexpr (lcm::expressible<T>) return lcm::fingerprint<T>();
        else return std::uint64_t{0};
      }(),
      [] { return reflect::type_signature<T>(); },
      [](const void* m) { return horus::to_json(*static_cast<const T*>(m)); },
      [](const void* m) { return horus::log_summary(*static_cast<const T*>(m)); },
      [](const void* m) { return cdr::encoded_size(*static_cast<const T*>(m)); },
      &own_stamp<T>,
      &encode_xcdr<T>,
      &encode_lcm<T>,
      &open_topic<T>,
  };
  return type;
}

template <class... L>
std::vector<const StandardType*> types_of(msg::TypeList<L...>) {
  return {&type_of<L>()...};
}

// The two halves, each in catalogue order.
std::span<const StandardType* const> first_half() noexcept;
std::span<const StandardType* const> second_half() noexcept;

}  // namespace horus::detail::standard
