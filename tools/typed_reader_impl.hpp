// The per-type half of typed_reader.hpp (horus bench's peers, which take each type's Topic<T>
// itself: the round trip they measure is the typed one), included by typed_reader_{first,second}.cpp.
#pragma once

#include "horus/msg/all.hpp"
#include "horus/standard_types.hpp"
#include "horus/topic.hpp"
#include "bench_peer_impl.hpp"
#include "typed_reader.hpp"

namespace horus::tools::detail {

// The bench peer of the standard message whose qualified name is `qualified`, in this half.
template <class... T>
void open_as(msg::TypeList<T...>, std::string_view qualified, Want want, Opened& out, std::string& error) {
  auto try_one = [&]<class M>() {
    if (out.known || horus::type_name<M>() != qualified) return;
    out.known = true;
    if (want == Want::BenchCheck) error = check_bench_size<M>(out.bench_payload->size);
    else out.bench = open_bench_as<M>(*out.bench_payload, *out.bench_endpoints, error);
  };
  (try_one.template operator()<T>(), ...);
}

}  // namespace horus::tools::detail
