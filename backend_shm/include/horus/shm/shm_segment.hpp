// A topic's ring in a POSIX shared-memory segment, shared by every process that opens the
// topic on this host: no broker, no daemon.
//
//   /dev/shm/horus.<namespace>.<topic>
//
//   offset 0       SegmentHeader   magic, layout version, the message type (name, hash, size,
//                                  serialized or not), capacity, and the participant table
//                                  (pid + process start time of every process attached)
//   signature_offset  the type's signature text (reflect::type_signature<T>(): what its hash
//                  is computed from), so a tool or another host can decode a type it lacks
//   ring_offset    the ring (ring.hpp), exactly as in process-local memory
//   pool_offset    large-data topics only: the pool holding the messages' bytes (pool.hpp)
//
// Membership changes (create, attach, detach, reclaim) happen under flock() on the segment's
// file descriptor. The kernel drops that lock when its holder dies, so a process killed while
// creating a segment never blocks the others: the next opener finds the header unfinished
// and formats it again. Participants whose process is gone (no such pid, or a pid reused by a
// process that started later) are reaped at every open and close, along with the ring lanes
// and subscriber entries they held (ring tokens carry the owner's pid in their high 32 bits),
// so a killed subscriber never holds a publisher back. When the last participant detaches,
// the segment is unlinked; a segment whose participants are all dead is reclaimed (formatted
// afresh) by the next open.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "horus/shm/pool.hpp"
#include "horus/shm/ring.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::shm {

inline constexpr std::uint64_t kSegmentMagic = 0x3147'4553'5355'524FULL;  // "ORUSSEG1"
inline constexpr std::uint32_t kSegmentVersion = 6;  // 2: the large-data pool; 3: the bridge claim;
                                                     // 4: the topic's scope and the bridge's state;
                                                     // 5: the type's signature, the bridge's malformed count;
                                                     // 6: the participants' high-water mark
inline constexpr std::size_t kMaxTypeName = 255;
inline constexpr std::size_t kMaxTransportName = 15;
inline constexpr std::size_t kMaxSignature = 256 * 1024;  // a type's signature text, at most

/// How far a shared-memory topic's messages go: this host only, or this host and the fleet
/// (through the host's bridge to a network transport). A host has one scope per topic.
enum class SegmentScope : std::uint32_t { Host = 1, Fleet = 2 };

struct alignas(kCacheLine) Participant {
  std::atomic<std::uint32_t> pid;         // 0: free
  std::atomic<std::uint64_t> start_time;  // the process's start time (clock ticks after boot)
};

/// The per-host bridge of a fleet topic (fleet/src/bridge.cpp): which process holds it,
/// the subscriber entry it exports from and the ring lane it imports into, and what it counted.
/// Everything but `owner` is written by the holder only. The entry and the lane are recorded
/// so that a successor adopts them at a takeover (it exports exactly what its predecessor had
/// not, and imports keep their lane): the reaper never frees them; the next holder does.
struct alignas(kCacheLine) BridgeState {
  // (holder pid << 32) | (its participant index + 1); 0: nobody. Compare-exchange only.
  std::atomic<std::uint64_t> owner;
  std::atomic<std::uint64_t> claims;        // claims ever made, takeovers included
  std::atomic<std::uint64_t> export_token;  // token of the entry it exports from (0: none)
  std::atomic<std::uint64_t> import_token;  // token of the lane it imports into (0: none)
  std::atomic<std::uint32_t> export_entry;
  std::atomic<std::uint32_t> import_lane;
  std::atomic<std::uint64_t> exported;  // messages of this host sent to the network
  std::atomic<std::uint64_t> imported;  // messages of other hosts written into the ring
  std::atomic<std::uint64_t> dropped;   // lost on the way: not exported (a takeover, a bridge that
                                        // lagged a full ring behind) or reported lost by the transport
  std::atomic<std::uint64_t> inflight;  // 1 while the holder exports a message it has read
  std::atomic<std::uint32_t> matched_publishers;   // remote writers its endpoint matched
  std::atomic<std::uint32_t> matched_subscribers;  // remote readers its endpoint matched
  std::atomic<std::uint64_t> claimed_unix_ns;      // when the holder claimed it
  std::atomic<std::uint64_t> malformed;  // samples from the network that did not decode (ignored)
  // Messages the egress budget (TopicOptions::max_rate_hz / max_bandwidth) kept from the
  // network. (It fills bytes that were padding, zero in older segments: the layout is unchanged.)
  std::atomic<std::uint64_t> budget_dropped;
  // A process that publishes on the topic asks the holder, which does not, for the bridge (its
  // claim word, as `owner`; 0: nobody asks): the bridge follows the host's publisher, so that
  // its sends export inline (fleet/src/bridge.cpp, the hand-over). Padding in older segments.
  std::atomic<std::uint64_t> handover;
};
static_assert(sizeof(BridgeState) == 2 * kCacheLine, "BridgeState keeps its size (the segment layout)");

