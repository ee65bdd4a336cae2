// The per-type half of the module, included by messages_{first,second,third}.cpp: a message's
// Python class from its reflection, and its topic behind AnyTopic (the library's AnyTopic of the
// type, horus/standard_types.hpp; large data's own Topic<T>, which lends pool slots).
#pragma once

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "class_ops.hpp"
#include "fields.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/standard_types.hpp"
#include "horus/topic.hpp"
#include "horus/wire/lcm.hpp"
#include "large_data.hpp"
#include "loan.hpp"
#include "typed.hpp"

namespace horus::python {

template <class T>
inline constexpr bool kLarge = is_pool_message<T>;

inline std::string short_name(std::string_view qualified) {
  const auto at = qualified.rfind("::");
  return std::string(at == std::string_view::npos ? qualified : qualified.substr(at + 2));
}

/// T's Python class (bound before any instance exists).
template <class T>
PyTypeObject* class_of() {
  static PyTypeObject* const type = reinterpret_cast<PyTypeObject*>(py::type::of<T>().ptr());
  return type;
}

/// A Python object as a T: an instance of T's class (raises TypeError naming both types otherwise).
template <class T>
const T& message_from(py::handle h) {
  if (PyObject_TypeCheck(h.ptr(), class_of<T>()) == 0)
    type_error("message", fmt::format("a horus.msg.{} (the topic's type)", short_name(type_name<T>())), h);
  return *static_cast<const T*>(cpp_object(h.ptr(), class_of<T>(), "message"));
}

// The per-type and per-field functions behind class_ops.hpp.
template <class T>
const void* self_of(py::handle obj) {
  return cpp_object(obj.ptr(), class_of<T>(), short_name(type_name<T>()).c_str());
}
template <class T, std::size_t I>
void* field_addr(void* object) {
  return &(static_cast<T*>(object)->*(reflect::get<I>(reflect::fields<T>()).ptr));
}
template <class V, bool Writable>
py::object get_erased(void* field, py::handle owner) {
  return to_py(*static_cast<V*>(field), owner, Writable);
}
template <class V>
void set_erased(void* field, py::handle value, const std::string& path) {
  from_py(value, *static_cast<V*>(field), path);
}

template <class T>
const ClassOps* class_ops() {
  static const ClassOps ops = [] {
    ClassOps o;
    o.short_name = short_name(type_name<T>());
    o.signature = reflect::type_signature<T>();
    o.wire = detail::wire_ops_of<T>();
    o.self = &self_of<T>;
    o.equal = [](const void* a, const void* b) { return *static_cast<const T*>(a) == *static_cast<const T*>(b); };
    o.copy = [](const void* m) { return py::cast(T(*static_cast<const T*>(m))); };
    if constexpr (kLarge<T>) o.from_json = [](const nlohmann::json& j) { return py::cast(from_json<T>(j)); };
    return o;
  }();
  return &ops;
}

// The field table of T: per field, its address function and its type's converters.
template <class T, std::size_t I>
constexpr FieldSpec field_spec() {
  constexpr auto f = reflect::get<I>(reflect::fields<T>());
  using V = typename std::remove_cvref_t<decltype(f)>::type;
  FieldSpec spec{f.name, &field_addr<T, I>, nullptr, nullptr};
  if constexpr (std::is_same_v<V, ByteBuffer>) {
    spec.get = [](void*, py::handle owner) -> py::object { return data_view<T>(py::reinterpret_borrow<py::object>(owner)); };
  } else {
    spec.get = &get_erased<V, !kLarge<T>>;  // large data's metadata: read-only views and copies
    if constexpr (!kLarge<T>) spec.set = &set_erased<V>;
  }
  return spec;
}
template <class T, std::size_t... I>
void add_fields(py::handle cls, std::index_sequence<I...>) {
  static constexpr FieldSpec specs[] = {field_spec<T, I>()...};
  python::add_fields(cls, short_name(type_name<T>()), specs, sizeof...(I));
}

template <class T>
py::class_<T> bind_class(py::module_& msg) {
  py::class_<T> c(msg, short_name(type_name<T>()).c_str());
  c.def(py::init<>());
  add_fields<T>(c, std::make_index_sequence<reflect::field_count<T>>{});
  c.attr("type_name") = std::string(type_name<T>());
  c.attr("type_hash") = type_hash<T>;
  c.attr("large_data") = kLarge<T>;
  add_methods(c, class_ops<T>());
  return c;
}

// A topic of a standard type that is not large data: the library's AnyTopic of the type
// (horus/standard_types.hpp: its Topic<T> compiled once there), this class converting only.
template <class T>
class TopicOf final : public AnyTopic {
 public:
  explicit TopicOf(std::unique_ptr<horus::AnyTopic> t) : topic_(std::move(t)) {}
  void send(py::handle msg) override { topic_->send(&message_from<T>(msg)); }
  bool try_send(py::handle msg) override { return topic_->try_send(&message_from<T>(msg)); }
  std::optional<Error> send_blocking(py::handle msg, std::chrono::nanoseconds timeout) override {
    // A copy that no other Python thread can change while the GIL is released.
    const T copy = message_from<T>(msg);
    Result<void> ok;
    {
      py::gil_scoped_release free;
      ok = topic_->send_blocking(&copy, timeout);
    }
    if (ok) return std::nullopt;
    if (ok.error().code() != Errc::Timeout) raise(ok.error());
    return std::move(ok.error());
  }
  py::object recv() override {
    T m{};
    return topic_->recv_into(&m) ? py::cast(std::move(m)) : py::none();
  }
  py::object recv_for(std::chrono::nanoseconds timeout) override {
    T m{};
    bool got = false;
    {
      py::gil_scoped_release free;
      got = topic_->recv_for_into(&m, timeout);
    }
    return got ? py::cast(std::move(m)) : py::none();
  }
  py::object read_latest() override {
    T m{};
    return topic_->read_latest_into(&m) ? py::cast(std::move(m)) : py::none();
  }
  bool wait_for(std::chrono::nanoseconds timeout) override {
    py::gil_scoped_release free;
    return topic_->wait_for(timeout);
  }
  bool has_message() override { return topic_->has_message(); }
  std::uint64_t pending_count() override { return topic_->pending_count(); }
  std::uint64_t dropped_count() const override { return topic_->dropped_count(); }
  std::uint32_t pub_count() const override { return topic_->pub_count(); }
  std::uint32_t sub_count() const override { return topic_->sub_count(); }
  TopicMetrics metrics() const override { return topic_->metrics(); }
  std::uint64_t deadline_missed_count() const override { return topic_->deadline_missed_count(); }
  std::uint64_t expired_count() const override { return topic_->expired_count(); }
  std::uint64_t network_errors() const override { return topic_->network_errors(); }
  bool is_bridge() const override { return topic_->is_bridge(); }
  std::uint32_t capacity() const override { return topic_->capacity(); }
  std::size_t max_message_size() const override { return topic_->max_message_size(); }
  Backend backend() const override { return topic_->backend(); }
  std::string_view name() const override { return topic_->name(); }
  void publish_only() override { topic_->publish_only(); }
  WaitSet::Id attach(WaitSet& ws) override { return topic_->attach(ws); }
  py::object loan(const py::args&, std::shared_ptr<AnyTopic>) override {
    throw py::type_error(fmt::format("loan: {} is not large data (only Image, DepthImage, PointCloud and Tensor "
                                     "topics lend pool slots)",
                                     short_name(type_name<T>())));
  }

