// horus/record/standard.hpp: a recorder's source and a player's sink of any standard message,
// over the library's AnyTopic (horus/standard_types.hpp: the types' topics and codecs are
// compiled once there; nothing here is per type).
#include "horus/record/standard.hpp"

#include <fmt/format.h>

#include "horus/standard_types.hpp"

namespace horus {

namespace {

class StandardSource final : public RecordSource {
 public:
  explicit StandardSource(std::unique_ptr<AnyTopic> topic)
      : topic_(std::move(topic)),
        name_(topic_->name()),
        type_{std::string(topic_->type().name), topic_->type().hash, topic_->type().signature(), {}} {}
  const std::string& topic() const override { return name_; }
  const RecordedType& type() const override { return type_; }
  std::string scope() const override { return std::string(horus::to_string(topic_->scope())); }
  std::optional<std::string> unsupported(RecordFormat format) const override {
    if (format == RecordFormat::Lcm && topic_->type().lcm_fingerprint == 0)
      return type_.name + " has no LCM encoding (a variable-size array of variable-size arrays, or an empty array)";
    return std::nullopt;
  }
  std::optional<std::uint64_t> next(RecordFormat format, std::vector<std::byte>& out) override {
    const StandardType& t = topic_->type();
    std::optional<std::uint64_t> stamp;
    topic_->take([&](const void* m) {
      if (format == RecordFormat::Mcap) t.encode_xcdr(m, out);
      else if (!t.encode_lcm(m, out)) return;
      stamp = t.own_stamp(m);
    });
    return stamp;
  }
  std::optional<std::uint64_t> take(void (*fn)(void* ctx, const void* msg), void* ctx) override {
    std::optional<std::uint64_t> stamp;
    topic_->take([&](const void* m) {
      fn(ctx, m);
      stamp = topic_->type().own_stamp(m);
    });
    return stamp;
  }
  bool attach(WaitSet& ws) override {
    try {
      topic_->attach(ws);
      return true;
    } catch (const Exception&) {
      return false;  // the wait set is full (kMaxAttachments): polled instead
    }
  }
  std::uint64_t dropped() const override { return topic_->dropped_count(); }

 private:
  std::unique_ptr<AnyTopic> topic_;
  std::string name_;
  RecordedType type_;
};

class StandardSink final : public PlaySink {
 public:
  StandardSink(std::unique_ptr<AnyTopic> topic, bool lcm_encoding) : topic_(std::move(topic)), lcm_(lcm_encoding) {
    topic_->publish_only();
  }
  // A subscriber that keeps no room for 100 ms loses its oldest message (and counts it), as it
  // would to any publisher.
  Result<void> publish(std::span<const std::byte> data) override {
    return topic_->send_recorded(data, lcm_, std::chrono::milliseconds(100));
  }

 private:
  std::unique_ptr<AnyTopic> topic_;
  bool lcm_;
};

class Ros2Sink final : public PlaySink {
 public:
  Ros2Sink(std::unique_ptr<AnyTopic> topic, const ros2::Conversion& conversion)
      : topic_(std::move(topic)), conversion_(conversion) {
    topic_->publish_only();
  }
  Result<void> publish(std::span<const std::byte> data) override {
    auto sample = net::encapsulation::parse(data);
    if (const auto* why = std::get_if<std::string>(&sample)) return fail(Errc::Corrupt, *why);
    struct Fill {
      const ros2::Conversion& conversion;
      const net::Sample& sample;
    } fill{conversion_, std::get<net::Sample>(sample)};
    return topic_->send_filled(
        [](void* ctx, void* msg) -> Result<void> {
          const auto& f = *static_cast<const Fill*>(ctx);
          auto ok = f.conversion.decode(f.sample.body, f.sample.little_endian, msg, nullptr);
          if (ok) return {};
          return fail(ok.error().malformed ? Errc::Corrupt : Errc::LimitReached, ok.error().what);
        },
        &fill, std::chrono::milliseconds(100));
  }

 private:
  std::unique_ptr<AnyTopic> topic_;
  const ros2::Conversion& conversion_;
};

Result<std::unique_ptr<AnyTopic>> open_named(std::string_view type_name, std::string_view name,
                                             const TopicOptions& options, std::uint64_t* type_hash) {
  const StandardType* type = find_standard_type(type_name);
  if (type == nullptr)
    return std::unexpected(Error(Errc::InvalidArgument,
                                 fmt::format("topic '{}': '{}' is not a standard message type (those of "
                                             "horus/msg/all.hpp: horus::msg::Pose2D, Image, ...)",
                                             name, type_name)));
  if (type_hash != nullptr) *type_hash = type->hash;
  return type->open(name, options);
}

}  // namespace

Result<std::unique_ptr<RecordSource>> open_standard_source(std::string_view type_name, std::string_view name,
                                                           const TopicOptions& options) {
  auto topic = open_named(type_name, name, options, nullptr);
  if (!topic) return std::unexpected(std::move(topic.error()));
  return std::unique_ptr<RecordSource>(new StandardSource(std::move(*topic)));
}

Result<std::unique_ptr<PlaySink>> open_standard_sink(std::string_view type_name, std::string_view name,
                                                     bool lcm_encoding, std::uint64_t& type_hash,
                                                     const TopicOptions& options) {
  type_hash = 0;
  auto topic = open_named(type_name, name, options, &type_hash);
  if (!topic) return std::unexpected(std::move(topic.error()));
  return std::unique_ptr<PlaySink>(new StandardSink(std::move(*topic), lcm_encoding));
}

Result<std::unique_ptr<PlaySink>> open_ros2_sink(std::string_view type_name, std::string_view name,
                                                 const ros2::Conversion& conversion, std::uint64_t& type_hash,
                                                 const TopicOptions& options) {
  type_hash = 0;
  auto topic = open_named(type_name, name, options, &type_hash);
  if (!topic) return std::unexpected(std::move(topic.error()));
  if (type_hash != conversion.horus_hash)
    return fail(Errc::TypeMismatch, fmt::format("topic '{}': {} does not convert from {} ({} does)", name, type_name,
                                                conversion.ros_type, conversion.horus_type));
  return std::unique_ptr<PlaySink>(new Ros2Sink(std::move(*topic), conversion));
}

}  // namespace horus
