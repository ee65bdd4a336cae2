// The LCM transport: the byte-level backend of horus::net (horus/network.hpp) over Debian's
// liblcm 1.3.1 (C API). This header includes no LCM header.
//
// One transport per LCM URL and process (an lcm_t that publishes, one receive thread), shared
// by every topic that uses that URL and released when the last one closes. For udpm, receiving
// goes through a second lcm_t that exists while an endpoint receives (EndpointSpec::receive,
// set_receiving): a process whose endpoints only publish has no receive socket, so its own
// datagrams never reach it (LCM's loopback would bring every one back to the publisher). An endpoint publishes to and
// subscribes to one LCM channel: the sample body is the whole LCM payload (lcm-gen's encoding,
// with its 8-byte fingerprint first), big-endian, so samples arrive with little_endian = false.
//
// What LCM does not have, and what this backend does about it:
//  - No discovery: matched_publishers() and matched_subscribers() are always 0.
//  - No sender identity: a process receives its own messages (udpm loops multicast back, memq
//    is one in-process queue, the tcpq server relays to every subscribed client, the sender
//    included), so delivers_own_samples() is true, except for file:// URLs (a log being written
//    delivers nothing back; a log being read cannot be published to).
//  - No reliability and no loss count: udpm drops a message silently when the kernel drops one
//    of its datagrams (a full socket receive buffer, typical with multi-megabyte messages; raise
//    it with ?recv_buf_size=N, capped by net.core.rmem_max). The transport reads the `drops`
//    counter of its LCM receive socket in /proc/net/udp about every 100 ms and reports each
//    increase to Listener::on_lost() of every open endpoint that receives (not one paused by
//    set_receiving(false)): the count is
//    datagrams the kernel dropped on this process's LCM socket (a fragmented message is many
//    datagrams; datagrams of channels nobody here subscribes to count too), not messages of the
//    endpoint's channel. Nothing is reported when /proc is unreadable, nor for memq, file, tcpq.
//  - LCM's per-subscription queue (30 messages by default, overflow dropped silently) is made
//    unlimited: the topic's ring is the bounded queue and counts what it overwrites.
//  - File replay (file://...?mode=r) starts when the transport is created; events replayed
//    before an endpoint of their channel is open are not delivered (LCM drops them).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::lcm {

/// liblcm's own default (used when neither HORUS_LCM_URL nor LCM_DEFAULT_URL is set): multicast
/// on this host only (ttl=0 keeps the packets on the machine).
inline constexpr std::string_view kDefaultUrl = "udpm://239.255.76.67:7667?ttl=0";

/// LCM_MAX_CHANNEL_NAME_LENGTH: a longer channel is never sent (publish fails) nor received.
inline constexpr std::size_t kMaxChannelLength = 63;

/// LCM_MAX_MESSAGE_SIZE (256 MiB): a udpm receiver discards larger payloads.
inline constexpr std::size_t kMaxMessageSize = std::size_t{1} << 28;

/// Checks an LCM URL without touching the network (lcm_create only prints its complaints on
/// stderr). Accepted (Errc::Config otherwise, the message quotes the URL, names the problem and
/// says what was expected):
///   udpm://A.B.C.D:PORT[?opts]  A.B.C.D a multicast address (224.0.0.0/4), PORT 1..65535;
///                               opts '&'-separated: ttl=0..255, recv_buf_size=N (N > 0),
///                               transmit_only=true|false
///   memq://                     in-process queue (no host part, no options)
///   file://PATH[?opts]          an LCM log; opts: mode=r|w|a, speed=S (a number),
///                               start_timestamp=T (an integer, microseconds)
///   tcpq://[HOST[:PORT]]        an LCM TCP queue server (default 127.0.0.1:7700), no options
Result<void> check_url(std::string_view url);

/// The URL of `config` (HORUS_LCM_URL, else LCM_DEFAULT_URL, else the file's network.lcm_url:
/// net::config_from), or kDefaultUrl when it names none. Checked with check_url; the error
/// names where the URL came from.
Result<std::string> url_from(const net::Config& config);

/// The URL of the fleet layer's own channels (`horus.fleet.*`: announcements, heartbeats, the
/// hosts' tables) for data URL `url`: a udpm URL's port + 1 (65535: 65534), same group and
/// options; any other URL unchanged. On a port of their own, a process whose data endpoints
/// only publish has no socket that receives the data channels (its own looped back datagrams
/// woke it for each message while the fleet layer kept one socket open for both).
std::string control_url(std::string_view url);

/// `channel` as an LCM channel name, or Errc::InvalidName when it is empty, longer than
/// kMaxChannelLength bytes or contains a NUL byte.
Result<std::string> check_channel(std::string_view channel);

/// The LCM transport of `url` in this process: created on first use (check_url, then
/// lcm_create; Errc::Io when liblcm cannot start it, e.g. no multicast route), then shared:
/// a second call with the same URL string returns the same live instance.
/// Endpoints use EndpointSpec::wire_topic as the LCM channel (matched exactly, not as a regex);
/// write() refuses bodies over kMaxMessageSize with Errc::MessageTooLarge.
Result<std::shared_ptr<net::Transport>> lcm_transport(std::string_view url);

/// The LCM channel of a horus topic: the topic name itself ("fleet.robot_1.pose"), so a name
/// over kMaxChannelLength bytes is an error (InvalidName), as is one that breaks horus's rules.
Result<std::string> channel_name(std::string_view topic);

/// Adds the transport to the registry ("lcm", the LCM format, channel_name, and a factory that
/// reads HORUS_LCM_URL / LCM_DEFAULT_URL).
void register_lcm();

}  // namespace horus::lcm

HORUS_API_END