 private:
  std::unique_ptr<horus::AnyTopic> topic_;
};

// A topic of large data (Image, DepthImage, PointCloud, Tensor): its own Topic<T>, which lends
// pool slots (loan()).
template <class T>
class LargeTopicOf final : public AnyTopic {
 public:
  explicit LargeTopicOf(Topic<T> t) : topic_(std::move(t)) {}
  void send(py::handle msg) override {
    if (py::isinstance<PyLoan>(msg)) return send_loan(msg.cast<PyLoan&>());
    topic_.send(message_from<T>(msg));
  }
  bool try_send(py::handle msg) override { return topic_.try_send(message_from<T>(msg)).has_value(); }
  std::optional<Error> send_blocking(py::handle msg, std::chrono::nanoseconds timeout) override {
    // Not a copy: large data's bytes are not resizable from Python.
    const T& m = message_from<T>(msg);
    Result<void> ok;
    {
      py::gil_scoped_release free;
      ok = topic_.send_blocking(m, timeout);
    }
    if (ok) return std::nullopt;
    if (ok.error().code() != Errc::Timeout) raise(ok.error());
    return std::move(ok.error());
  }
  py::object recv() override { return out(topic_.recv()); }
  py::object recv_for(std::chrono::nanoseconds timeout) override {
    std::optional<T> m;
    {
      py::gil_scoped_release free;
      m = topic_.recv_for(timeout);
    }
    return out(std::move(m));
  }
  py::object read_latest() override { return out(topic_.read_latest()); }
  bool wait_for(std::chrono::nanoseconds timeout) override {
    py::gil_scoped_release free;
    return topic_.wait_for(timeout);
  }
  bool has_message() override { return topic_.has_message(); }
  std::uint64_t pending_count() override { return topic_.pending_count(); }
  std::uint64_t dropped_count() const override { return topic_.dropped_count(); }
  std::uint32_t pub_count() const override { return topic_.pub_count(); }
  std::uint32_t sub_count() const override { return topic_.sub_count(); }
  TopicMetrics metrics() const override { return topic_.metrics(); }
  std::uint64_t deadline_missed_count() const override { return topic_.deadline_missed_count(); }
  std::uint64_t expired_count() const override { return topic_.expired_count(); }
  std::uint64_t network_errors() const override { return topic_.network_errors(); }
  bool is_bridge() const override { return topic_.is_bridge(); }
  std::uint32_t capacity() const override { return topic_.capacity(); }
  std::size_t max_message_size() const override { return topic_.max_message_size(); }
  Backend backend() const override { return topic_.backend(); }
  std::string_view name() const override { return topic_.name(); }
  void publish_only() override { topic_.publish_only(); }
  WaitSet::Id attach(WaitSet& ws) override { return ws.attach(topic_); }
  py::object loan(const py::args& args, std::shared_ptr<AnyTopic> self) override {
    using D = typename T::Descriptor;
    const bool given = args.size() == 1 && PyObject_TypeCheck(args[0].ptr(), class_of<D>()) != 0;
    const D desc = given ? *static_cast<const D*>(cpp_object(args[0].ptr(), class_of<D>(), "loan"))
                         : describe_from(static_cast<const T*>(nullptr), args);
    auto l = topic_.loan(desc);
    if (!l) raise(l.error());
    return py::cast(PyLoan(std::make_unique<LoanOf<T>>(std::move(*l)), std::move(self)));
  }