struct alignas(kCacheLine) SegmentHeader {
  std::uint64_t magic;
  std::uint32_t layout_version;
  std::atomic<std::uint32_t> ready;  // 1 once formatted (written last, under the lock)
  char type_name[kMaxTypeName + 1];
  std::uint64_t type_hash;
  std::uint32_t payload_size;  // the ring's payload: sizeof(T), or 8 + largest encoded message
  std::uint32_t serialized;    // 1: slots hold [length][encoded bytes]
  std::uint32_t capacity;
  std::uint32_t creator_pid;
  std::uint64_t ring_offset;
  std::uint64_t total_size;
  std::uint64_t created_unix_ns;
  std::uint64_t pool_offset;       // 0: no pool; else the large-data pool (pool.hpp)
  std::uint64_t pool_slot_bytes;   // largest message's bytes in the pool
  std::uint32_t pool_slots_per_lane;
  std::uint32_t scope;                           // SegmentScope
  char transport[kMaxTransportName + 1];         // a fleet topic's network transport ("cyclonedds")
  std::uint64_t signature_offset;                // sizeof(SegmentHeader): the signature follows the header
  std::uint64_t signature_size;                  // its bytes (0: none given), at most kMaxSignature
  // Participants [0, participant_hwm) may be in use (raised under the file lock by a joining
  // process, never lowered): a reader of the table (discovery's scans) looks at those only.
  std::atomic<std::uint32_t> participant_hwm;
  BridgeState bridge;
  Participant participants[kMaxParticipants];
};
static_assert(std::is_standard_layout_v<SegmentHeader>, "the segment header has a fixed layout");

/// What a segment must carry.
struct SegmentSpec {
  std::string_view type_name;
  std::uint64_t type_hash = 0;
  std::uint32_t payload_size = 0;
  bool serialized = false;
  std::uint32_t capacity = 0;          // slots per lane used when creating the segment
  bool capacity_required = false;      // true: an existing segment with another capacity is an error
  bool payload_required = true;        // false (serialized, no slot size given): accept the existing one
  mode_t mode = 0600;                  // permissions of a created segment
  std::uint64_t pool_slot_bytes = 0;   // large data: bytes per pool slot (0: no pool)
  std::uint32_t pool_slots_per_lane = 0;
  bool pool_required = true;           // false: accept an existing pool's slot size
  SegmentScope scope = SegmentScope::Host;
  std::string_view transport;          // fleet: the network transport's name (at most 15 characters)
  std::string_view signature;          // the type's signature (reflect::type_signature<T>()), or empty
};

struct SegmentError {
  enum class Kind { TypeMismatch, ConfigMismatch, Permission, LimitReached, Io, InvalidName };
  Kind kind;
  std::string message;
};

/// The shared-memory namespace: HORUS_NAMESPACE, else "u<uid>" (one per user, so two users
/// on one host never share or collide). Letters, digits, '_' and '-', 1 to 64 characters.
std::expected<std::string, SegmentError> shm_namespace();
/// The namespace that `value` (of HORUS_NAMESPACE) names; empty: "u<uid>".
std::expected<std::string, SegmentError> shm_namespace(std::string_view value);
/// The mode of segments this process creates: HORUS_SHM_MODE (octal, e.g. 0660 to share a
/// namespace with the group; owner read and write are always kept), else 0600. An error names a
/// malformed value and what is expected.
std::expected<mode_t, SegmentError> shm_mode_from_environment();
/// The mode that `value` (of HORUS_SHM_MODE) names; empty: 0600.
std::expected<mode_t, SegmentError> shm_mode(std::string_view value);
/// Why the shared-memory file open as `fd` (named `name`, "/horus....") must not be used, or
/// nothing when it may: it belongs to another user than this process's effective user (unless
/// `mode`, HORUS_SHM_MODE, shares segments with a group, the file belongs to a group of this
/// process and gives nothing beyond `mode`), or it gives group or others write beyond `mode`.
/// Another local user could have made it to read or forge a topic's messages, or to shrink it
/// under the processes that map it (SIGBUS).
std::optional<std::string> foreign_file(int fd, mode_t mode, const std::string& name);
/// "/horus.<namespace>.<topic>": the name given to shm_open (the file is /dev/shm/horus....).
std::string segment_name(std::string_view ns, std::string_view topic);

