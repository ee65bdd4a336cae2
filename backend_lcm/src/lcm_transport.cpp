// The LCM (liblcm 1.3.1, C API) backend of horus::net: see horus/network.hpp (the contract)
// and horus/lcm/transport.hpp.
//
// One LcmTransport per URL and process (net::SharedCache, keyed by the URL string; its shutdown
// rule is in horus/transport/shared_cache.hpp): an Engine (lcm_engine.cpp: the lcm_t and its
// receive thread) and the thread's handle. One LcmEndpoint per open(): an exact-channel
// subscription and lcm_publish. lcm_internal.hpp lists the other pieces.
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iterator>
#include <memory>
#include <mutex>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "horus/log.hpp"
#include "horus/transport/shared_cache.hpp"
#include "horus/transport_registry.hpp"
#include "lcm_internal.hpp"

namespace horus::lcm {
namespace detail {
namespace {

static_assert(kMaxChannelLength == LCM_MAX_CHANNEL_NAME_LENGTH);
static_assert(kMaxMessageSize == LCM_MAX_MESSAGE_SIZE);

// write() keeps a per-thread buffer for the body; above this size it is released after use.
constexpr std::size_t kKeepBufferLimit = std::size_t{16} << 20;

// ---------------------------------------------------------------------------- LcmEndpoint

class LcmEndpoint final : public net::Endpoint {
 public:
  LcmEndpoint(std::shared_ptr<net::Transport> transport, std::shared_ptr<Engine> engine, std::string channel,
              std::shared_ptr<Subscription> sub)
      : transport_(std::move(transport)), engine_(std::move(engine)), channel_(std::move(channel)), sub_(std::move(sub)) {}
  LcmEndpoint(const LcmEndpoint&) = delete;
  LcmEndpoint& operator=(const LcmEndpoint&) = delete;

  ~LcmEndpoint() override { engine_->unsubscribe(sub_); }

  Result<void> write(std::size_t body_size, const net::BodyWriter& writer) override {
    if (body_size > kMaxMessageSize)
      return fail(Errc::MessageTooLarge, sub_->label() + ": a body of " + std::to_string(body_size) +
                                             " bytes exceeds LCM's largest message (" + std::to_string(kMaxMessageSize) +
                                             " bytes, LCM_MAX_MESSAGE_SIZE)");
    thread_local std::vector<std::byte> buffer;
    try {
      if (buffer.size() < body_size || buffer.empty()) buffer.resize(std::max<std::size_t>(body_size, 64));
    } catch (const std::bad_alloc&) {
      return fail(Errc::Io, sub_->label() + ": out of memory for a body of " + std::to_string(body_size) + " bytes");
    }
    writer.fill(writer.context, std::span<std::byte>(buffer.data(), body_size));
    int error = 0;
    const int rc = engine_->publish(channel_.c_str(), buffer.data(), static_cast<unsigned>(body_size), error);
    if (buffer.size() > kKeepBufferLimit) std::vector<std::byte>().swap(buffer);
    if (rc == 0) return {};
    std::string why;
    if (engine_->info().provider == Provider::File && engine_->info().file_read)
      why = " (the URL reads a log: file:// URLs publish only with mode=w or mode=a)";
    else if (rc > 0)
      why = " (only " + std::to_string(rc) + " bytes of the datagram were sent)";
    else if (error != 0)
      why = ": " + std::string(std::strerror(error));
    return fail(Errc::Io, sub_->label() + ": lcm_publish of " + std::to_string(body_size) + " bytes to LCM URL '" +
                              engine_->url() + "' failed" + why);
  }

  void set_receiving(bool on) noexcept override { engine_->set_receiving(sub_, channel_, on); }

  std::uint32_t matched_publishers() const override { return 0; }   // LCM has no discovery
  std::uint32_t matched_subscribers() const override { return 0; }  // LCM has no discovery

 private:
  std::shared_ptr<net::Transport> transport_;  // keeps the transport (and its thread) alive
  std::shared_ptr<Engine> engine_;
  const std::string channel_;
  std::shared_ptr<Subscription> sub_;
};

// ---------------------------------------------------------------------------- LcmTransport

class LcmTransport final : public net::Transport, public std::enable_shared_from_this<LcmTransport> {
  struct Private {};

 public:
  static constexpr std::string_view kCacheName = "LCM instances";  // its net::SharedCache
  LcmTransport(Private, net::CacheTicket ticket, std::shared_ptr<Engine> engine)
      : ticket_(std::move(ticket)), engine_(std::move(engine)) {}
  LcmTransport(const LcmTransport&) = delete;
  LcmTransport& operator=(const LcmTransport&) = delete;

  // Called by the cache, under its lock.
  static Result<std::shared_ptr<LcmTransport>> create(net::CacheTicket ticket, const std::string& url,
                                                      const UrlInfo& info);