 private:
  void send_loan(PyLoan& l) {
    auto* mine = dynamic_cast<LoanOf<T>*>(l.get());
    if (mine == nullptr) throw py::value_error("send: this loan was sent already, or is of another type");
    auto owned = l.take();
    topic_.send(std::move(static_cast<LoanOf<T>&>(*owned).loan));
  }
  static py::object out(std::optional<T>&& m) {
    if (!m) return py::none();
    return py::cast(std::move(*m));
  }
  Topic<T> topic_;
};

template <class T>
MessageType message_type(py::object cls) {
  MessageType t;
  t.qualified = std::string(type_name<T>());
  t.short_name = short_name(t.qualified);
  t.hash = type_hash<T>;
  t.cls = std::move(cls);
  t.large = kLarge<T>;
  if constexpr (lcm::expressible<T>) t.lcm_fingerprint = lcm::fingerprint<T>();
  t.open = [](const std::string& name, const TopicOptions& options) -> std::unique_ptr<AnyTopic> {
    if constexpr (kLarge<T>) {
      auto topic = Topic<T>::open(name, options);
      if (!topic) raise(topic.error());
      return std::make_unique<LargeTopicOf<T>>(std::move(*topic));
    } else {
      static const StandardType* const type = find_standard_type(type_hash<T>);
      if (type == nullptr) throw std::logic_error(std::string(type_name<T>()) + " is not in the library's standard types");
      auto topic = type->open(name, options);
      if (!topic) raise(topic.error());
      return std::make_unique<TopicOf<T>>(std::move(*topic));
    }
  };
  return t;
}

template <class... T>
void bind_all(py::module_& msg, msg::TypeList<T...>) {
  auto one = [&]<class M>() {
    auto c = bind_class<M>(msg);
    if constexpr (kLarge<M>) bind_large_extras(c);
    register_type(message_type<M>(c));
  };
  (one.template operator()<T>(), ...);
}

}  // namespace horus::python
