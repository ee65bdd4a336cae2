// Remote-type watching for the DDS transports: a remote endpoint on one of our topics that
// carries another type name never communicates with ours, and DDS says nothing about it
// (Cyclone DDS 0.10 raises no INCONSISTENT_TOPIC; Fast DDS 2.9 only matches by name). The
// transport feeds what its discovery sees (remote_seen / remote_gone) and the endpoints this
// process has open (add_local / remove_local); each local endpoint hears once, through its
// report function, of each remote endpoint of another type on its topic:
//   "<label>: a remote publisher carries type 'B', this process expects 'A'; they will not
//   communicate"
// Report functions run on the caller's thread after the watcher's lock is released (they may
// call a listener). Thread-safe.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "horus/export.hpp"
#include "horus/network.hpp"

HORUS_API_BEGIN

namespace horus::net {

/// The type hash of a USER_DATA as ROS 2 writes it ("...;typehash=RIHS01_<hex>;..."), or empty.
std::string type_hash_of(std::string_view user_data);

class RemoteTypes {
 public:
  /// A remote endpoint as the transport names it (a GUID, or a built-in topic instance handle
  /// in its first 8 bytes).
  using Id = std::array<std::uint8_t, 16>;
  using Report = std::function<void(const std::string& message)>;

  /// Adds a local endpoint (`key` identifies it for remove_local) on `wire_topic` with
  /// `type_name`, and reports the remote endpoints already known to carry another type. When
  /// another local endpoint holds the topic with another type, nothing is added and that type
  /// is returned; otherwise an empty string.
  /// `user_data`: the endpoint's USER_DATA; when it has a "typehash=...;" (a topic mapped onto
  /// ROS 2), a remote endpoint of the same type whose USER_DATA has another hash is reported:
  ///   "<label>: a remote publisher of type 'T' announces type hash B, this process's is A ..."
  std::string add_local(const void* key, std::string_view wire_topic, std::string_view type_name, std::string label,
                        Report report, std::string_view user_data = {});
  void remove_local(const void* key);
  /// The type of another local endpoint on `wire_topic` if it is not `type_name`, else "".
  std::string local_conflict(std::string_view wire_topic, std::string_view type_name) const;

  /// A remote endpoint discovered (again): reported to each local endpoint of its topic with
  /// another type (or the same type with another type hash in `user_data`) that has not heard
  /// of it yet.
  /// `guid`: the endpoint's GUID where `id` is not it (Cyclone DDS's instance handles).
  void remote_seen(const Id& id, std::string_view wire_topic, std::string_view type_name, bool publisher,
                   std::string_view user_data = {}, const Id* guid = nullptr);
  /// A remote endpoint went away.
  void remote_gone(const Id& id);
  /// Every remote endpoint whose id starts with `prefix` went away (a remote participant).
  void remotes_gone(std::span<const std::uint8_t> prefix);

  /// Every remote endpoint known now, on any topic (Transport::remote_endpoints).
  std::vector<Transport::Remote> remotes() const;

 private:
  struct Local {
    std::string wire_topic, type_name, label;
    Report report;
    std::set<Id> reported;  // remote endpoints it heard of
    std::string type_hash;  // from its USER_DATA's "typehash=...;", or empty
  };
  struct Remote {
    std::string wire_topic, type_name;
    bool publisher = false;
    std::string type_hash;
    Id guid{};
  };
  using Pending = std::vector<std::pair<Report, std::string>>;

  std::string conflict_locked(std::string_view wire_topic, std::string_view type_name) const;
  static void report_locked(Local& local, const Id& id, const Remote& remote, Pending& out);
  static void deliver(Pending& pending) noexcept;

  mutable std::mutex mutex_;
  std::multimap<std::string, std::pair<const void*, Local>, std::less<>> locals_;  // by wire topic
  std::map<Id, Remote> remotes_;
};

}  // namespace horus::net

HORUS_API_END
