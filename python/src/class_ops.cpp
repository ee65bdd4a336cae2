// class_ops.hpp
#include "class_ops.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include <bit>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "horus/json.hpp"
#include "horus/wire/dynamic.hpp"
#include "typed.hpp"

namespace horus::python {

void add_field(py::handle cls, FieldInfo f) {
  const auto info = std::make_shared<const FieldInfo>(std::move(f));
  py::cpp_function get([info](py::handle self) { return info->get(info->addr(self), self); });
  py::cpp_function set;
  if (info->set != nullptr)
    set = py::cpp_function([info](py::handle self, py::handle v) { info->set(info->addr(self), v, info->path); });
  py::object property = py::module_::import("builtins").attr("property");
  py::setattr(cls, info->name.c_str(), property(get, set.ptr() != nullptr ? py::object(set) : py::object(py::none())));
}

namespace {

// JSON (whose objects are sorted by key) as Python, with a struct's keys in field order.
py::object ordered(const nlohmann::json& j, const wire::DynType& t) {
  using K = wire::DynType::Kind;
  if (t.kind == K::Struct && j.is_object()) {
    py::dict out;
    for (std::size_t i = 0; i < t.field_names.size() && i < t.children.size(); ++i)
      if (auto it = j.find(t.field_names[i]); it != j.end()) out[py::str(t.field_names[i])] = ordered(*it, t.children[i]);
    return out;
  }
  if ((t.kind == K::Array || t.kind == K::Sequence) && j.is_array() && !t.children.empty() &&
      t.children[0].kind == K::Struct) {
    py::list out;
    for (const auto& e : j) out.append(ordered(e, t.children[0]));
    return out;
  }
  return json_to_py(j);
}

py::object to_dict(const ClassOps& ops, const void* m) {
  const auto format = net::WireFormat::Xcdr1;
  auto size = ops.wire->encoded_size(format, m);
  if (!size) raise(size.error());
  std::vector<std::byte> body(*size);
  ops.wire->encode(format, m, body);
  auto type = wire::parse_signature(ops.signature);
  if (!type) throw std::logic_error("horus: the signature of " + ops.short_name + " does not parse: " + type.error());
  auto json = wire::decode_json(*type, wire::DynFormat::Xcdr1, body, std::endian::native == std::endian::little);
  if (!json) throw std::logic_error("horus: " + ops.short_name + " does not decode from its own encoding: " + json.error());
  return ordered(*json, *type);
}

}  // namespace

void add_methods(py::handle cls, const ClassOps* ops) {
  auto method = [&](const char* name, py::cpp_function f) { py::setattr(cls, name, f); };
  const py::object c = py::reinterpret_borrow<py::object>(cls);
  method("__eq__", py::cpp_function([ops, c](py::handle self, py::handle other) {
    return PyObject_IsInstance(other.ptr(), c.ptr()) == 1 && ops->equal(ops->self(self), ops->self(other));
  }, py::is_method(cls), py::name("__eq__")));
  py::setattr(cls, "__hash__", py::none());
  auto copy = [ops](py::handle self) { return ops->copy(ops->self(self)); };
  method("__copy__", py::cpp_function(copy, py::is_method(cls), py::name("__copy__")));
  method("copy", py::cpp_function(copy, py::is_method(cls), py::name("copy"),
                                  py::doc("A copy that owns its bytes (a received image's copy leaves the pool slot)")));
  method("__deepcopy__", py::cpp_function([ops](py::handle self, py::handle) { return ops->copy(ops->self(self)); },
                                          py::is_method(cls), py::name("__deepcopy__")));
  method("to_dict", py::cpp_function([ops](py::handle self) { return to_dict(*ops, ops->self(self)); },
                                     py::is_method(cls), py::name("to_dict"),
                                     py::doc("The message as a dict of its fields (nested dicts and lists, as JSON)")));
  if (ops->from_json == nullptr) return;
  py::setattr(cls, "_from_dict", py::module_::import("builtins").attr("staticmethod")(py::cpp_function(
      [ops](py::handle d) {
        try {
          return ops->from_json(py_to_json(d, ops->short_name));
        } catch (const JsonError& e) {
          throw py::value_error(fmt::format("{}.from_dict: {}", ops->short_name, e.what()));
        }
      },
      py::name("_from_dict"))));
}

}  // namespace horus::python
