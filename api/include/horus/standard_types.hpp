// The 81 standard messages known at run time: one table per type and a Topic behind a small
// interface, compiled once in the library (api/src/standard_types_*.cpp) for every program that
// meets a type by its name (the CLI's echo / pub / record / play, the Python package, the
// recorder's sources and the player's sinks) instead of instantiating Topic<T>, the codecs and
// the JSON of 81 types again in each of them.
//
//   const horus::StandardType* type = horus::find_standard_type("Pose2D");  // or "horus::msg::Pose2D"
//   auto topic = type->open("robot.pose", {});                            // Result<unique_ptr<AnyTopic>>
//   (*topic)->take([&](const void* msg) { std::puts(type->summary(msg).c_str()); });
//
// The functions taking `const void* msg` expect a message of the table's own type (the one
// AnyTopic::take hands out); nothing checks that.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "horus/backend.hpp"
#include "horus/topic_options.hpp"
#include "horus/error.hpp"
#include "horus/metrics.hpp"
#include "horus/waitset.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

class AnyTopic;

/// What a program needs of one standard message type whose name it learns at run time.
struct StandardType {
  std::string_view name;          // qualified: "horus::msg::Pose2D"
  std::uint64_t hash;             // horus::type_hash
  std::uint64_t lcm_fingerprint;  // lcm-gen's; 0 when LCM cannot carry the type
  /// reflect::type_signature: the layout text the hash is taken of.
  std::string (*signature)();
  /// horus::to_json, horus::log_summary, the XCDR1 body's size (what it takes on DDS) and the
  /// message's own timestamp_ns (0: it has none).
  nlohmann::json (*to_json)(const void* msg);
  std::string (*summary)(const void* msg);
  std::size_t (*xcdr_size)(const void* msg);
  std::uint64_t (*own_stamp)(const void* msg);
  /// The bytes a recording holds: the encapsulation header and the XCDR1 body (MCAP), or
  /// lcm-gen's encoding (false, `out` untouched, when LCM cannot carry the type).
  void (*encode_xcdr)(const void* msg, std::vector<std::byte>& out);
  bool (*encode_lcm)(const void* msg, std::vector<std::byte>& out);
  /// Topic<T>::open(name, options).
  Result<std::unique_ptr<AnyTopic>> (*open)(std::string_view name, const TopicOptions& options);

  /// The last part of the qualified name ("Pose2D").
  std::string_view short_name() const noexcept { return name.substr(name.rfind(':') + 1); }
};

/// A Topic<T> of a standard type, its type known at run time.
class AnyTopic {
 public:
  virtual ~AnyTopic() = default;
  virtual const StandardType& type() const noexcept = 0;

  // `msg` and `out` below point to a message of the topic's type (a T: what the caller made of
  // it knows the type; nothing here checks it).

  /// Topic::send, try_send (false: it was refused) and send_blocking of *msg.
  virtual void send(const void* msg) = 0;
  virtual bool try_send(const void* msg) = 0;
  virtual Result<void> send_blocking(const void* msg, std::chrono::nanoseconds timeout) = 0;
  /// Topic::recv, recv_for and read_latest: the message moved into *out (true), or nothing
  /// (false, *out untouched).
  virtual bool recv_into(void* out) = 0;
  virtual bool recv_for_into(void* out, std::chrono::nanoseconds timeout) = 0;
  virtual bool read_latest_into(void* out) = 0;
  /// Takes the next message and hands it to `fn` (a `const void*` to the message, valid during
  /// the call: not copied); false, without calling it, when none was waiting (Topic::recv).
  template <class F>
  bool take(F&& fn) {
    return take_with([](void* ctx, const void* msg) { (*static_cast<std::remove_reference_t<F>*>(ctx))(msg); },
                     static_cast<void*>(&fn));
  }
  /// Topic::wait_for, has_message, pending_count.
  virtual bool wait_for(std::chrono::nanoseconds timeout) = 0;
  virtual bool has_message() = 0;
  virtual std::uint64_t pending_count() = 0;
  /// Publishes the message `json` describes (horus::from_json: strict), waiting up to `timeout`
  /// for room (Topic::send_blocking). Errc::InvalidArgument names the field that did not fit.
  virtual Result<void> send_json(const nlohmann::json& json, std::chrono::nanoseconds timeout) = 0;
  /// Publishes a recorded message: `data` in lcm-gen's encoding (`lcm`) or the encapsulation
  /// header and an XCDR1 body. Waits up to `timeout` for room, then overwrites the oldest
  /// message (a subscriber that keeps no room loses it, and counts it, as it would to any
  /// publisher). Errc::Corrupt names what did not decode; Errc::TypeMismatch when LCM cannot
  /// carry the type.
  virtual Result<void> send_recorded(std::span<const std::byte> data, bool lcm, std::chrono::nanoseconds timeout) = 0;
  /// Publishes the message `fill` makes of a default-constructed message of the topic's type (a
  /// ROS 2 sample's conversion, horus/ros2/convert.hpp), as send_recorded does; fill's error is
  /// returned and nothing is sent.
  virtual Result<void> send_filled(Result<void> (*fill)(void* ctx, void* msg), void* ctx,
                                   std::chrono::nanoseconds timeout) = 0;

  virtual std::string_view name() const noexcept = 0;
  virtual Backend backend() const noexcept = 0;
  virtual Scope scope() const noexcept = 0;
  virtual std::uint32_t pub_count() const noexcept = 0;
  virtual std::uint32_t sub_count() const noexcept = 0;
  virtual std::uint64_t dropped_count() const noexcept = 0;
  virtual TopicMetrics metrics() const noexcept = 0;
  virtual std::uint64_t deadline_missed_count() const noexcept = 0;
  virtual std::uint64_t expired_count() const noexcept = 0;
  virtual std::uint64_t network_errors() const noexcept = 0;
  virtual bool is_bridge() const noexcept = 0;
  virtual std::uint32_t capacity() const noexcept = 0;
  virtual std::size_t max_message_size() const noexcept = 0;
  /// Topic::publish_only: this handle will not read.
  virtual void publish_only() noexcept = 0;
  /// WaitSet::attach of the topic (throws as it does: Errc::LimitReached when the set is full).
  virtual WaitSet::Id attach(WaitSet& ws) = 0;

 protected:
  virtual bool take_with(void (*fn)(void* ctx, const void* msg), void* ctx) = 0;
};

/// The standard messages, in catalogue order (horus/msg/all.hpp's AllMessages).
std::span<const StandardType* const> standard_types() noexcept;
/// The standard message called `name`: qualified ("horus::msg::Pose2D") or its last part
/// ("Pose2D"); null when none is.
const StandardType* find_standard_type(std::string_view name) noexcept;
const StandardType* find_standard_type(std::uint64_t hash) noexcept;
/// The standard message whose LCM type has this fingerprint (lcm-gen's); null when none has.
const StandardType* find_standard_type_by_lcm_fingerprint(std::uint64_t fingerprint) noexcept;

}  // namespace horus

HORUS_API_END
