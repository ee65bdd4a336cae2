// The out-of-line part of horus/reflect.hpp: type_signature<T>()'s text sink.
#include "horus/reflect.hpp"

namespace horus::reflect::detail {

void StringSink::put(std::string_view p) { s.append(p); }

}  // namespace horus::reflect::detail
