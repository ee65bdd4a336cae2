// horus-idlgen: the interface files of the standard messages (see horus/idlgen/cli.hpp).
// Each domain of the catalogue (horus/msg/all.hpp) becomes one file: geometry.idl, sensor.idl, ...
#include "horus/idlgen/cli.hpp"
#include "horus/msg/all.hpp"

int main(int argc, char** argv) {
  horus::idlgen::Model model;
  horus::msg::for_each_message([&]<class T>(std::string_view domain) { model.add<T>(domain); });
  return horus::idlgen::run_cli(model, argc, argv);
}
