#include "horus/transport/remote_types.hpp"

#include <algorithm>
#include <utility>

namespace horus::net {

std::string RemoteTypes::conflict_locked(std::string_view wire_topic, std::string_view type_name) const {
  auto [first, last] = locals_.equal_range(wire_topic);
  for (auto it = first; it != last; ++it)
    if (it->second.second.type_name != type_name) return it->second.second.type_name;
  return {};
}

std::string type_hash_of(std::string_view user_data) {
  constexpr std::string_view kKey = "typehash=";
  const auto at = user_data.find(kKey);
  if (at == std::string_view::npos || (at != 0 && user_data[at - 1] != ';')) return {};
  const auto value = user_data.substr(at + kKey.size());
  return std::string(value.substr(0, value.find(';')));
}

void RemoteTypes::report_locked(Local& local, const Id& id, const Remote& remote, Pending& out) {
  const bool other_type = remote.type_name != local.type_name;
  const bool other_hash = !other_type && !local.type_hash.empty() && !remote.type_hash.empty() &&
                          remote.type_hash != local.type_hash;
  if ((!other_type && !other_hash) || !local.reported.insert(id).second) return;
  const std::string who = local.label + ": a remote " + (remote.publisher ? "publisher" : "subscriber");
  if (other_type)
    out.emplace_back(local.report, who + " carries type '" + remote.type_name + "', this process expects '" +
                                       local.type_name + "'; they will not communicate");
  else
    out.emplace_back(local.report, who + " of type '" + remote.type_name + "' announces type hash " + remote.type_hash +
                                       ", this process's is " + local.type_hash +
                                       " (another version of the message); its samples may not decode");
}

void RemoteTypes::deliver(Pending& pending) noexcept {
  for (auto& [report, message] : pending) {
    try {
      report(message);
    } catch (...) {
    }
  }
}

std::string RemoteTypes::add_local(const void* key, std::string_view wire_topic, std::string_view type_name,
                                   std::string label, Report report, std::string_view user_data) {
  Pending pending;
  {
    std::lock_guard lock(mutex_);
    if (std::string other = conflict_locked(wire_topic, type_name); !other.empty()) return other;
    auto it = locals_.emplace(std::string(wire_topic),
                              std::pair<const void*, Local>(
                                  key, Local{std::string(wire_topic), std::string(type_name), std::move(label),
                                             std::move(report), {}, type_hash_of(user_data)}));
    for (const auto& [id, remote] : remotes_)
      if (remote.wire_topic == wire_topic) report_locked(it->second.second, id, remote, pending);
  }
  deliver(pending);
  return {};
}

void RemoteTypes::remove_local(const void* key) {
  Report dropped;  // released after the lock: it may own the endpoint's last reference
  std::lock_guard lock(mutex_);
  for (auto it = locals_.begin(); it != locals_.end(); ++it) {
    if (it->second.first == key) {
      dropped = std::move(it->second.second.report);
      locals_.erase(it);
      return;
    }
  }
}

std::string RemoteTypes::local_conflict(std::string_view wire_topic, std::string_view type_name) const {
  std::lock_guard lock(mutex_);
  return conflict_locked(wire_topic, type_name);
}

void RemoteTypes::remote_seen(const Id& id, std::string_view wire_topic, std::string_view type_name, bool publisher,
                              std::string_view user_data, const Id* guid) {
  Pending pending;
  {
    std::lock_guard lock(mutex_);
    auto& remote = remotes_[id];
    remote = Remote{std::string(wire_topic), std::string(type_name), publisher, type_hash_of(user_data),
                    guid != nullptr ? *guid : id};
    auto [first, last] = locals_.equal_range(wire_topic);
    for (auto it = first; it != last; ++it) report_locked(it->second.second, id, remote, pending);
  }
  deliver(pending);
}

std::vector<Transport::Remote> RemoteTypes::remotes() const {
  std::lock_guard lock(mutex_);
  std::vector<Transport::Remote> out;
  out.reserve(remotes_.size());
  for (const auto& [id, r] : remotes_) out.push_back({r.guid, r.wire_topic, r.type_name, r.publisher, r.type_hash});
  return out;
}

void RemoteTypes::remote_gone(const Id& id) {
  std::lock_guard lock(mutex_);
  remotes_.erase(id);
  for (auto& [topic, local] : locals_) local.second.reported.erase(id);
}

void RemoteTypes::remotes_gone(std::span<const std::uint8_t> prefix) {
  std::lock_guard lock(mutex_);
  const auto matches = [&](const Id& id) {
    return prefix.size() <= id.size() && std::equal(prefix.begin(), prefix.end(), id.begin());
  };
  std::erase_if(remotes_, [&](const auto& entry) { return matches(entry.first); });
  for (auto& [topic, local] : locals_) std::erase_if(local.second.reported, matches);
}

}  // namespace horus::net
