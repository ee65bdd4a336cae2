// The error path of the wire decoders (horus/wire/reader.hpp), compiled once: a path's text and
// the parts of an error message.
#include "horus/wire/reader.hpp"

#include <string>

namespace horus::wire {

std::string Path::text() const {
  std::string head = parent ? parent->text() : std::string();
  if (index != ~std::size_t{0}) return head + "[" + std::to_string(index) + "]";
  return parent ? head + "." + std::string(name) : std::string(name);
}

namespace detail {
void append_parts(std::string& out, std::initializer_list<Part> parts) {
  for (const Part& p : parts) {
    switch (p.kind) {
      case Part::Kind::Text: out.append(p.text); break;
      case Part::Kind::Negative: out += '-'; [[fallthrough]];
      case Part::Kind::Unsigned: out += std::to_string(p.magnitude); break;
    }
  }
}
}  // namespace detail

}  // namespace horus::wire
