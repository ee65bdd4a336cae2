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

void* cpp_object(PyObject* obj, PyTypeObject* owner, const char* what) {
  if (PyObject_TypeCheck(obj, owner) == 0)
    throw py::type_error(fmt::format("{}: expected a {}, got {}", what, owner->tp_name, Py_TYPE(obj)->tp_name));
  auto* inst = reinterpret_cast<py::detail::instance*>(obj);
  if (!inst->simple_layout)  // a Python class deriving from two message classes: whose object?
    throw py::type_error(fmt::format("{}: a class deriving from several horus message classes is not supported ({})",
                                     what, Py_TYPE(obj)->tp_name));
  void* p = inst->get_value_and_holder().value_ptr();
  if (p == nullptr) throw py::type_error(fmt::format("{}: the {} was not initialized (__init__ not called)", what, owner->tp_name));
  return p;
}

namespace {

// horus._horus.Field: one reflected field of a message class, as a data descriptor.
struct FieldObject {
  PyObject_HEAD
  FieldInfo* info;
};

// Runs f, turning a C++ exception into the Python error it stands for; false then.
template <class F>
bool guarded(F&& f) {
  try {
    f();
    return true;
  } catch (py::error_already_set& e) {
    e.restore();
  } catch (const py::builtin_exception& e) {
    e.set_error();
  } catch (const Exception& e) {
    try {
      raise(e.error());
    } catch (py::error_already_set& set) {
      set.restore();
    }
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  } catch (...) {
    PyErr_SetString(PyExc_RuntimeError, "horus: an unknown C++ exception");
  }
  return false;
}

PyObject* field_get(PyObject* self, PyObject* obj, PyObject*) {
  if (obj == nullptr || obj == Py_None) {  // on the class: the descriptor itself
    Py_INCREF(self);
    return self;
  }
  const FieldInfo& f = *reinterpret_cast<FieldObject*>(self)->info;
  PyObject* out = nullptr;
  guarded([&] { out = f.get(f.addr(cpp_object(obj, f.owner, f.path.c_str())), obj).release().ptr(); });
  return out;
}

int field_set(PyObject* self, PyObject* obj, PyObject* value) {
  const FieldInfo& f = *reinterpret_cast<FieldObject*>(self)->info;
  if (value == nullptr) {
    PyErr_Format(PyExc_AttributeError, "%s: a message field cannot be deleted", f.path.c_str());
    return -1;
  }
  if (f.set == nullptr) {
    PyErr_Format(PyExc_AttributeError, "%s is read-only (large data: its metadata comes from the constructor)",
                 f.path.c_str());
    return -1;
  }
  return guarded([&] { f.set(f.addr(cpp_object(obj, f.owner, f.path.c_str())), value, f.path); }) ? 0 : -1;
}

void field_dealloc(PyObject* self) {
  PyTypeObject* type = Py_TYPE(self);
  delete reinterpret_cast<FieldObject*>(self)->info;
  type->tp_free(self);
  Py_DECREF(type);  // a heap type: each instance holds a reference to it
}

PyObject* field_repr(PyObject* self) {
  return PyUnicode_FromFormat("<horus field %s>", reinterpret_cast<FieldObject*>(self)->info->path.c_str());
}

PyTypeObject* field_type() {
  static PyTypeObject* const type = [] {
    static PyType_Slot slots[] = {
        {Py_tp_descr_get, reinterpret_cast<void*>(&field_get)},
        {Py_tp_descr_set, reinterpret_cast<void*>(&field_set)},
        {Py_tp_dealloc, reinterpret_cast<void*>(&field_dealloc)},
        {Py_tp_repr, reinterpret_cast<void*>(&field_repr)},
        {0, nullptr},
    };
    static PyType_Spec spec = {"horus._horus.Field", static_cast<int>(sizeof(FieldObject)), 0, Py_TPFLAGS_DEFAULT, slots};
    PyObject* t = PyType_FromSpec(&spec);  // kept for the life of the process
    if (t == nullptr) throw py::error_already_set();
    return reinterpret_cast<PyTypeObject*>(t);
  }();
  return type;
}

}  // namespace

void add_field(py::handle cls, FieldInfo f) {
  PyTypeObject* type = field_type();
  auto* obj = reinterpret_cast<FieldObject*>(type->tp_alloc(type, 0));
  if (obj == nullptr) throw py::error_already_set();
  obj->info = new FieldInfo(std::move(f));
  py::setattr(cls, obj->info->name.c_str(), py::reinterpret_steal<py::object>(reinterpret_cast<PyObject*>(obj)));
}

void add_fields(py::handle cls, const std::string& class_name, const FieldSpec* specs, std::size_t n) {
  py::tuple names(n);
  for (std::size_t i = 0; i < n; ++i) {
    const FieldSpec& f = specs[i];
    add_field(cls, FieldInfo{std::string(f.name), class_name + "." + std::string(f.name),
                             reinterpret_cast<PyTypeObject*>(cls.ptr()), f.addr, f.get, f.set});
    names[i] = py::str(std::string(f.name));
  }
  py::setattr(cls, "fields", names);
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
