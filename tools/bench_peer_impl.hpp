// The per-type half of bench_peer.hpp, included by typed_reader_impl.hpp (typed_reader_{first,
// second}.cpp): where each standard type carries the round trip's tag, and its peer over the
// library's AnyTopic (large data: its own Topic<T>, which lends pool slots).
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <type_traits>

#include "bench_peer.hpp"
#include "horus/msg/all.hpp"
#include "horus/msg/generic_value.hpp"
#include "horus/standard_types.hpp"
#include "horus/topic.hpp"

namespace horus::tools::detail {

// -- where the tag travels ------------------------------------------------------------------
//
// A field of the message chosen by reflection, by preference: a 64-bit time stamp
// (timestamp_ns, stamp_nanos), a 64-bit integer, a double, a 32-bit integer, a float; nested
// messages are searched too. Fields that say how much of an array is valid (counts, lengths,
// sizes) are never used: a receiver may check them. Large data carries it in its first 8 bytes.

enum TagPass : int { kStamp = 0, kInt64, kDouble, kInt32, kFloat, kText, kPasses };

// A text field of at least 24 characters (NUL-terminated) carries the tag in decimal.
template <class V>
inline constexpr bool kTextField = false;
template <std::size_t N>
inline constexpr bool kTextField<std::array<char, N>> = N >= 24;

inline bool tag_name_ok(std::string_view n) {
  for (std::string_view bad : {"count", "len", "size", "num_", "ndim", "step"})
    if (n.find(bad) != std::string_view::npos) return false;
  return true;
}

template <class V>
constexpr int tag_pass_of() {
  if constexpr (std::is_same_v<V, std::uint64_t> || std::is_same_v<V, std::int64_t>) return kInt64;
  else if constexpr (std::is_same_v<V, double>) return kDouble;
  else if constexpr (std::is_same_v<V, std::uint32_t> || std::is_same_v<V, std::int32_t>) return kInt32;
  else if constexpr (std::is_same_v<V, float>) return kFloat;
  else if constexpr (kTextField<V>) return kText;
  else return -1;
}

// Calls f(name, field) on the first field of `m` (depth first) that pass `pass` accepts.
template <class M, class F>
bool visit_tag_field(M& m, int pass, F&& f) {
  bool done = false;
  reflect::for_each_field(m, [&](std::string_view name, auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    if (done) return;
    if constexpr (tag_pass_of<V>() >= 0) {
      const bool stamp = std::is_same_v<V, std::uint64_t> && (name == "timestamp_ns" || name == "stamp_nanos");
      if (pass == kStamp ? stamp : (tag_pass_of<V>() == pass && tag_name_ok(name))) {
        f(name, v);
        done = true;
      }
    } else if constexpr (Reflected<V> && !std::is_enum_v<V>) {
      done = visit_tag_field(v, pass, f);
    }
  });
  return done;
}

template <class M>
int tag_pass() {
  static const int pass = [] {
    M m{};
    for (int p = 0; p < kPasses; ++p)
      if (visit_tag_field(m, p, [](std::string_view, auto&) {})) return p;
    return -1;
  }();
  return pass;
}

inline std::uint64_t tag_modulus_of(int pass) {
  switch (pass) {
    case kStamp:
    case kInt64:
    case kText: return std::uint64_t{1} << 62;
    case kDouble: return std::uint64_t{1} << 52;
    case kInt32: return std::uint64_t{1} << 30;
    default: return std::uint64_t{1} << 23;
  }
}

template <class M>
void set_tag(M& m, std::uint64_t tag) {
  visit_tag_field(m, tag_pass<M>(), [&](std::string_view, auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    const std::uint64_t t = tag % tag_modulus_of(tag_pass<M>());
    if constexpr (kTextField<V>) {
      v = {};
      const auto r = fmt::format_to_n(v.data(), v.size() - 1, "{}", t);
      (void)r;
    } else {
      v = static_cast<V>(t);
    }
  });
}

template <class M>
std::uint64_t get_tag(const M& m) {
  std::uint64_t out = 0;
  visit_tag_field(m, tag_pass<M>(), [&](std::string_view, auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    if constexpr (kTextField<V>) {
      for (char c : v) {
        if (c < '0' || c > '9') break;
        out = out * 10 + static_cast<std::uint64_t>(c - '0');
      }
    } else if constexpr (std::is_floating_point_v<V>)
      out = v < 0 ? 0 : static_cast<std::uint64_t>(v);
    else
      out = static_cast<std::uint64_t>(v) % tag_modulus_of(tag_pass<M>());
  });
  return out;
}

// GenericMessage carries the tag as its MessagePack payload (an unsigned integer).
template <class M>
inline constexpr bool kMsgpackTag = std::is_same_v<M, msg::GenericMessage>;

template <class M>
void put_tag(M& m, std::uint64_t tag) {
  if constexpr (kMsgpackTag<M>) {
    if (auto g = M::from_value(tag)) m = *g;
  } else {
    set_tag(m, tag);
  }
}

template <class M>
std::uint64_t take_tag(const M& m) {
  if constexpr (kMsgpackTag<M>) {
    auto v = m.template to_value<std::uint64_t>();
    return v ? *v : 0;
  } else {
    return get_tag(m);
  }
}

template <class M>
std::string tag_field_name() {
  std::string out;
  M m{};
  visit_tag_field(m, tag_pass<M>(), [&](std::string_view n, auto&) { out = std::string(n); });
  return out;
}

// -- sized payloads -------------------------------------------------------------------------

template <class M>
inline constexpr bool kSizedSerialized = std::is_same_v<M, msg::CompressedImage>;
// A sized CompressedImage's slot: its data and room for the other fields.
inline constexpr std::uint64_t kSerializedSlack = 1024;

// A large-data message of about `bytes` bytes (0: its default, a 640 x 480 frame or the like).
template <class M>
auto describe_bytes(std::uint64_t bytes) {
  using msg::TensorDtype;
  if constexpr (std::is_same_v<M, msg::Image>) {
    if (bytes == 0) return M::describe(480, 640, msg::ImageEncoding::Rgb8);
    return M::describe(1, static_cast<std::uint32_t>(bytes), msg::ImageEncoding::Mono8);
  } else if constexpr (std::is_same_v<M, msg::DepthImage>) {
    if (bytes == 0) return M::describe(480, 640, TensorDtype::U16);
    return M::describe(1, static_cast<std::uint32_t>((bytes + 1) / 2), TensorDtype::U16);
  } else if constexpr (std::is_same_v<M, msg::PointCloud>) {
    return M::describe(bytes == 0 ? 10000 : (bytes + 11) / 12, 3, TensorDtype::F32);
  } else {
    const std::array<std::uint64_t, 1> shape{bytes == 0 ? std::uint64_t{640 * 480} : bytes};
    return M::describe(shape, TensorDtype::U8);
  }
}

// What both kinds of peer report the same way.
template <class M>
std::string describe_peer(std::uint64_t bytes, std::uint64_t pooled_bytes) {
  const std::string name(horus::type_name<M>());
  if constexpr (is_pool_message<M>)
    return fmt::format("{} ({} bytes of data through the pool)", name, pooled_bytes);
  else if constexpr (is_serialized_message<M>)
    return fmt::format("{} (serialized, {} bytes)", name, bytes);
  else
    return fmt::format("{} (fixed size, {} bytes)", name, sizeof(M));
}

// A peer of a type that is not large data: the library's AnyTopic of the type
// (horus/standard_types.hpp: its Topic<T> compiled once there; a send or receive costs one
// indirect call more than a Topic<T> of this file would).
template <class M>
class BenchPeerOf final : public BenchPeer {
 public:
  BenchPeerOf(std::unique_ptr<AnyTopic> in, std::unique_ptr<AnyTopic> out, std::uint64_t size)
      : in_(std::move(in)), out_(std::move(out)) {
    if constexpr (kSizedSerialized<M>) {
      sample_.data.assign(size, std::uint8_t{0xA5});
      (void)sample_.set_format("bench");
    } else {
      (void)size;
    }
  }

