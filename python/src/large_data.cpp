// NumPy views of large-data messages, and their constructors (large_data.hpp).
#include "large_data.hpp"

#include <fmt/format.h>
#include <pybind11/stl.h>

#include <optional>
#include <stdexcept>

#include "fields.hpp"

namespace horus::python {

py::dtype numpy_dtype(msg::TensorDtype d) {
  using D = msg::TensorDtype;
  switch (d) {
    case D::F32: return py::dtype("float32");
    case D::F64: return py::dtype("float64");
    case D::F16: return py::dtype("float16");
    case D::BF16: return py::dtype("uint16");
    case D::I8: return py::dtype("int8");
    case D::I16: return py::dtype("int16");
    case D::I32: return py::dtype("int32");
    case D::I64: return py::dtype("int64");
    case D::U8: return py::dtype("uint8");
    case D::U16: return py::dtype("uint16");
    case D::U32: return py::dtype("uint32");
    case D::U64: return py::dtype("uint64");
    case D::Bool: return py::dtype("bool");
  }
  return py::dtype("uint8");
}

namespace {
py::ssize_t ss(std::uint64_t v) { return static_cast<py::ssize_t>(v); }

// A row-major shape's byte strides.
std::vector<py::ssize_t> packed(const std::vector<py::ssize_t>& shape, py::ssize_t element) {
  std::vector<py::ssize_t> s(shape.size());
  py::ssize_t step = element;
  for (std::size_t i = shape.size(); i-- > 0;) {
    s[i] = step;
    step *= shape[i];
  }
  return s;
}

// frame_id, writable through the class's set_frame_id (which refuses text that does not fit).
template <class T>
void frame_id_property(py::class_<T>& c, const char* cls) {
  c.def_property("frame_id", [](const T& m) { return std::string(m.frame_id()); }, [cls](T& m, const std::string& v) {
    if (!m.set_frame_id(v)) throw py::value_error(fmt::format("{}.frame_id: '{}' is too long for the field", cls, v));
  });
}

template <class D>
D described(std::optional<D> d, std::string_view what) {
  if (!d) throw py::value_error(fmt::format("{}: these dimensions describe no valid message (zero, unknown type, or over 2 GiB)", what));
  return *d;
}
}  // namespace

namespace {
template <class V>
V arg(const py::args& a, std::size_t i, V fallback, const char* what) {
  if (i >= a.size()) return fallback;
  if constexpr (std::is_enum_v<V>) return enum_from<V>(a[i], what);
  else if constexpr (std::is_same_v<V, std::vector<std::uint64_t>>) return a[i].cast<std::vector<std::uint64_t>>();
  else return number_from<V>(a[i], what);
}
void arity(const py::args& a, std::size_t lo, std::size_t hi, const char* usage) {
  if (a.size() < lo || a.size() > hi) throw py::type_error(fmt::format("loan: expected {}, or a descriptor", usage));
}
}  // namespace

msg::ImageDescriptor describe_from(const msg::Image*, const py::args& a) {
  arity(a, 2, 3, "(height, width[, encoding])");
  return described(msg::Image::describe(arg<std::uint32_t>(a, 0, 0, "height"), arg<std::uint32_t>(a, 1, 0, "width"),
                                        arg(a, 2, msg::ImageEncoding::Rgb8, "encoding")),
                   "Image.describe");
}
msg::DepthImageDescriptor describe_from(const msg::DepthImage*, const py::args& a) {
  arity(a, 2, 3, "(height, width[, dtype])");
  return described(msg::DepthImage::describe(arg<std::uint32_t>(a, 0, 0, "height"), arg<std::uint32_t>(a, 1, 0, "width"),
                                             arg(a, 2, msg::TensorDtype::F32, "dtype")),
                   "DepthImage.describe");
}
msg::PointCloudDescriptor describe_from(const msg::PointCloud*, const py::args& a) {
  arity(a, 1, 3, "(num_points[, fields_per_point[, dtype]])");
  return described(msg::PointCloud::describe(arg<std::uint64_t>(a, 0, 0, "num_points"),
                                             arg<std::uint32_t>(a, 1, 3, "fields_per_point"),
                                             arg(a, 2, msg::TensorDtype::F32, "dtype")),
                   "PointCloud.describe");
}
msg::TensorDescriptor describe_from(const msg::Tensor*, const py::args& a) {
  arity(a, 1, 2, "(shape[, dtype])");
  const auto shape = arg(a, 0, std::vector<std::uint64_t>{}, "shape");
  return described(msg::Tensor::describe(std::span<const std::uint64_t>(shape), arg(a, 1, msg::TensorDtype::F32, "dtype")),
                   "Tensor.describe");
}

ArrayShape array_shape(const msg::Image& m) {
  const std::uint32_t bpp = m.bytes_per_pixel(), ch = m.channels();
  const std::uint32_t elem = ch == 0 ? 1 : bpp / ch;
  ArrayShape s;
  s.dtype = elem == 4 ? py::dtype("float32") : elem == 2 ? py::dtype("uint16") : py::dtype("uint8");
  s.shape = {ss(m.height()), ss(m.width())};
  s.strides = {ss(m.step()), ss(bpp)};
  if (ch > 1) {
    s.shape.push_back(ss(ch));
    s.strides.push_back(ss(elem));
  }
  return s;
}

ArrayShape array_shape(const msg::DepthImage& m) {
  ArrayShape s;
  s.dtype = numpy_dtype(m.dtype());
  s.shape = {ss(m.height()), ss(m.width())};
  s.strides = packed(s.shape, s.dtype.itemsize());
  return s;
}

ArrayShape array_shape(const msg::PointCloud& m) {
  ArrayShape s;
  s.dtype = numpy_dtype(m.dtype());
  s.shape = {ss(m.point_count()), ss(m.fields_per_point())};
  s.strides = packed(s.shape, s.dtype.itemsize());
  return s;
}

ArrayShape array_shape(const msg::Tensor& m) {
  ArrayShape s;
  s.dtype = numpy_dtype(m.dtype());
  for (auto d : m.shape()) s.shape.push_back(ss(d));
  for (auto d : m.strides()) s.strides.push_back(ss(d));
  return s;
}

py::array array_over(const ArrayShape& s, const std::uint8_t* bytes, std::size_t size, py::handle base, bool writable) {
  py::array a = s.shape.empty() ? py::array(py::dtype("uint8"), {ss(size)}, {py::ssize_t{1}}, bytes, base)
                                : py::array(s.dtype, s.shape, s.strides, bytes, base);
  if (!writable) a.attr("setflags")(py::arg("write") = false);
  return a;
}

void bind_large_extras(py::class_<msg::Image>& c) {
  c.def(py::init<std::uint32_t, std::uint32_t, msg::ImageEncoding>(), py::arg("height"), py::arg("width"),
        py::arg("encoding") = msg::ImageEncoding::Rgb8);
  c.def_static("describe", [](std::uint32_t h, std::uint32_t w, msg::ImageEncoding e) {
    return described(msg::Image::describe(h, w, e), "Image.describe");
  }, py::arg("height"), py::arg("width"), py::arg("encoding") = msg::ImageEncoding::Rgb8);
  frame_id_property(c, "Image");
  c.def_property("timestamp_ns", &msg::Image::timestamp_ns, [](msg::Image& m, std::uint64_t ns) { m.set_timestamp_ns(ns); });
}

void bind_large_extras(py::class_<msg::DepthImage>& c) {
  c.def(py::init([](std::uint32_t h, std::uint32_t w, msg::TensorDtype d) {
          if (d == msg::TensorDtype::F32) return msg::DepthImage::meters(h, w);
          if (d == msg::TensorDtype::U16) return msg::DepthImage::millimeters(h, w);
          throw py::value_error("DepthImage: dtype is F32 (metres) or U16 (millimetres)");
        }),
        py::arg("height"), py::arg("width"), py::arg("dtype") = msg::TensorDtype::F32);
  c.def_static("describe", [](std::uint32_t h, std::uint32_t w, msg::TensorDtype d) {
    return described(msg::DepthImage::describe(h, w, d), "DepthImage.describe");
  }, py::arg("height"), py::arg("width"), py::arg("dtype") = msg::TensorDtype::F32);
  c.def_property("timestamp_ns", &msg::DepthImage::timestamp_ns,
                 [](msg::DepthImage& m, std::uint64_t ns) { m.set_timestamp_ns(ns); });
  frame_id_property(c, "DepthImage");
  c.def_property("depth_scale", &msg::DepthImage::depth_scale, [](msg::DepthImage& m, float v) {
    if (!m.set_depth_scale(v)) throw py::value_error("DepthImage.depth_scale: a finite number above 0 (mm per unit)");
  });
}

void bind_large_extras(py::class_<msg::PointCloud>& c) {
  c.def(py::init(&msg::PointCloud::make), py::arg("num_points"), py::arg("fields_per_point") = 3,
        py::arg("dtype") = msg::TensorDtype::F32);
  c.def_static("describe", [](std::uint64_t n, std::uint32_t f, msg::TensorDtype d) {
    return described(msg::PointCloud::describe(n, f, d), "PointCloud.describe");
  }, py::arg("num_points"), py::arg("fields_per_point") = 3, py::arg("dtype") = msg::TensorDtype::F32);
  frame_id_property(c, "PointCloud");
  c.def_property("timestamp_ns", &msg::PointCloud::timestamp_ns,
                 [](msg::PointCloud& m, std::uint64_t ns) { m.set_timestamp_ns(ns); });
}

void bind_large_extras(py::class_<msg::Tensor>& c) {
  c.def(py::init([](const std::vector<std::uint64_t>& shape, msg::TensorDtype d) {
          return msg::Tensor(std::span<const std::uint64_t>(shape), d);
        }),
        py::arg("shape"), py::arg("dtype") = msg::TensorDtype::F32);
  c.def_static("describe", [](const std::vector<std::uint64_t>& shape, msg::TensorDtype d) {
    return described(msg::Tensor::describe(std::span<const std::uint64_t>(shape), d), "Tensor.describe");
  }, py::arg("shape"), py::arg("dtype") = msg::TensorDtype::F32);
}

}  // namespace horus::python