/// Start time of a process (field 22 of /proc/<pid>/stat), or 0 when it does not exist.
std::uint64_t process_start_time(pid_t pid) noexcept;
/// True when `pid` runs and, if start_time != 0, started at start_time (not a reused pid).
bool process_alive(pid_t pid, std::uint64_t start_time) noexcept;
/// The pid a ring token belongs to (tokens are (pid << 32) | per-process counter).
constexpr pid_t token_pid(std::uint64_t token) noexcept { return static_cast<pid_t>(token >> 32); }

/// One process's attachment to a topic's segment. Move-only; detaching is the destructor.
class ShmSegment {
 public:
  /// Opens the segment of `topic` in namespace `ns`, creating it if needed, and attaches.
  static std::expected<ShmSegment, SegmentError> open(std::string_view ns, std::string_view topic,
                                                      const SegmentSpec& spec);

  ShmSegment() = default;
  ShmSegment(ShmSegment&& o) noexcept;
  ShmSegment& operator=(ShmSegment&& o) noexcept;
  ShmSegment(const ShmSegment&) = delete;
  ShmSegment& operator=(const ShmSegment&) = delete;
  ~ShmSegment();

  Ring ring() const noexcept { return ring_; }
  /// The large-data pool (false when the topic has none).
  Pool pool() const noexcept { return pool_; }
  /// Our index in the participant table (what pins the pool's slots).
  std::uint32_t participant() const noexcept { return slot_; }
  const SegmentHeader& header() const noexcept { return *header_; }
  /// The type's signature text as the segment's creator wrote it (empty when it gave none).
  std::string_view signature() const noexcept;
  const std::string& name() const noexcept { return name_; }
  /// Processes attached now (after reaping dead ones).
  std::uint32_t live_participants() const;
  /// Releases ring lanes and subscriber entries held by processes that are gone, and their
  /// participant entries (under the segment lock). Returns how many processes were reaped.
  std::uint32_t reap_dead() const;

  /// The bridge of a fleet topic: at most one process of the host holds it, through the
  /// segment; no daemon. Claimed when nobody holds it or its holder's process is gone (that
  /// is a takeover); a holder that detaches releases it. Lock-free: a compare-exchange.
  enum class BridgeClaim { Claimed, TookOver, Held, Ours };
  BridgeClaim claim_bridge() noexcept;
  /// Gives the bridge up if this attachment holds it.
  void release_bridge() noexcept;
  /// The live process that holds the bridge, or 0.
  pid_t bridge_holder() const noexcept;
  /// This attachment's claim word (what `owner` holds while it holds the bridge).
  std::uint64_t bridge_word() const noexcept;
  /// Whether the live process and attachment that claim word `word` names is attached still.
  bool bridge_word_alive(std::uint64_t word) const noexcept;
  /// Hands the bridge this attachment holds to the attachment whose claim word is `to` (the
  /// hand-over: no other process can claim it in between); watchers see it as a release.
  /// False when this attachment does not hold it.
  bool transfer_bridge(std::uint64_t to) noexcept;
  /// The holder records the subscriber entry it exports from and the lane it imports into
  /// (token 0: none); the reaper leaves them for a successor.
  void record_bridge_export(std::uint32_t entry, std::uint64_t token) noexcept;
  void record_bridge_import(std::uint32_t lane, std::uint64_t token) noexcept;
  /// A new holder (after TookOver, or Claimed after a holder that left) takes the entry and
  /// the lane its predecessor recorded: `adopt(entry, old_token)` / `adopt(lane, old_token)`
  /// return whether they were adopted; what was not adopted is freed. Under the segment lock,
  /// so the reaper cannot free them meanwhile. Returns false when the lock was not obtained.
  struct Inheritance {
    std::optional<std::uint32_t> export_entry;  // recorded entry, with its token
    std::uint64_t export_token = 0;
    std::optional<std::uint32_t> import_lane;
    std::uint64_t import_token = 0;
    std::uint64_t inflight = 0;  // the predecessor died exporting a message
  };
  template <class Adopt>
  bool inherit_bridge(Adopt&& adopt) {
    Inheritance in;
    if (!lock_inheritance(in)) return false;
    adopt(in);
    unlock_inheritance(in);
    return true;
  }
  BridgeState& bridge() const noexcept { return header_->bridge; }

