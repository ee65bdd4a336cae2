// The Python classes and topics of the detection, perception and navigation messages.
#include "typed_impl.hpp"

namespace horus::python {

void bind_messages_second(py::module_& msg) {
  bind_all(msg, msg::detail::Concat<msg::DetectionMessages, msg::PerceptionMessages, msg::NavigationMessages>::type{});
}

}  // namespace horus::python
