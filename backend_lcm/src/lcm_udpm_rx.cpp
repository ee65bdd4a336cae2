// horus's own receiver of LCM's UDP multicast protocol (lcm_internal.hpp, UdpmReceiver).
//
// The protocol (LCM's documentation, "UDP Multicast Protocol"): every datagram starts with a
// big-endian magic and sequence number.
//   LC02 (a message that fits one datagram): magic, seqno, the channel NUL-terminated, the data.
//   LC03 (a fragment): magic, seqno, the message's size, this fragment's offset in it, its
//        number and the number of fragments (16 bits each); fragment 0 carries the channel
//        NUL-terminated before its data.
// A sender has at most one message in reassembly: a fragment of another sequence number from
// the same sender abandons it (counted as lost).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>

#include "lcm_internal.hpp"

namespace horus::lcm::detail {

namespace {

constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr std::uint32_t kMagicLong = 0x4c433033;   // "LC03"
constexpr std::size_t kShortHeader = 8;
constexpr std::size_t kLongHeader = 20;
constexpr std::size_t kDatagramMax = 65536;
// Messages in reassembly at once (one per sender), and their bytes: beyond either, the oldest
// is abandoned and counted as lost.
constexpr std::size_t kMaxPartials = 64;
constexpr std::uint64_t kMaxPartialBytes = std::uint64_t{1} << 30;

std::uint32_t be32(const std::byte* p) noexcept {
  return (std::to_integer<std::uint32_t>(p[0]) << 24) | (std::to_integer<std::uint32_t>(p[1]) << 16) |
         (std::to_integer<std::uint32_t>(p[2]) << 8) | std::to_integer<std::uint32_t>(p[3]);
}
std::uint16_t be16(const std::byte* p) noexcept {
  return static_cast<std::uint16_t>((std::to_integer<unsigned>(p[0]) << 8) | std::to_integer<unsigned>(p[1]));
}

// The channel at the start of `bytes`: NUL-terminated within kMaxChannelLength + 1 bytes.
std::optional<std::string_view> read_channel(std::span<const std::byte> bytes) noexcept {
  const std::size_t limit = std::min(bytes.size(), kMaxChannelLength + 1);
  for (std::size_t i = 0; i < limit; ++i)
    if (bytes[i] == std::byte{0}) {
      if (i == 0) return std::nullopt;
      return std::string_view(reinterpret_cast<const char*>(bytes.data()), i);
    }
  return std::nullopt;
}

std::string os_error(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

}  // namespace

Result<std::unique_ptr<UdpmReceiver>> UdpmReceiver::open(const std::string& url, const UrlInfo& info) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return fail(Errc::Io, "LCM URL '" + url + "': " + os_error("socket()"));
  std::unique_ptr<UdpmReceiver> rx(new UdpmReceiver(fd));
  const int one = 1, zero = 0;
  auto fail_with = [&](const char* what) -> Result<std::unique_ptr<UdpmReceiver>> {
    return fail(Errc::Io, "LCM could not start the receive side for URL '" + url + "': " + os_error(what) +
                              provider_hint(url, info));
  };
  // Other LCM programs on the host (liblcm's sockets, other horus processes) bind the same port.
  if (::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0) return fail_with("setsockopt(SO_REUSEADDR)");
  if (info.recv_buf_size != 0) {
    const int size = static_cast<int>(info.recv_buf_size);
    if (::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size) != 0) return fail_with("setsockopt(SO_RCVBUF)");
  }
  // The kernel's count of datagrams dropped for a full buffer, and its receive time, with each.
  if (::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) != 0) return fail_with("setsockopt(SO_RXQ_OVFL)");
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &one, sizeof one) != 0) return fail_with("setsockopt(SO_TIMESTAMP)");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(info.port);
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return fail_with("bind()");
  ip_mreq group{};
  std::memcpy(&group.imr_multiaddr.s_addr, info.group.data(), 4);
  group.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &group, sizeof group) != 0)
    return fail_with("joining the multicast group (IP_ADD_MEMBERSHIP)");
  // Only this group's datagrams, not those of every group another socket of the host joined on
  // this port (Linux's default).
  (void)::setsockopt(fd, IPPROTO_IP, IP_MULTICAST_ALL, &zero, sizeof zero);
  if (rx->epoll_fd_ < 0) return fail_with("epoll_create1()");
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = fd;
  if (::epoll_ctl(rx->epoll_fd_, EPOLL_CTL_ADD, fd, &ev) != 0) return fail_with("epoll_ctl()");
  return rx;
}

