// The per-type halves of message_trips.hpp: included by the two .cpp files that instantiate them.
#pragma once

#include <optional>

#include <algorithm>
#include <span>
#include <vector>

#include "horus/standard_types.hpp"
#include "horus/topic.hpp"
#include "horus/wire/dynamic.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/xcdr1.hpp"
#include "message_samples.hpp"
#include "message_trips.hpp"

namespace horus_test::detail {

inline std::string short_name(std::string_view q) { return std::string(q.substr(q.rfind("::") + 2)); }

// A topic of T: the library's AnyTopic for a standard message (horus/standard_types.hpp: its
// Topic<T> compiled once there, not again here), a Topic<T> of its own for the wire test types.
template <class T, bool kStandard = horus::reflect::StandardMessage<T>>
class HandleOf;

template <class T>
class HandleOf<T, true> {
 public:
  std::string open(const std::string& name, const horus::TopicOptions& o) {
    auto t = horus::find_standard_type(horus::type_hash<T>)->open(name, o);
    if (!t) return t.error().message();
    topic_ = std::move(*t);
    return {};
  }
  void send(const T& m) { topic_->send(&m); }
  template <class F>
  bool take(F&& f) {
    return topic_->take([&](const void* m) { f(*static_cast<const T*>(m)); });
  }

 private:
  std::unique_ptr<horus::AnyTopic> topic_;
};

template <class T>
class HandleOf<T, false> {
 public:
  std::string open(const std::string& name, const horus::TopicOptions& o) {
    auto t = horus::Topic<T>::open(name, o);
    if (!t) return t.error().message();
    topic_.emplace(std::move(*t));
    return {};
  }
  void send(const T& m) { topic_->send(m); }
  template <class F>
  bool take(F&& f) {
    auto m = topic_->recv();
    if (!m) return false;
    f(static_cast<const T&>(*m));
    return true;
  }

 private:
  std::optional<horus::Topic<T>> topic_;
};

template <class T>
class TripOf final : public Trip {
 public:
  std::string open(horus::Backend mine, const std::string& prefix) override {
    const std::string base = prefix + "." + short_name(horus::type_name<T>());
    horus::TopicOptions o;
    o.backend = mine;
    if (auto err = out_.open(base, o); !err.empty()) return err;
    return back_.open(base + ".echo", o);
  }
  void send() override { out_.send(sent_); }
  bool poll() override {
    bool done = false;
    while (back_.take([&](const T& got) {
      if (auto same = SameMessage(got, sent_); !same) failure_ = same.message();
    }))
      done = true;
    return done;
  }
  const std::string& failure() const override { return failure_; }

 private:
  HandleOf<T> out_, back_;
  T sent_ = topic_sample<T>();
  std::string failure_;
};

template <class T>
class EchoOf final : public Echo {
 public:
  std::string open(const std::string& prefix) override {
    const std::string base = prefix + "." + short_name(horus::type_name<T>());
    if (auto err = in_.open(base, {}); !err.empty()) return err;
    return out_.open(base + ".echo", {});
  }
  void pump() override {
    while (in_.take([&](const T& m) { out_.send(m); })) {
    }
  }

 private:
  HandleOf<T> in_, out_;
};

// One encoding of a sample against the dynamic decoder: the same JSON as to_json, and every
// shorter prefix refused by both decoders alike.
template <class T, class TypedDecode>
std::string dynamic_compare(const horus::wire::DynType& type, horus::wire::DynFormat format,
                            const std::vector<std::byte>& bytes, bool little_endian, const TypedDecode& typed,
                            std::string_view what) {
  const auto want = horus::to_json(*typed(std::span<const std::byte>(bytes)));
  auto got = horus::wire::decode_json(type, format, bytes, little_endian);
  if (!got) return std::string(what) + ": " + got.error();
  if (*got != want) return std::string(what) + ": dynamic " + got->dump() + "\n vs to_json " + want.dump();
  // Every prefix: refused by both, or (XCDR1's final padding) accepted by both alike.
  const std::size_t step = std::max<std::size_t>(1, bytes.size() / 64);
  for (std::size_t n = 0; n < bytes.size(); n += step) {
    const std::span<const std::byte> cut(bytes.data(), n);
    const bool typed_ok = typed(cut).has_value();
    const bool dyn_ok = horus::wire::decode_json(type, format, cut, little_endian).has_value();
    if (typed_ok != dyn_ok)
      return std::string(what) + ": a prefix of " + std::to_string(n) + " bytes " + (dyn_ok ? "decodes" : "fails") +
             " dynamically but " + (typed_ok ? "decodes" : "fails") + " typed";
  }
  return {};
}

template <class T>
std::string dynamic_check() {
  const std::string sig = horus::reflect::type_signature<T>();
  auto type = horus::wire::parse_signature(sig, horus::type_hash<T>);
  if (!type) return type.error();
  const T m = topic_sample<T>();
  std::string out;
  auto note = [&](std::string s) {
    if (!s.empty()) out += (out.empty() ? "" : "; ") + s;
  };
  const auto cdr_le = horus::cdr::encode(m);
  note(dynamic_compare<T>(*type, horus::wire::DynFormat::Xcdr1, cdr_le, true,
                          [](std::span<const std::byte> b) { return horus::cdr::decode<T>(b, true); }, "XCDR1"));
  if constexpr (horus::lcm::expressible<T>) {
    const auto lcm = horus::lcm::encode(m);
    note(dynamic_compare<T>(*type, horus::wire::DynFormat::Lcm, lcm, true,
                            [](std::span<const std::byte> b) { return horus::lcm::decode<T>(b); }, "LCM"));
  } else if (horus::wire::check_expressible(*type, horus::wire::DynFormat::Lcm)) {
    note("LCM: the signature says expressible, the type says not");
  }
  return out;
}

template <class T>
MessageType entry() {
  static const std::string name = short_name(horus::type_name<T>());
  return {name, [] { return std::unique_ptr<Trip>(new TripOf<T>()); },
          [] { return std::unique_ptr<Echo>(new EchoOf<T>()); }, &dynamic_check<T>,
          [] { return horus::to_json(topic_sample<T>()).dump(); }, [] { return horus::reflect::type_signature<T>(); }};
}

template <class... T>
std::vector<MessageType> entries(horus::msg::TypeList<T...>) {
  return {entry<T>()...};
}

}  // namespace horus_test::detail
