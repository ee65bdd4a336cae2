// The per-type half of typed_reader.hpp, included by typed_reader_{first,second}.cpp.
#pragma once

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "typed_reader.hpp"

namespace horus::tools::detail {

template <class T>
class ReaderOf final : public TypedReader {
 public:
  explicit ReaderOf(Topic<T> topic) : topic_(std::move(topic)) {}
  std::optional<std::string> recv_text(bool json) override {
    auto m = topic_.recv();
    if (!m) return std::nullopt;
    return json ? horus::to_json(*m).dump() : horus::log_summary(*m);
  }
  bool recv_any() override { return topic_.recv().has_value(); }
  bool wait(std::chrono::nanoseconds timeout) override { return topic_.wait_for(timeout); }

 private:
  Topic<T> topic_;
};

template <class... T>
std::unique_ptr<TypedReader> open_as(msg::TypeList<T...>, std::string_view type_name, const std::string& name,
                                     const Backend& backend, std::string& error, bool& known) {
  std::unique_ptr<TypedReader> out;
  auto try_one = [&]<class M>() {
    if (known || horus::type_name<M>() != type_name) return;
    known = true;
    auto topic = Topic<M>::open(name, TopicOptions{backend, {}, {}});
    if (!topic) error = topic.error().message();
    else out = std::make_unique<ReaderOf<M>>(std::move(*topic));
  };
  (try_one.template operator()<T>(), ...);
  return out;
}

}  // namespace horus::tools::detail