UdpmReceiver::UdpmReceiver(int fd) : fd_(fd), epoll_fd_(::epoll_create1(EPOLL_CLOEXEC)), buffer_(kDatagramMax) {}

UdpmReceiver::~UdpmReceiver() {
  ::close(fd_);  // gone at once: the receive thread may be polling epoll_fd_, which does not hold it
  if (epoll_fd_ >= 0) ::close(epoll_fd_);
}

UdpmReceiver::Lost UdpmReceiver::drain(const std::function<void(const UdpmMessage&)>& deliver, int budget) {
  Lost lost;
  std::uint64_t kernel_before = 0;
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t))];
  for (int i = 0; i < budget; ++i) {
    sockaddr_in from{};
    iovec iov{buffer_.data(), buffer_.size()};
    msghdr msg{};
    msg.msg_name = &from;
    msg.msg_namelen = sizeof from;
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      break;  // EAGAIN: nothing more now
    }
    std::int64_t recv_us = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SCM_TIMESTAMP) {
        timeval tv{};
        std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
        recv_us = static_cast<std::int64_t>(tv.tv_sec) * 1'000'000 + tv.tv_usec;
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t drops = 0;
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        lost.kernel += static_cast<std::uint32_t>(drops - kernel_drops_);  // the counter is 32-bit and wraps
        kernel_drops_ = drops;
      }
    }
    if (recv_us == 0) {
      timeval tv{};
      ::gettimeofday(&tv, nullptr);
      recv_us = static_cast<std::int64_t>(tv.tv_sec) * 1'000'000 + tv.tv_usec;
    }
    const std::uint64_t sender = (std::uint64_t{from.sin_addr.s_addr} << 16) | from.sin_port;
    const bool kernel_dropped = lost.kernel != kernel_before;
    kernel_before = lost.kernel;
    lost.network += take(std::span<const std::byte>(buffer_.data(), static_cast<std::size_t>(n)), sender, recv_us,
                         kernel_dropped, deliver);
  }
  return lost;
}

