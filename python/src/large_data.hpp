// Image, DepthImage, PointCloud and Tensor as NumPy arrays without a copy: the array views the
// message's bytes (a received message's pool slot, read-only; a loan's slot, writable) and
// keeps the message, hence the slot, alive. Shapes: Image (height, width[, channels]) of its
// encoding's element type, rows `step` bytes apart; DepthImage (height, width) float32 (m) or
// uint16 (mm); PointCloud (points, fields); Tensor its shape and byte strides. A message whose
// metadata does not describe its bytes gives its bytes flat, as uint8.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

#include "horus/msg/image.hpp"
#include "horus/msg/perception.hpp"
#include "horus/msg/point_cloud.hpp"
#include "horus/msg/tensor.hpp"

namespace horus::python {

namespace py = pybind11;

/// The NumPy type of a TensorDtype (BF16 as uint16: NumPy has no bfloat16).
py::dtype numpy_dtype(msg::TensorDtype d);

struct ArrayShape {
  py::dtype dtype = py::dtype::of<std::uint8_t>();
  std::vector<py::ssize_t> shape;
  std::vector<py::ssize_t> strides;
};

ArrayShape array_shape(const msg::Image& m);
ArrayShape array_shape(const msg::DepthImage& m);
ArrayShape array_shape(const msg::PointCloud& m);
ArrayShape array_shape(const msg::Tensor& m);

/// The array over `bytes` with shape `s`, kept valid by `base`; read-only unless `writable`.
py::array array_over(const ArrayShape& s, const std::uint8_t* bytes, std::size_t size, py::handle base, bool writable);

/// message.data: the view of a large-data message's bytes. Read-only when they are a
/// received pool slot (or a loan's: a loan is filled through Loan.data); writable when owned.
template <class T>
py::array data_view(py::object self) {
  T& m = self.cast<T&>();
  const bool writable = !m.buffer().borrowed();
  const std::uint8_t* p = writable ? m.data_mut().data() : m.data().data();
  return array_over(m.is_consistent() ? array_shape(m) : ArrayShape{}, p, m.data().size(), self, writable);
}

/// Topic.loan(*args): the descriptor Type.describe(*args) gives, made without a Python call.
msg::ImageDescriptor describe_from(const msg::Image*, const py::args& a);
msg::DepthImageDescriptor describe_from(const msg::DepthImage*, const py::args& a);
msg::PointCloudDescriptor describe_from(const msg::PointCloud*, const py::args& a);
msg::TensorDescriptor describe_from(const msg::Tensor*, const py::args& a);

/// The constructors and methods of the four classes beyond their reflected fields.
void bind_large_extras(py::class_<msg::Image>& c);
void bind_large_extras(py::class_<msg::DepthImage>& c);
void bind_large_extras(py::class_<msg::PointCloud>& c);
void bind_large_extras(py::class_<msg::Tensor>& c);

}  // namespace horus::python
