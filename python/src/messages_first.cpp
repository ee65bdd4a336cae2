// The Python classes and topics of the geometry, sensor, control and vision messages.
#include "typed_impl.hpp"

namespace horus::python {

void bind_messages_first(py::module_& msg) {
  bind_all(msg, msg::detail::Concat<msg::GeometryMessages, msg::SensorMessages, msg::ControlMessages,
                                    msg::VisionMessages>::type{});
}

}  // namespace horus::python