 private:
  // open()'s steps (shm_segment.cpp); the *_locked ones run with the file's lock held.
  struct Layout;
  /// The spec checked (names, ring and pool configurations, signature) and where each part goes.
  static std::expected<Layout, SegmentError> layout_of(std::string_view topic, const SegmentSpec& spec);
  /// Maps an existing file of `size` bytes and checks it against the spec: true when it must be
  /// formatted (new, unfinished, damaged and abandoned, every user gone), false when attached.
  std::expected<bool, SegmentError> attach_locked(std::string_view topic, const SegmentSpec& spec, bool pooled,
                                                  std::size_t size);
  /// Sizes and formats the file as a new segment.
  std::expected<void, SegmentError> format_locked(const SegmentSpec& spec, const Layout& layout, pid_t self);
  /// Takes a free entry of the participant table.
  std::expected<void, SegmentError> join_locked(std::string_view topic, pid_t self, std::uint64_t start);
  std::uint32_t reap_dead_locked() const;  // the caller holds the lock
  bool lock_inheritance(Inheritance& in) noexcept;
  void unlock_inheritance(const Inheritance& in) noexcept;
  void detach() noexcept;
  int fd_ = -1;
  void* base_ = nullptr;
  std::size_t size_ = 0;
  SegmentHeader* header_ = nullptr;
  Ring ring_;
  Pool pool_;
  std::string name_;
  std::uint32_t slot_ = kMaxParticipants;  // our participant entry
  pid_t owner_ = 0;  // the process that attached (a forked child only unmaps its copy)
};

/// A read-only view of a segment, for tools: maps it PROT_READ, never joins it or writes to
/// it, so looking never disturbs a topic. Only the Ring's reading methods may be used.
class SegmentView {
 public:
  /// Maps "/horus.<ns>.<topic>"-style shm name `name` (with the leading '/').
  static std::expected<SegmentView, SegmentError> open(const std::string& name);
  SegmentView() = default;
  SegmentView(SegmentView&& o) noexcept { *this = std::move(o); }
  SegmentView& operator=(SegmentView&& o) noexcept;
  SegmentView(const SegmentView&) = delete;
  SegmentView& operator=(const SegmentView&) = delete;
  ~SegmentView();

  const SegmentHeader& header() const noexcept { return *header_; }
  /// The type's signature text (empty when its creator gave none).
  std::string_view signature() const noexcept;
  Ring ring() const noexcept { return ring_; }
  /// The large-data pool, read-only (false when the topic has none).
  Pool pool() const noexcept { return pool_; }
  std::size_t size() const noexcept { return size_; }

 private:
  void* base_ = nullptr;
  std::size_t size_ = 0;
  const SegmentHeader* header_ = nullptr;
  Ring ring_;
  Pool pool_;
};

/// A segment found in /dev/shm, for tools (`horus topic list`, `horus clean`).
struct SegmentInfo {
  std::string name;   // shm name without the leading '/'
  std::string topic;
  std::uint64_t size = 0;
  bool readable = false;  // header read and valid
  std::string type_name;
  std::vector<std::pair<pid_t, bool>> participants;  // pid, alive
};
/// Every segment of namespace `ns`.
std::vector<SegmentInfo> list_segments(std::string_view ns);
/// Removes segments of `ns` whose participants are all dead (or whose header is unfinished
/// and unlocked); returns the names removed.
std::vector<std::string> clean_stale_segments(std::string_view ns);

}  // namespace horus::shm

HORUS_API_END
