// The per-type half of typed_reader.hpp, included by typed_reader_{first,second}.cpp.
#pragma once

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "horus/wire/xcdr1.hpp"
#include "bench_peer_impl.hpp"
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
  std::optional<std::size_t> recv_size() override {
    auto m = topic_.recv();
    if (!m) return std::nullopt;
    return cdr::encoded_size(static_cast<const T&>(*m));
  }
  bool wait(std::chrono::nanoseconds timeout) override { return topic_.wait_for(timeout); }

 private:
  Topic<T> topic_;
};

template <class T>
class WriterOf final : public TypedWriter {
 public:
  explicit WriterOf(Topic<T> topic) : topic_(std::move(topic)) { topic_.publish_only(); }
  std::string send_json(const nlohmann::json& json) override {
    try {
      const T m = horus::from_json<T>(json);
      if (auto ok = topic_.send_blocking(m, std::chrono::seconds(1)); !ok) return ok.error().message();
      return {};
    } catch (const JsonError& e) {
      return e.what();
    }
  }
  std::uint32_t sub_count() const override { return topic_.sub_count(); }
  std::string backend() const override { return std::string(to_string(topic_.backend())); }

 private:
  Topic<T> topic_;
};

inline bool names_type(std::string_view qualified, std::string_view asked) {
  return qualified == asked || (qualified.size() > asked.size() + 2 && qualified.ends_with(asked) &&
                                qualified.substr(qualified.size() - asked.size() - 2, 2) == "::");
}

template <class... T>
void open_as(msg::TypeList<T...>, std::string_view type_name, const std::string& name,
             const std::optional<Backend>& backend, Want want, Opened& out, std::string& error) {
  auto try_one = [&]<class M>() {
    std::uint64_t fingerprint = 0;
    if constexpr (lcm::expressible<M>) fingerprint = lcm::fingerprint<M>();
    if (out.known) return;
    if (out.lcm_fingerprint != 0 ? fingerprint != out.lcm_fingerprint : !names_type(horus::type_name<M>(), type_name))
      return;
    out.known = true;
    out.qualified = std::string(horus::type_name<M>());
    out.hash = horus::type_hash<M>;
    if (want == Want::Name) return;
    if (want == Want::BenchCheck) {
      error = check_bench_size<M>(out.bench_payload->size);
      return;
    }
    if (want == Want::Bench) {
      out.bench = open_bench_as<M>(*out.bench_payload, *out.bench_endpoints, error);
      return;
    }
    TopicOptions options;
    options.backend = backend;
    auto topic = Topic<M>::open(name, options);
    if (!topic) error = topic.error().message();
    else if (want == Want::Reader) out.reader = std::make_unique<ReaderOf<M>>(std::move(*topic));
    else out.writer = std::make_unique<WriterOf<M>>(std::move(*topic));
  };
  (try_one.template operator()<T>(), ...);
}

}  // namespace horus::tools::detail
