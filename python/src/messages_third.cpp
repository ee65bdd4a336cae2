// The Python classes and topics of the diagnostics, force, input, tracking, time, audio and
// generic messages.
#include "typed_impl.hpp"

namespace horus::python {

void bind_messages_third(py::module_& msg) {
  bind_all(msg, msg::detail::Concat<msg::DiagnosticsMessages, msg::ForceMessages, msg::InputMessages,
                                    msg::TrackingMessages, msg::TimeMessages, msg::AudioMessages,
                                    msg::GenericMessages>::type{});
}

}  // namespace horus::python
