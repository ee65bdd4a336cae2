// What the Python class of a message is made of, without a pybind11 function per field or per
// class: every attribute and method is one of a few shared functions (class_ops.cpp) that call,
// through the pointers below, small per-type functions (typed_impl.hpp). This keeps the build
// of 81 classes cheap: pybind11 instantiates its call machinery a few times, not thousands.
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json_fwd.hpp>

#include <string>

#include "horus/detail/network_link.hpp"

namespace horus::python {

namespace py = pybind11;

/// One reflected field as a Python attribute.
struct FieldInfo {
  std::string name;  // the C++ name
  std::string path;  // "Pose2D.x", for errors
  PyTypeObject* owner = nullptr;                            // the class
  void* (*addr)(void* object) = nullptr;                    // the field in the C++ object
  py::object (*get)(void* field, py::handle owner) = nullptr;  // to_py of the field's type
  void (*set)(void* field, py::handle value, const std::string& path) = nullptr;  // null: read-only
};

/// The per-type functions behind a class's methods (one static instance per type). to_dict
/// encodes with the library's XCDR1 codec of the type (detail::WireOps) and renders the bytes
/// with the type's signature (horus/wire/dynamic.hpp): the JSON of horus::to_json, without a
/// JSON walk compiled per type. __repr__, the keyword constructor and from_dict are Python's,
/// over the fields' attributes (horus/__init__.py).
struct ClassOps {
  std::string short_name;
  std::string signature;                            // reflect::type_signature<T>()
  const detail::WireOps* wire = nullptr;            // the type's codecs
  const void* (*self)(py::handle obj) = nullptr;    // the C++ object of an instance
  bool (*equal)(const void* a, const void* b) = nullptr;
  py::object (*copy)(const void* m) = nullptr;
  py::object (*from_json)(const nlohmann::json& j) = nullptr;  // large data only (its fields are read-only)
};

/// One field as the per-type table gives it (typed_impl.hpp's field_specs): constant data.
struct FieldSpec {
  std::string_view name;
  void* (*addr)(void* object);
  py::object (*get)(void* field, py::handle owner);
  void (*set)(void* field, py::handle value, const std::string& path);  // null: read-only
};

/// The C++ object of `obj`, an instance of `owner` (of a subclass); raises TypeError naming
/// `what` otherwise. Reads pybind11's instance directly: a field access costs no type caster.
void* cpp_object(PyObject* obj, PyTypeObject* owner, const char* what);

/// Adds `f` to `cls` as a data descriptor (a C type, horus._horus.Field: no pybind11 call per access).
void add_field(py::handle cls, FieldInfo f);
/// Adds the `n` fields of `specs` as properties, and the tuple of their names as `fields`.
void add_fields(py::handle cls, const std::string& class_name, const FieldSpec* specs, std::size_t n);
/// Adds __eq__, __copy__, __deepcopy__, copy, to_dict (and, for large data, _from_dict) to `cls`.
void add_methods(py::handle cls, const ClassOps* ops);

}  // namespace horus::python
