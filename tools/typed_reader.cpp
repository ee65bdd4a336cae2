// typed_reader.hpp's topics of a standard message known by name: the library's AnyTopic
// (horus/standard_types.hpp) behind the CLI's interfaces, no type instantiated here.
#include "typed_reader.hpp"

#include <nlohmann/json.hpp>

#include "horus/record/standard.hpp"
#include "horus/standard_types.hpp"

namespace horus::tools {

namespace {

class AnyTopicReader final : public TypedReader {
 public:
  explicit AnyTopicReader(std::unique_ptr<AnyTopic> topic) : topic_(std::move(topic)) {}
  std::optional<std::string> recv_text(bool json) override {
    std::optional<std::string> out;
    const StandardType& type = topic_->type();
    topic_->take([&](const void* m) { out = json ? type.to_json(m).dump() : type.summary(m); });
    return out;
  }
  std::optional<std::size_t> recv_size() override {
    std::optional<std::size_t> out;
    const StandardType& type = topic_->type();
    topic_->take([&](const void* m) { out = type.xcdr_size(m); });
    return out;
  }
  bool wait(std::chrono::nanoseconds timeout) override { return topic_->wait_for(timeout); }

 private:
  std::unique_ptr<AnyTopic> topic_;
};

class Writer final : public TypedWriter {
 public:
  explicit Writer(std::unique_ptr<AnyTopic> topic) : topic_(std::move(topic)) { topic_->publish_only(); }
  std::string send_json(const nlohmann::json& json) override {
    if (auto ok = topic_->send_json(json, std::chrono::seconds(1)); !ok) return ok.error().message();
    return {};
  }
  std::uint32_t sub_count() const override { return topic_->sub_count(); }
  std::string backend() const override { return std::string(to_string(topic_->backend())); }

 private:
  std::unique_ptr<AnyTopic> topic_;
};

// Topic `name` of the standard type `type_name`; nothing with `error` empty when there is none.
std::unique_ptr<AnyTopic> open_any(std::string_view type_name, const std::string& name,
                                   const std::optional<Backend>& backend, std::string& error) {
  error.clear();
  const StandardType* type = find_standard_type(type_name);
  if (type == nullptr) return nullptr;
  TopicOptions options;
  options.backend = backend;
  auto topic = type->open(name, options);
  if (!topic) {
    error = topic.error().message();
    return nullptr;
  }
  return std::move(*topic);
}

}  // namespace

std::string standard_type(std::string_view type_name) {
  const StandardType* type = find_standard_type(type_name);
  return type ? std::string(type->name) : std::string();
}

std::unique_ptr<TypedReader> open_reader(std::string_view type_name, const std::string& name, const Backend& backend,
                                         std::string& error) {
  auto topic = open_any(type_name, name, backend, error);
  return topic ? std::make_unique<AnyTopicReader>(std::move(topic)) : nullptr;
}

std::unique_ptr<TypedWriter> open_writer(std::string_view type_name, const std::string& name,
                                         const std::optional<Backend>& backend, std::string& error) {
  auto topic = open_any(type_name, name, backend, error);
  return topic ? std::make_unique<Writer>(std::move(topic)) : nullptr;
}

std::string standard_type_by_lcm_fingerprint(std::uint64_t fingerprint) {
  const StandardType* type = find_standard_type_by_lcm_fingerprint(fingerprint);
  return type ? std::string(type->name) : std::string();
}

// Recording and playing go through the record library's sources and sinks of the standard types
// (horus/record/standard.hpp), which the Python package uses too.
std::unique_ptr<RecordSource> open_record_source(std::string_view type_name, const std::string& name,
                                                 const std::optional<Backend>& backend, std::string& error) {
  error.clear();
  if (find_standard_type(type_name) == nullptr) return nullptr;
  TopicOptions options;
  options.backend = backend;
  auto source = open_standard_source(type_name, name, options);
  if (!source) error = source.error().message();
  return source ? std::move(*source) : nullptr;
}

std::unique_ptr<PlaySink> open_play_sink(std::string_view type_name, const std::string& name, bool lcm_encoding,
                                         const ros2::Conversion* conversion, const TopicOptions& options,
                                         std::uint64_t& type_hash, std::string& error) {
  error.clear();
  type_hash = 0;
  if (find_standard_type(type_name) == nullptr) return nullptr;
  auto sink = conversion != nullptr ? open_ros2_sink(type_name, name, *conversion, type_hash, options)
                                    : open_standard_sink(type_name, name, lcm_encoding, type_hash, options);
  if (!sink) error = sink.error().message();
  return sink ? std::move(*sink) : nullptr;
}

}  // namespace horus::tools