// The sender's sequence (a new one for a sender not seen yet) and, in `gap`, the messages lost
// whole before `seqno`.
UdpmReceiver::Sequence& UdpmReceiver::track_sequence(std::uint64_t sender, std::uint32_t seqno, bool kernel_dropped,
                                                     std::uint64_t& gap) {
  auto seq = sequences_.find(sender);
  if (seq == sequences_.end()) {
    if (sequences_.size() >= kMaxSenders) sequences_.clear();
    seq = sequences_.emplace(sender, Sequence{seqno, 0, false}).first;
  } else {
    const std::uint32_t ahead = seqno - seq->second.last;  // wraps
    if (ahead >= 1 && ahead < (1u << 31)) {
      if (ahead > 1 && ahead <= 100'000 && !kernel_dropped) gap = ahead - 1;
      seq->second.last = seqno;
    } else if (const std::uint32_t behind = seq->second.last - seqno; ahead != 0 && behind > 100'000) {
      seq->second = Sequence{seqno, 0, false};  // far behind: the sender started again
    }
  }
  return seq->second;
}

// Room for a new message of `size` bytes: abandons the oldest messages in reassembly beyond the
// limits. Returns how many.
std::uint64_t UdpmReceiver::make_room(std::uint32_t size) {
  std::uint64_t lost = 0;
  while (!partials_.empty() && (partials_.size() >= kMaxPartials || partial_bytes_ + size > kMaxPartialBytes)) {
    auto oldest = std::min_element(partials_.begin(), partials_.end(),
                                   [](const auto& a, const auto& b) { return a.second.last_us < b.second.last_us; });
    partial_bytes_ -= oldest->second.data.size();
    partials_.erase(oldest);
    ++lost;
  }
  return lost;
}

std::uint64_t UdpmReceiver::take(std::span<const std::byte> d, std::uint64_t sender, std::int64_t recv_us,
                                 bool kernel_dropped, const std::function<void(const UdpmMessage&)>& deliver) {
  if (d.size() < kShortHeader) return 0;  // not LCM: ignored, as liblcm does
  const std::uint32_t magic = be32(d.data());
  if (magic != kMagicShort && magic != kMagicLong) return 0;
  const std::uint32_t seqno = be32(d.data() + 4);
  // A gap in the sender's sequence numbers (one per message, whatever its channel): messages
  // the network lost whole. Not when the kernel dropped datagrams just now (counted as such),
  // nor for a jump that is no gap (a sender that restarted on the same port, reordering).
  std::uint64_t gap = 0;
  Sequence& seq = track_sequence(sender, seqno, kernel_dropped, gap);
  // A datagram of LCM's that contradicts itself is a message lost too (liblcm drops it silently).
  if (magic == kMagicShort) {
    const auto channel = read_channel(d.subspan(kShortHeader));
    if (!channel) return gap + 1;
    deliver(UdpmMessage{*channel, d.subspan(kShortHeader + channel->size() + 1), recv_us});
    return gap;
  }
  return take_fragment(d, sender, seqno, seq, gap, recv_us, deliver);
}

// A datagram of a long message (fragments): reassembled per sender; delivered when whole.
// Returns the messages lost, `gap` included.
std::uint64_t UdpmReceiver::take_fragment(std::span<const std::byte> d, std::uint64_t sender, std::uint32_t seqno,
                                          Sequence& seq, std::uint64_t gap, std::int64_t recv_us,
                                          const std::function<void(const UdpmMessage&)>& deliver) {
  if (d.size() < kLongHeader) return gap + 1;
  const std::uint32_t size = be32(d.data() + 8);
  const std::uint32_t offset = be32(d.data() + 12);
  const std::uint16_t number = be16(d.data() + 16);
  const std::uint16_t count = be16(d.data() + 18);
  std::span<const std::byte> data = d.subspan(kLongHeader);
  if (count == 0 || number >= count || size > kMaxMessageSize) return gap + 1;
  std::uint64_t lost = gap;
  auto it = partials_.find(sender);
  if (it != partials_.end() && it->second.seqno != seqno) {  // the sender moved on: the old one is lost
    partial_bytes_ -= it->second.data.size();
    partials_.erase(it);
    it = partials_.end();
    ++lost;
  }
  if (it == partials_.end()) {
    if (number != 0) {  // a message whose first fragment we missed: liblcm drops it too (counted once)
      if (!seq.any_counted || seq.counted != seqno) {
        seq.any_counted = true;
        seq.counted = seqno;
        ++lost;
      }
      return lost;
    }
    const auto channel = read_channel(data);
    if (!channel) return lost + 1;
    lost += make_room(size);
    Partial p;
    p.seqno = seqno;
    p.channel = std::string(*channel);
    try {
      p.data.resize(size);
      p.seen.assign(count, false);
    } catch (const std::bad_alloc&) {
      return lost + 1;
    }
    p.remaining = count;
    it = partials_.emplace(sender, std::move(p)).first;
    partial_bytes_ += size;
    data = data.subspan(channel->size() + 1);
  } else if (number == 0) {
    const auto channel = read_channel(data);
    if (!channel) return lost + 1;
    data = data.subspan(channel->size() + 1);
  }
  Partial& p = it->second;
  if (p.data.size() != size || p.seen.size() != count || offset > size || data.size() > size - offset) {
    partial_bytes_ -= p.data.size();
    partials_.erase(it);
    return lost + 1;  // fragments that contradict each other
  }
  p.last_us = recv_us;
  if (p.seen[number]) return lost;  // a duplicate
  p.seen[number] = true;
  std::copy(data.begin(), data.end(), p.data.begin() + offset);
  if (--p.remaining != 0) return lost;
  Partial done = std::move(p);
  partial_bytes_ -= done.data.size();
  partials_.erase(it);
  deliver(UdpmMessage{done.channel, std::span<const std::byte>(done.data), recv_us});
  return lost;
}

}  // namespace horus::lcm::detail
