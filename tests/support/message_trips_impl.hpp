// The per-type halves of message_trips.hpp: included by the two .cpp files that instantiate them.
#pragma once

#include <optional>

#include "horus/topic.hpp"
#include "message_samples.hpp"
#include "message_trips.hpp"

namespace horus_test::detail {

inline std::string short_name(std::string_view q) { return std::string(q.substr(q.rfind("::") + 2)); }

template <class T>
class TripOf final : public Trip {
 public:
  std::string open(horus::Backend mine, const std::string& prefix) override {
    const std::string base = prefix + "." + short_name(horus::type_name<T>());
    horus::TopicOptions o;
    o.backend = mine;
    auto out = horus::Topic<T>::open(base, o);
    auto back = horus::Topic<T>::open(base + ".echo", o);
    if (!out || !back) return (!out ? out.error() : back.error()).message();
    out_.emplace(std::move(*out));
    back_.emplace(std::move(*back));
    return {};
  }
  void send() override { out_->send(sent_); }
  bool poll() override {
    bool done = false;
    while (auto got = back_->recv()) {
      if (auto same = SameMessage(*got, sent_); !same) failure_ = same.message();
      done = true;
    }
    return done;
  }
  const std::string& failure() const override { return failure_; }

 private:
  std::optional<horus::Topic<T>> out_, back_;
  T sent_ = topic_sample<T>();
  std::string failure_;
};

template <class T>
class EchoOf final : public Echo {
 public:
  std::string open(const std::string& prefix) override {
    const std::string base = prefix + "." + short_name(horus::type_name<T>());
    auto in = horus::Topic<T>::open(base);
    auto out = horus::Topic<T>::open(base + ".echo");
    if (!in || !out) return (!in ? in.error() : out.error()).message();
    in_.emplace(std::move(*in));
    out_.emplace(std::move(*out));
    return {};
  }
  void pump() override {
    while (auto m = in_->recv()) out_->send(*m);
  }

 private:
  std::optional<horus::Topic<T>> in_, out_;
};

template <class T>
MessageType entry() {
  static const std::string name = short_name(horus::type_name<T>());
  return {name, [] { return std::unique_ptr<Trip>(new TripOf<T>()); },
          [] { return std::unique_ptr<Echo>(new EchoOf<T>()); }};
}

template <class... T>
std::vector<MessageType> entries(horus::msg::TypeList<T...>) {
  return {entry<T>()...};
}

}  // namespace horus_test::detail
