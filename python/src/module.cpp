// horus._horus: the compiled half of the Python package horus (python/horus/__init__.py
// re-exports it). The message classes, topics, errors, and the registry of standard types.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <string>

#include "fields.hpp"
#include "horus/msg/image.hpp"
#include "horus/msg/tensor.hpp"
#include "horus/version.hpp"
#include "typed.hpp"

namespace horus::python {

namespace {

std::map<std::string, MessageType, std::less<>>& types() {
  static auto* t = new std::map<std::string, MessageType, std::less<>>();  // never destroyed: holds Python objects
  return *t;
}

const char* error_class(Errc c) {
  switch (c) {
    case Errc::InvalidName: return "InvalidNameError";
    case Errc::TypeMismatch: return "TypeMismatchError";
    case Errc::InvalidArgument: return "InvalidArgumentError";
    case Errc::ConfigMismatch: return "ConfigMismatchError";
    case Errc::LimitReached: return "LimitReachedError";
    case Errc::Timeout: return "TimeoutError";
    case Errc::MessageTooLarge: return "MessageTooLargeError";
    case Errc::Config: return "ConfigError";
    case Errc::Io: return "IoError";
    case Errc::Corrupt: return "CorruptError";
  }
  return "Error";
}

template <class E>
void bind_enum(py::module_& m, const char* name) {
  py::enum_<E> e(m, name);
  for (const auto& v : reflect::enum_values<E>()) e.value(std::string(v.name).c_str(), v.value);
}

}  // namespace

[[noreturn]] void raise(const Error& e) {
  const py::object cls = py::module_::import("horus._errors").attr(error_class(e.code()));
  py::object exc = cls(e.message());
  exc.attr("code") = std::string(to_string(e.code()));
  PyErr_SetObject(cls.ptr(), exc.ptr());
  throw py::error_already_set();
}

void type_error(std::string_view path, std::string_view expected, py::handle got) {
  throw py::type_error(fmt::format("{}: expected {}, got {} ({})", path, expected,
                                   py::str(py::type::of(got).attr("__name__")).cast<std::string>(),
                                   py::repr(got).cast<std::string>().substr(0, 80)));
}

void value_error(const std::string& text) { throw py::value_error(text); }

void register_type(MessageType type) {
  auto key = type.qualified;
  types().insert_or_assign(std::move(key), std::move(type));
}

const MessageType* find_type(std::string_view qualified) {
  auto it = types().find(qualified);
  return it == types().end() ? nullptr : &it->second;
}

const MessageType* find_type_by_lcm_fingerprint(std::uint64_t fingerprint) {
  for (const auto& [q, t] : types())
    if (fingerprint != 0 && t.lcm_fingerprint == fingerprint) return &t;
  return nullptr;
}

const MessageType& type_of(py::handle cls) {
  if (py::isinstance<py::str>(cls)) {
    const auto name = cls.cast<std::string>();
    for (const auto& [q, t] : types())
      if (q == name || t.short_name == name) return t;
    throw py::type_error(fmt::format("'{}' is not a standard message type (horus.msg has Pose2D, Image, ...)", name));
  }
  if (py::hasattr(cls, "type_name"))
    if (const auto* t = find_type(py::str(cls.attr("type_name")).cast<std::string>()); t != nullptr && t->cls.is(cls))
      return *t;
  throw py::type_error(fmt::format("expected a message class of horus.msg (horus.msg.Pose2D, ...), got {}",
                                   py::repr(cls).cast<std::string>()));
}

py::object json_to_py(const nlohmann::json& j) {
  using V = nlohmann::json::value_t;
  switch (j.type()) {
    case V::null:
    case V::discarded: return py::none();
    case V::boolean: return py::bool_(j.get<bool>());
    case V::number_integer: return py::int_(j.get<std::int64_t>());
    case V::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case V::number_float: return py::float_(j.get<double>());
    case V::string: return py::str(j.get_ref<const std::string&>());
    case V::binary: {
      const auto& b = j.get_binary();
      return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
    }
    case V::array: {
      py::list out;
      for (const auto& e : j) out.append(json_to_py(e));
      return out;
    }
    case V::object: {
      py::dict out;
      for (const auto& [k, v] : j.items()) out[py::str(k)] = json_to_py(v);
      return out;
    }
  }
  return py::none();
}

nlohmann::json py_to_json(py::handle h, const std::string& path) {
  if (h.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
  if (py::isinstance<py::int_>(h)) {
    if (h.cast<py::int_>() < py::int_(0)) return h.cast<std::int64_t>();
    return h.cast<std::uint64_t>();
  }
  if (py::isinstance<py::float_>(h)) return h.cast<double>();
  if (py::isinstance<py::str>(h)) return h.cast<std::string>();
  if (py::isinstance<py::array>(h)) return py_to_json(h.attr("tolist")(), path);
  if (py::hasattr(h, "to_dict") && py::hasattr(h, "type_name")) return py_to_json(h.attr("to_dict")(), path);
  if (py::isinstance<py::dict>(h)) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, v] : h.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) type_error(path, "str keys", k);
      out[k.cast<std::string>()] = py_to_json(v, path + "." + k.cast<std::string>());
    }
    return out;
  }
  if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    nlohmann::json out = nlohmann::json::array();
    std::size_t i = 0;
    for (const auto& e : h) out.push_back(py_to_json(e, path + "[" + std::to_string(i++) + "]"));
    return out;
  }
  if (py::hasattr(h, "name") && py::hasattr(h, "value") && py::hasattr(h, "__members__"))
    return py::str(h.attr("name")).cast<std::string>();  // a horus.msg enum member
  if (py::hasattr(h, "__index__")) return py_to_json(py::reinterpret_steal<py::object>(PyNumber_Index(h.ptr())), path);
  if (py::hasattr(h, "__float__")) return py_to_json(py::reinterpret_steal<py::object>(PyNumber_Float(h.ptr())), path);
  type_error(path, "a dict, list, str, number, bool or None", h);
}

std::chrono::nanoseconds seconds(py::handle s, std::string_view what) {
  if (s.is_none()) return std::chrono::hours(24 * 365 * 100);
  const double v = number_from<double>(s, what);
  if (!std::isfinite(v) || v < 0)
    throw py::value_error(fmt::format("{}: seconds, a finite number of 0 or more (got {})", what, v));
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::min(v, 3.0e9) * 1e9));
}

}  // namespace horus::python

PYBIND11_MODULE(_horus, m) {
  namespace hp = horus::python;
  namespace py = pybind11;
  m.doc() = "horus: typed zero-copy topics for robot fleets (the compiled half; import horus)";
  m.attr("__version__") = std::string(horus::version_number());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const horus::Exception& e) {
      try {
        hp::raise(e.error());
      } catch (py::error_already_set& set) {
        set.restore();
      }
    }
  });
  py::module_ msg = m.def_submodule("msg", "The standard messages: classes from the C++ reflection");
  hp::bind_enum<horus::msg::ImageEncoding>(msg, "ImageEncoding");
  hp::bind_enum<horus::msg::TensorDtype>(msg, "TensorDtype");
  hp::bind_enum<horus::msg::DeviceType>(msg, "DeviceType");
  hp::bind_messages_first(msg);
  hp::bind_messages_second(msg);
  hp::bind_messages_third(msg);
  hp::bind_generic(msg);
  m.def("message_types", [] {
    py::list out;
    for (const auto& [q, t] : hp::types()) out.append(t.cls);
    return out;
  }, "Every standard message class, by qualified name");
  hp::bind_topics(m);
  hp::bind_tools(m);
}
