// A Python object held by C++ code that may drop it on a thread without the GIL (a fleet's
// thread, an executor destroyed while another thread spins): it takes the GIL to let it go.
#pragma once

#include <pybind11/pybind11.h>

#include <utility>

namespace horus::python {

class GilObject {
 public:
  explicit GilObject(pybind11::object o) : o_(std::move(o)) {}
  GilObject(const GilObject&) = delete;
  GilObject& operator=(const GilObject&) = delete;
  ~GilObject() {
    pybind11::gil_scoped_acquire gil;
    o_ = pybind11::object();
  }
  const pybind11::object& get() const noexcept { return o_; }

 private:
  pybind11::object o_;
};

}  // namespace horus::python
