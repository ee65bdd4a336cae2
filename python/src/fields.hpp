// A reflected field's value to and from Python: numbers, enums (horus.msg enums), text
// (fixed char arrays as str), nested messages (views into the parent), fixed arrays of numbers
// (NumPy views into the message), vectors and byte buffers (NumPy copies), lists of the rest.
// Every error names the field path and what was expected.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

namespace horus::python {

namespace py = pybind11;

template <class V>
struct is_array : std::false_type {};
template <class E, std::size_t N>
struct is_array<std::array<E, N>> : std::true_type {
  using element = E;
};
template <class V>
struct is_vector : std::false_type {};
template <class E, class A>
struct is_vector<std::vector<E, A>> : std::true_type {
  using element = E;
};
template <>
struct is_vector<ByteBuffer> : std::true_type {
  using element = std::uint8_t;
};

template <class V>
inline constexpr bool is_number = std::is_arithmetic_v<V> && !std::is_same_v<V, bool> && !std::is_same_v<V, char>;

[[noreturn]] void type_error(std::string_view path, std::string_view expected, py::handle got);
[[noreturn]] void value_error(const std::string& text);

/// A Python int or float as the number type V, range-checked (an int field refuses 1.5 and 300
/// for a uint8); errors name `path`.
template <class V>
V number_from(py::handle h, std::string_view path) {
  PyObject* o = h.ptr();
  if constexpr (std::is_floating_point_v<V>) {
    if (PyFloat_Check(o)) return static_cast<V>(PyFloat_AS_DOUBLE(o));
    if (PyBool_Check(o) || (!PyLong_Check(o) && !py::hasattr(h, "__float__"))) type_error(path, "a number", h);
    const double v = PyFloat_AsDouble(o);
    if (v == -1.0 && PyErr_Occurred()) throw py::error_already_set();
    return static_cast<V>(v);
  } else {
    if (PyBool_Check(o) || (!PyLong_Check(o) && !py::hasattr(h, "__index__"))) type_error(path, "an integer", h);
    const py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(o));  // a NumPy integer too
    if (!i) throw py::error_already_set();
    int overflow = 0;
    if constexpr (std::is_signed_v<V>) {
      const long long v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
      if (overflow == 0 && v >= std::numeric_limits<V>::min() && v <= std::numeric_limits<V>::max())
        return static_cast<V>(v);
    } else {
      const unsigned long long v = PyLong_AsUnsignedLongLong(i.ptr());
      if (PyErr_Occurred()) PyErr_Clear();
      else if (v <= std::numeric_limits<V>::max()) return static_cast<V>(v);
    }
    value_error(std::string(path) + ": " + py::str(h).cast<std::string>() + " is out of range for " +
                (std::is_signed_v<V> ? "int" : "uint") + std::to_string(sizeof(V) * 8) + " (" +
                std::to_string(std::numeric_limits<V>::min()) + " to " + std::to_string(std::numeric_limits<V>::max()) +
                ")");
  }
}

/// The NumPy array of `n` V at `data`: a view kept valid by `base`, or a copy without one;
/// read-only unless `writable` (a copy always is: writing it would change nothing).
template <class V>
py::array numpy_of(const V* data, std::size_t n, py::handle base, bool writable) {
  py::array_t<V> a = base ? py::array_t<V>(static_cast<py::ssize_t>(n), data, base)
                          : py::array_t<V>(static_cast<py::ssize_t>(n), data);
  if (!writable || !base) a.attr("setflags")(py::arg("write") = false);
  return a;
}

template <class V>
py::object to_py(V& v, py::handle owner, bool writable = true);
template <class V>
void from_py(py::handle h, V& v, const std::string& path);

