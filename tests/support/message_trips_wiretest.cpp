// The wire test types' entries (their own file: they need the test types' header).
#include "message_trips_impl.hpp"
#include "wire_test_types.hpp"

namespace horus_test {

const std::vector<MessageType>& wire_test_types() {
  static const std::vector<MessageType> types =
      detail::entries(horus::msg::TypeList<wiretest::All, wiretest::Keywords, wiretest::Widths>{});
  return types;
}

}  // namespace horus_test
