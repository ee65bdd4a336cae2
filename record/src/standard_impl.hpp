// The per-type half of horus/record/standard.hpp, included by standard_{first,second}.cpp.
#pragma once

#include <string_view>

#include "horus/msg/all.hpp"
#include "horus/record/standard.hpp"
#include "horus/topic.hpp"

namespace horus::record_detail {

/// True when `asked` names the type `qualified`: in full, or its last part ("Pose2D").
inline bool names_type(std::string_view qualified, std::string_view asked) {
  return qualified == asked || (qualified.size() > asked.size() + 2 && qualified.ends_with(asked) &&
                                qualified.substr(qualified.size() - asked.size() - 2, 2) == "::");
}

template <class... T>
void open_standard(msg::TypeList<T...>, std::string_view type_name, std::string_view name,
                   const TopicOptions& options, StandardOpen& out) {
  auto one = [&]<class M>() {
    if (out.known || !names_type(horus::type_name<M>(), type_name)) return;
    out.known = true;
    out.hash = horus::type_hash<M>;
    auto topic = Topic<M>::open(name, options);
    if (!topic) out.error = std::move(topic.error());
    else if (out.want_sink) out.sink = std::make_unique<TopicSink<M>>(std::move(*topic), out.lcm_encoding);
    else out.source = std::make_unique<TopicSource<M>>(std::move(*topic));
  };
  (one.template operator()<T>(), ...);
}

}  // namespace horus::record_detail