/// A field's value: nested messages are views of the owner and fixed arrays of numbers NumPy
/// views (read-only, and nested messages copies, when not `writable`: large data's metadata);
/// vectors are read-only NumPy copies and other arrays tuples (assign the whole field).
template <class V>
py::object to_py(V& v, py::handle owner, bool writable) {
  using namespace horus::reflect;
  if constexpr (std::is_same_v<V, bool> || is_number<V>) {
    return py::cast(v);
  } else if constexpr (std::is_same_v<V, char>) {
    return py::str(&v, 1);
  } else if constexpr (ReflectedEnum<V>) {
    return py::cast(v);
  } else if constexpr (reflect::detail::is_char_array<V>::value) {
    const auto s = fixed_str_view(v);  // bytes from another program: invalid UTF-8 shows as U+FFFD
    return py::reinterpret_steal<py::str>(PyUnicode_DecodeUTF8(s.data(), static_cast<py::ssize_t>(s.size()), "replace"));
  } else if constexpr (Reflected<V>) {
    if (!writable) return py::cast(V(v));
    return py::cast(&v, py::return_value_policy::reference_internal, owner);
  } else if constexpr (is_array<V>::value) {
    using E = typename is_array<V>::element;
    if constexpr (is_number<E>) {
      return numpy_of<E>(v.data(), v.size(), owner, writable);
    } else {
      py::tuple out(v.size());
      for (std::size_t i = 0; i < v.size(); ++i) out[i] = to_py(v[i], owner, writable);
      return out;
    }
  } else if constexpr (is_vector<V>::value) {
    using E = typename is_vector<V>::element;
    return numpy_of<E>(v.data(), v.size(), py::handle(), false);
  } else {
    static_assert(sizeof(V) == 0, "a field type the Python binding does not know");
  }
}

/// A horus.msg enum from an enum member, its name or its value.
template <class E>
E enum_from(py::handle h, std::string_view path) {
  if (py::isinstance<E>(h)) return h.cast<E>();
  std::string names;
  for (const auto& ev : reflect::enum_values<E>()) names += (names.empty() ? "" : ", ") + std::string(ev.name);
  if (py::isinstance<py::str>(h)) {
    E e{};
    if (reflect::enum_from_name(h.cast<std::string>(), e)) return e;
    value_error(std::string(path) + ": '" + h.cast<std::string>() + "' is not one of " + names);
  }
  const auto raw = number_from<std::underlying_type_t<E>>(h, path);
  for (const auto& ev : reflect::enum_values<E>())
    if (static_cast<std::underlying_type_t<E>>(ev.value) == raw) return ev.value;
  value_error(std::string(path) + ": " + std::to_string(raw) + " is not a value of " + names);
}

template <class V>
void from_py(py::handle h, V& v, const std::string& path) {
  using namespace horus::reflect;
  if constexpr (std::is_same_v<V, bool>) {
    if (!py::isinstance<py::bool_>(h) && !py::isinstance<py::int_>(h)) type_error(path, "a bool", h);
    v = h.cast<bool>();
  } else if constexpr (is_number<V>) {
    v = number_from<V>(h, path);
  } else if constexpr (std::is_same_v<V, char>) {
    if (!py::isinstance<py::str>(h) || py::len(h) != 1) type_error(path, "a one-character str", h);
    v = h.cast<std::string>()[0];
  } else if constexpr (ReflectedEnum<V>) {
    v = enum_from<V>(h, path);
  } else if constexpr (reflect::detail::is_char_array<V>::value) {
    if (!py::isinstance<py::str>(h)) type_error(path, "a str", h);
    const auto s = h.cast<std::string>();
    if (!set_fixed_str(v, s))
      value_error(path + ": '" + s + "' is " + std::to_string(s.size()) + " bytes; the field holds at most " +
                  std::to_string(v.size() - 1));
  } else if constexpr (Reflected<V>) {
    if (!py::isinstance<V>(h)) type_error(path, std::string(horus::type_name<V>()), h);
    v = h.cast<const V&>();
  } else if constexpr (is_array<V>::value || is_vector<V>::value) {
    if (!py::isinstance<py::sequence>(h) && !py::isinstance<py::array>(h)) type_error(path, "a sequence", h);
    const py::sequence seq = py::isinstance<py::array>(h) ? py::sequence(h.attr("tolist")()) : h.cast<py::sequence>();
    const std::size_t n = py::len(seq);
    V out{};  // filled whole, then assigned: a bad element leaves the field as it was
    if constexpr (is_array<V>::value) {
      if (n != out.size())
        value_error(path + ": " + std::to_string(n) + " elements given; the field has exactly " + std::to_string(out.size()));
    } else {
      out.resize(n);
    }
    for (std::size_t i = 0; i < n; ++i) from_py(seq[i], out[i], path + "[" + std::to_string(i) + "]");
    v = std::move(out);
  } else {
    static_assert(sizeof(V) == 0, "a field type the Python binding does not know");
  }
}

}  // namespace horus::python