  bool send(std::uint64_t tag, std::int64_t& sent_at) override {
    put_tag(sample_, tag);
    sent_at = bench_now_ns();
    if (checked_) {
      out_->send(&sample_);
      return true;
    }
    // The first message tells whether the topic takes this size (a serialized message larger
    // than its slot is refused); the others have the same size, and reading the counters on
    // every send would put their cache lines into the measured round trip.
    const auto failures = out_->metrics().send_failures();
    out_->send(&sample_);
    checked_ = out_->metrics().send_failures() == failures;
    return checked_;
  }

  std::optional<std::uint64_t> recv_tag() override {
    std::optional<std::uint64_t> tag;
    in_->take([&](const void* m) { tag = take_tag(*static_cast<const M*>(m)); });
    return tag;
  }

  bool echo_one(EchoStamp* stamp) override {
    return in_->take([&](const void* m) {
      if (stamp != nullptr) {
        stamp->tag = take_tag(*static_cast<const M*>(m));
        stamp->at = bench_now_ns();
      }
      out_->send(m);
    });
  }

  bool wait(std::chrono::nanoseconds timeout) override { return in_->wait_for(timeout); }

  std::uint64_t tag_modulus() const override {
    if constexpr (kMsgpackTag<M>) return std::uint64_t{1} << 62;
    else return tag_modulus_of(tag_pass<M>());
  }
  std::uint64_t message_bytes() const override { return out_->type().xcdr_size(&sample_); }
  std::string describe() const override { return describe_peer<M>(message_bytes(), 0); }
  std::string tag_carrier() const override {
    if constexpr (kMsgpackTag<M>) return "the MessagePack payload";
    else return "field " + tag_field_name<M>();
  }
  std::uint64_t dropped() const override { return in_->dropped_count(); }
  std::uint32_t subscribers() const override { return out_->sub_count(); }
  std::uint32_t capacity() const override { return out_->capacity(); }
  std::string backend() const override { return std::string(to_string(out_->backend())); }

