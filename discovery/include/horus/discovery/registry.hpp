// The local registry: every topic on this host, read from the shared-memory segments
// themselves (there is no daemon and no separate registry file to go stale). Reading maps each
// segment read-only, so it never disturbs a topic.
//
//   for (const auto& t : horus::discovery::list_topics(ns)) fmt::print("{} {}\n", t.topic, t.type_name);
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <expected>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::discovery {

/// A process attached to a topic.
struct Process {
  pid_t pid = 0;
  bool alive = false;
  std::uint32_t publishers = 0;   // publishing handles (ring lanes) it holds
  std::uint32_t subscribers = 0;  // subscribing handles it holds
  bool bridge = false;            // it bridges the topic to the network (fleet topics)
};

struct TopicEntry {
  std::string topic;          // horus topic name
  std::string segment;        // /dev/shm file name
  std::string type_name;      // "horus::msg::Pose2D"
  std::uint64_t type_hash = 0;
  std::uint32_t message_size = 0;  // bytes (fixed-size) or the largest encoded message (serialized)
  bool serialized = false;
  // Large data (Image, PointCloud, DepthImage, Tensor): the pool holding the bytes.
  bool pooled = false;
  std::uint64_t pool_slot_bytes = 0;     // largest message's bytes
  std::uint32_t pool_slots_per_publisher = 0;
  std::uint32_t pool_pinned = 0;         // slots pinned now by received messages
  std::uint64_t pool_reused = 0;         // unread messages lost because their slot was reused
  std::uint64_t pool_exhausted = 0;      // sends refused: every slot of the publisher pinned
  std::uint32_t capacity = 0;      // slots per publisher
  std::uint64_t segment_bytes = 0;
  std::uint64_t created_unix_ns = 0;
  std::string signature;           // the type's layout text (reflect::type_signature): decodes it without the type
  std::uint32_t publishers = 0;    // handles, all processes
  std::uint32_t subscribers = 0;
  std::uint64_t messages_sent = 0;  // since the segment was created
  std::uint64_t dropped = 0;        // messages subscribers lost to overwrites
  double rate_hz = -1.0;            // messages per second over the sampling window (-1: not sampled)
  std::vector<Process> processes;
  bool stale = false;  // no live process: `horus clean` removes it
  // Scope: "host" (shared memory) or "fleet" (shared memory and, through one bridge per host,
  // `transport`). The bridge's own lane and entry are not in publishers/subscribers.
  std::string scope = "host";
  std::string transport;            // fleet: "cyclonedds", "fastdds", "lcm"
  pid_t bridge_pid = 0;             // fleet: the live process that bridges it (0: none now)
  std::uint64_t bridge_claims = 0;  // claims ever made (1 + takeovers)
  std::uint64_t exported = 0;       // messages of this host sent to the network
  std::uint64_t imported = 0;       // messages of other hosts written into the ring
  std::uint64_t bridge_dropped = 0; // lost on the way (takeovers, transport losses)
  std::uint64_t budget_dropped = 0; // kept from the network by the topic's egress budget
  std::uint64_t malformed = 0;      // samples from the network that did not decode (ignored)
  std::uint32_t remote_publishers = 0;   // remote writers the bridge matched
  std::uint32_t remote_subscribers = 0;  // remote readers the bridge matched
};

/// Every topic of shared-memory namespace `ns`. With a window > 0, sent counts are watched that
/// long (a look every 5 ms) to give rate_hz: the messages between the first and the last time a
/// count moved, over that time (a topic slower than the window: 0, or one message over the window).
std::vector<TopicEntry> list_topics(std::string_view ns, std::chrono::milliseconds window = std::chrono::milliseconds(0));

/// The same, for a caller that looks again and again (the fleet agent's announcements): keeps
/// each segment mapped between scans (a file replaced under the same name is mapped anew: its
/// inode differs) and asks the kernel whether a process lives once per scan, not once per
/// topic. A scan of 1000 topics costs about a millisecond instead of tens.
class Scanner {
 public:
  explicit Scanner(std::string ns);
  ~Scanner();
  Scanner(const Scanner&) = delete;
  Scanner& operator=(const Scanner&) = delete;
  /// Every topic now, sorted by name (rate_hz not sampled).
  std::vector<TopicEntry> scan();
  /// True when a topic appeared or went since the last call (the directory changed): cheap.
  bool topics_changed();

 private:
  struct Cache;
  std::string ns_;
  std::unique_ptr<Cache> cache_;
};

/// One topic; an error text when it does not exist (naming the namespace and the topics that do).
std::expected<TopicEntry, std::string> find_topic(std::string_view ns, std::string_view topic,
                                                  std::chrono::milliseconds window = std::chrono::milliseconds(0));

/// Removes the segments of `ns` whose processes are all gone; returns their topic names.
std::vector<std::string> clean(std::string_view ns);

}  // namespace horus::discovery

HORUS_API_END