  ~LcmTransport() override {
    engine_->request_stop();
    if (thread_.joinable()) {
      // The last endpoint may be closed by a listener, on the receive thread itself: that
      // thread then ends on its own and releases the engine.
      if (engine_->on_receive_thread())
        thread_.detach();
      else
        thread_.join();
    }
    // ticket_, destroyed last, frees the URL in the cache.
  }

  std::string_view name() const noexcept override { return "lcm"; }

  // udpm loops multicast back (IP_MULTICAST_LOOP), memq and the tcpq server deliver to every
  // subscriber; a log file does not.
  bool delivers_own_samples() const noexcept override { return engine_->info().provider != Provider::File; }

  Result<std::unique_ptr<net::Endpoint>> open(const net::EndpointSpec& spec, net::Listener& listener) override {
    std::string label = "topic '" + spec.topic + "' (LCM channel '" + spec.wire_topic + "')";
    auto channel = check_channel(spec.wire_topic);
    if (!channel) return fail(Errc::InvalidName, label + ": " + channel.error().message());
    auto sub = std::make_shared<Subscription>(listener, std::move(label));
    if (auto done = engine_->subscribe(sub, *channel, spec.receive); !done) return std::unexpected(std::move(done.error()));
    try {
      return std::unique_ptr<net::Endpoint>(
          std::make_unique<LcmEndpoint>(shared_from_this(), engine_, std::move(*channel), sub));
    } catch (...) {
      engine_->unsubscribe(sub);
      throw;
    }
  }

 private:
  net::CacheTicket ticket_;  // first: removes the cache entry after everything else is gone
  std::shared_ptr<Engine> engine_;
  std::thread thread_;
};

Result<std::shared_ptr<LcmTransport>> LcmTransport::create(net::CacheTicket ticket, const std::string& url,
                                                           const UrlInfo& info) {
  lcm_t* lcm = lcm_create(url.c_str());  // udpm: the send socket only (receiving starts later)
  if (lcm == nullptr)
    return fail(Errc::Io, "LCM could not start provider for URL '" + url + "' (liblcm printed the reason on stderr)" +
                              provider_hint(url, info));
  const int event_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (event_fd < 0) {
    const int err = errno;
    lcm_destroy(lcm);
    return fail(Errc::Io, "LCM URL '" + url + "': eventfd() failed: " + std::strerror(err));
  }
  std::shared_ptr<Engine> engine;
  try {
    engine = std::make_shared<Engine>(url, info, lcm, event_fd);
  } catch (...) {
    lcm_destroy(lcm);
    ::close(event_fd);
    throw;
  }
  // memq, file and tcpq receive through the publishing instance: start it now, as before any
  // endpoint (a log that cannot be read is an error of the transport).
  if (info.provider != Provider::Udpm)
    if (auto ok = engine->start_receiving_now(); !ok) return std::unexpected(std::move(ok.error()));

  auto t = std::make_shared<LcmTransport>(Private{}, std::move(ticket), engine);
  try {
    t->thread_ = std::thread(&Engine::run, engine);
  } catch (const std::system_error& e) {
    return fail(Errc::Io, "LCM URL '" + url + "': cannot start the receive thread: " + e.what());
  }
  return t;
}

}  // namespace
}  // namespace detail

// ---------------------------------------------------------------------------- public API

Result<std::shared_ptr<net::Transport>> lcm_transport(std::string_view url) {
  using detail::LcmTransport;
  auto info = detail::parse_url(url);
  if (!info) return std::unexpected(std::move(info.error()));
  const std::string key(url);
  auto got = net::SharedCache<LcmTransport>::instance().get(
      key, [&](net::CacheTicket ticket) { return LcmTransport::create(std::move(ticket), key, *info); },
      "LCM URL '" + key + "': the previous transport of this URL did not shut down within 10 s");
  if (!got) return std::unexpected(std::move(got.error()));
  return std::shared_ptr<net::Transport>(std::move(*got));
}

namespace {
// The transports of a configuration's data URL (`control` false) or of its fleet layer's
// channels (control_url).
Result<std::shared_ptr<net::Transport>> open_for(const net::Config& config, bool control) {
  auto url = url_from(config);
  if (!url) return std::unexpected(std::move(url.error()));
  if (config.security.mode == net::SecurityMode::Permissive) {
    static std::once_flag once;
    std::call_once(once, [&] {
      horus::detail::log().warn("LCM URL '{}': security is permissive ({}) and LCM has none: its fleet topics "
                                "run unprotected (anyone on the network reads and writes them)",
                                *url, config.security.origin);
    });
  }
  return lcm_transport(control ? control_url(*url) : *url);
}
}  // namespace

void register_lcm() {
  (void)net::register_transport(
      {"lcm", net::WireFormat::Lcm, &channel_name,
       [](const net::Config& config) { return open_for(config, false); },
       [](const net::Config& config) { return open_for(config, true); },
       [](const net::Config& config) -> Result<void> {
         auto url = url_from(config);
         if (!url) return std::unexpected(std::move(url.error()));
         return {};
       }});
}

}  // namespace horus::lcm