 private:
  std::unique_ptr<AnyTopic> in_;
  std::unique_ptr<AnyTopic> out_;
  M sample_{};
  bool checked_ = false;
};

// A peer of large data (Image, DepthImage, PointCloud, Tensor): its own Topic<M>, which lends
// pool slots; the tag rides in the data's first 8 bytes.
template <class M>
class PooledBenchPeerOf final : public BenchPeer {
 public:
  PooledBenchPeerOf(Topic<M> in, Topic<M> out, std::uint64_t size)
      : in_(std::move(in)), out_(std::move(out)), desc_(*describe_bytes<M>(size)) {}

  bool send(std::uint64_t tag, std::int64_t& sent_at) override {
    auto loan = out_.loan(desc_);
    if (!loan) return false;
    auto bytes = (*loan)->data_mut();
    const std::uint64_t t = tag;
    std::memcpy(bytes.data(), &t, std::min<std::size_t>(sizeof t, bytes.size()));
    sent_at = bench_now_ns();
    out_.send(std::move(*loan));
    return true;
  }

  std::optional<std::uint64_t> recv_tag() override {
    auto m = in_.recv();
    if (!m) return std::nullopt;
    return tag_of(static_cast<const M&>(*m));
  }

  bool echo_one(EchoStamp* stamp) override {
    auto m = in_.recv();
    if (!m) return false;
    if (stamp != nullptr) {
      stamp->tag = tag_of(static_cast<const M&>(*m));
      stamp->at = bench_now_ns();
    }
    out_.send(static_cast<const M&>(*m));
    return true;
  }

  bool wait(std::chrono::nanoseconds timeout) override { return in_.wait_for(timeout); }
  std::uint64_t tag_modulus() const override { return std::uint64_t{1} << 62; }
  std::uint64_t message_bytes() const override { return desc_.data_size; }
  std::string describe() const override { return describe_peer<M>(0, desc_.data_size); }
  std::string tag_carrier() const override { return "the first 8 bytes of the data"; }
  std::uint64_t dropped() const override { return in_.dropped_count(); }
  std::uint32_t subscribers() const override { return out_.sub_count(); }
  std::uint32_t capacity() const override { return out_.capacity(); }
  std::string backend() const override { return std::string(to_string(out_.backend())); }

 private:
  static std::uint64_t tag_of(const M& m) {
    std::uint64_t t = 0;
    const auto bytes = m.data();
    std::memcpy(&t, bytes.data(), std::min<std::size_t>(sizeof t, bytes.size()));
    return t;
  }

  Topic<M> in_;
  Topic<M> out_;
  typename Topic<M>::descriptor_type desc_{};
};

// The XCDR1 size of a default M, from the library's table of the type.
template <class M>
std::size_t xcdr_size_of() {
  const M m{};
  return find_standard_type(type_hash<M>)->xcdr_size(&m);
}

// Checks the size for M; the error, or empty.
template <class M>
std::string check_bench_size(std::uint64_t size) {
  const std::string name(horus::type_name<M>());
  if constexpr (is_pool_message<M>) {
    if (size > kMaxBenchPayload)
      return fmt::format("--size {} is beyond the largest slot horus bench uses ({} bytes, LCM's largest message)",
                         size, kMaxBenchPayload);
    if (size != 0 && size < 8)
      return fmt::format("--size {}: {} carries the tag in its first 8 bytes; give at least 8", size, name);
    if (!describe_bytes<M>(size)) return fmt::format("--size {} does not make a valid {}", size, name);
    return {};
  } else if constexpr (kSizedSerialized<M>) {
    if (size + kSerializedSlack > (std::uint64_t{1} << 30) - 8)
      return fmt::format("--size {} is beyond the largest serialized slot (1 GiB - 8 bytes, {} of them the "
                         "message's other fields)", size, kSerializedSlack);
    return {};
  } else {
    if (size == 0) return {};
    return fmt::format("{} has no payload to size ({}, {} bytes); --size applies to CompressedImage (serialized) "
                       "and the large-data types Image, DepthImage, PointCloud, Tensor (pool)",
                       name, is_serialized_message<M> ? "serialized" : "fixed size", xcdr_size_of<M>());
  }
}

// Opens the peer as M; `error` set on failure.
template <class M>
std::unique_ptr<BenchPeer> open_bench_as(const BenchPayload& p, const BenchEndpoints& e, std::string& error) {
  if constexpr (!is_pool_message<M> && !kMsgpackTag<M>) {
    if (tag_pass<M>() < 0) {
      error = fmt::format("{} has no numeric field to carry the round trip's sequence number",
                          horus::type_name<M>());
      return nullptr;
    }
  }
  if (error = check_bench_size<M>(p.size); !error.empty()) return nullptr;
  TopicOptions options;
  options.backend = e.backend;
  if constexpr (is_pool_message<M>) {
    options.slot_size = describe_bytes<M>(p.size)->data_size;
  } else if constexpr (kSizedSerialized<M>) {
    // The message and its fixed fields: a slot as large as the message, so the ring gets the
    // depth the message's size gives it (a 2 MiB default slot would leave 4 slots).
    if (p.size > 0) options.slot_size = p.size + kSerializedSlack;
  }
  auto fail = [&](const std::string& topic, const Error& err) {
    error = fmt::format("topic {}: {}", topic, err.message());
    return std::unique_ptr<BenchPeer>();
  };
  if constexpr (is_pool_message<M>) {
    auto in = Topic<M>::open(e.in, options);
    if (!in) return fail(e.in, in.error());
    auto out = Topic<M>::open(e.out, options);
    if (!out) return fail(e.out, out.error());
    return std::make_unique<PooledBenchPeerOf<M>>(std::move(*in), std::move(*out), p.size);
  } else {
    const StandardType* type = find_standard_type(type_hash<M>);
    auto in = type->open(e.in, options);
    if (!in) return fail(e.in, in.error());
    auto out = type->open(e.out, options);
    if (!out) return fail(e.out, out.error());
    return std::make_unique<BenchPeerOf<M>>(std::move(*in), std::move(*out), p.size);
  }
}

}  // namespace horus::tools::detail
