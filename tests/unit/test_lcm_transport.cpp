// The LCM transport (horus/lcm/transport.hpp) on its own: URL and channel checks, memq://
// (in-process) round trips, exact channel matching, own-sample delivery, the size limit,
// endpoint shutdown under traffic, and file:// logs. udpm:// is in test_lcm_udpm.cpp. Every wait
// is bounded by a deadline.
#include <atomic>
#include <cstdlib>
#include <ctime>
#include <optional>
#include <thread>

#include <lcm/eventlog.h>

#include "horus/environment.hpp"
#include "lcm_transport_test.hpp"

#if defined(__SANITIZE_THREAD__)
// liblcm and GLib are not instrumented, and GLib's GMutex is a bare futex that ThreadSanitizer
// cannot see: memq's hand-over of a message (malloc'd by the publishing thread, read by the
// receive thread) is reported as a race inside liblcm. Ignore the memory accesses made by
// non-instrumented libraries; everything in horus is still checked.
extern "C" const char* __tsan_default_options() { return "ignore_noninstrumented_modules=1"; }
#endif

namespace {

/// Sets or unsets an environment variable for the scope, then restores it.
class EnvGuard {
 public:
  EnvGuard(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = std::string(old);
    if (value)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~EnvGuard() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  EnvGuard(const EnvGuard&) = delete;
  EnvGuard& operator=(const EnvGuard&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// ---------------------------------------------------------------------------- URLs and channels

TEST(LcmUrl, AcceptsGoodUrls) {
  for (std::string_view url : {
           horus::lcm::kDefaultUrl,
           std::string_view("udpm://239.255.76.67:7667"),
           std::string_view("udpm://224.0.0.1:1?ttl=1&recv_buf_size=4194304"),
           std::string_view("udpm://239.255.255.255:65535?transmit_only=false&ttl=255"),
           std::string_view("udpm://239.0.0.1:7667?transmit_only=true"),
           std::string_view("memq://"),
           std::string_view("file:///tmp/x.lcmlog"),
           std::string_view("file:///tmp/x.lcmlog?mode=w&speed=2.5&start_timestamp=-1"),
           std::string_view("file://relative.lcmlog?mode=a&speed=0"),
           std::string_view("tcpq://"),
           std::string_view("tcpq://127.0.0.1:7700"),
           std::string_view("tcpq://localhost"),
       }) {
    const auto ok = horus::lcm::check_url(url);
    EXPECT_TRUE(ok) << url << ": " << (ok ? "" : ok.error().message());
  }
}

TEST(LcmUrl, RejectsEachKindOfBadUrlNamingTheProblem) {
  struct Case {
    std::string url;
    std::vector<std::string> expected;  // substrings of the message
  };
  const std::string udpm_expected = "expected udpm://<IPv4 224.0.0.0-239.255.255.255>:<port>[?ttl=0..255&recv_buf_size=N]";
  const std::string base = "udpm://239.255.76.67:7667";
  const std::vector<Case> cases = {
      {"", {"the URL is empty", "udpm://..., memq://, file://... or tcpq://..."}},
      {"garbage", {"no '<scheme>://'"}},
      {"://x", {"no '<scheme>://'"}},
      {"foo://bar", {"unknown scheme 'foo'", "expected udpm://..., memq://, file://... or tcpq://..."}},
      {"udpm://10.1.2.3:7667",
       {"LCM URL 'udpm://10.1.2.3:7667': 10.1.2.3 is not a multicast address; " + udpm_expected +
        " (the default is udpm://239.255.76.67:7667?ttl=0)"}},
      {"udpm://240.0.0.1:7667", {"240.0.0.1 is not a multicast address"}},
      {"udpm://notanip:7667", {"'notanip' is not an IPv4 address", udpm_expected}},
      {"udpm://239.255.076.67:7667", {"'239.255.076.67' is not an IPv4 address"}},
      {"udpm://239.255.76:7667", {"'239.255.76' is not an IPv4 address"}},
      {"udpm://239.255.76.67.1:7667", {"is not an IPv4 address"}},
      {"udpm://", {"no multicast address and port"}},
      {"udpm://:7667", {"no multicast address"}},
      {"udpm://239.255.76.67", {"the port is missing"}},
      {"udpm://239.255.76.67:", {"the port is missing"}},
      {"udpm://239.255.76.67:abc", {"port 'abc' is not a decimal number"}},
      {"udpm://239.255.76.67:0x1DF3", {"port '0x1DF3' is not a decimal number"}},
      {"udpm://239.255.76.67:0", {"port 0 is out of range 1..65535"}},
      {"udpm://239.255.76.67:70000", {"port 70000 is out of range 1..65535"}},
      {base + "?ttl=256", {"ttl=256 is not an integer 0..255", "ttl=0..255, recv_buf_size="}},
      {base + "?ttl=x", {"ttl=x is not an integer 0..255"}},
      {base + "?ttl=-1", {"ttl=-1 is not an integer 0..255"}},
      {base + "?bogus=1", {"unknown udpm option 'bogus'", "transmit_only=true|false"}},
      {base + "?recv_buf_size=0", {"recv_buf_size=0 is not a positive integer"}},
      {base + "?recv_buf_size=4294967296", {"recv_buf_size=4294967296 is not a positive integer"}},
      {base + "?transmit_only=yes", {"transmit_only=yes is neither true nor false"}},
      {base + "?ttl=0&ttl=1", {"option 'ttl' is given twice"}},
      {base + "?", {"'?' is followed by no option"}},
      {base + "?ttl=0&", {"an empty option"}},
      {base + "?ttl", {"option 'ttl' is not of the form name=value"}},
      {base + "?ttl=0?ttl=1", {"ttl=0?ttl=1 is not an integer 0..255"}},
      {"memq://x", {"memq takes no host part and no options", "expected memq://"}},
      {"memq://?a=b", {"memq takes no host part and no options"}},
      {"file://", {"no file path", "file://<path>[?mode=r|w|a"}},
      {"file://?mode=r", {"no file path"}},
      {"file:///x?mode=q", {"mode=q is not r, w or a"}},
      {"file:///x?speed=fast", {"speed=fast is not a number"}},
      {"file:///x?start_timestamp=1.5", {"start_timestamp=1.5 is not an integer"}},
      {"file:///x?color=red", {"unknown file option 'color'"}},
      {"tcpq://host?x=1", {"tcpq takes no options"}},
      {"tcpq://host:0", {"port '0' is not a number 1..65535"}},
      {"tcpq://ho st:7700", {"'ho st' is not a host name"}},
      {std::string("udpm://239.255.76.67:7667\0x", 27), {"NUL byte"}},
  };
  for (const Case& c : cases) {
    const auto result = horus::lcm::check_url(c.url);
    ASSERT_FALSE(result) << "accepted: " << c.url;
    EXPECT_EQ(result.error().code(), Errc::Config) << c.url;
    const std::string& message = result.error().message();
    if (c.url.find('\0') == std::string::npos) {
      EXPECT_NE(message.find("LCM URL '" + c.url + "'"), std::string::npos) << message;
    }
    EXPECT_NE(message.find("(the default is udpm://239.255.76.67:7667?ttl=0)"), std::string::npos) << message;
    for (const std::string& part : c.expected)
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

TEST(LcmUrl, LcmTransportRefusesABadUrlWithoutStartingLcm) {
  const auto t = horus::lcm::lcm_transport("udpm://10.1.2.3:7667");
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code(), Errc::Config);
  EXPECT_NE(t.error().message().find("not a multicast address"), std::string::npos);
}

namespace {
// The URL the environment alone names (net::config_from with no configuration file).
horus::Result<std::string> url_from_environment() {
  auto config = horus::net::config_from(horus::Environment::read(), {});
  if (!config) return std::unexpected(config.error());
  return horus::lcm::url_from(*config);
}
}  // namespace

TEST(LcmUrl, EnvironmentPrecedence) {
  {
    EnvGuard a("HORUS_LCM_URL", nullptr), b("LCM_DEFAULT_URL", nullptr);
    const auto url = url_from_environment();
    ASSERT_TRUE(url) << url.error().message();
    EXPECT_EQ(*url, horus::lcm::kDefaultUrl);
  }
  {
    EnvGuard a("HORUS_LCM_URL", ""), b("LCM_DEFAULT_URL", "");
    const auto url = url_from_environment();
    ASSERT_TRUE(url);
    EXPECT_EQ(*url, horus::lcm::kDefaultUrl);
  }
  {
    EnvGuard a("HORUS_LCM_URL", nullptr), b("LCM_DEFAULT_URL", "memq://");
    const auto url = url_from_environment();
    ASSERT_TRUE(url);
    EXPECT_EQ(*url, "memq://");
  }
  {
    EnvGuard a("HORUS_LCM_URL", ""), b("LCM_DEFAULT_URL", "memq://");
    const auto url = url_from_environment();
    ASSERT_TRUE(url);
    EXPECT_EQ(*url, "memq://");
  }
  {
    EnvGuard a("HORUS_LCM_URL", "udpm://239.1.2.3:9999?ttl=1"), b("LCM_DEFAULT_URL", "memq://");
    const auto url = url_from_environment();
    ASSERT_TRUE(url);
    EXPECT_EQ(*url, "udpm://239.1.2.3:9999?ttl=1");
  }
  {
    EnvGuard a("HORUS_LCM_URL", "udpm://10.0.0.1:7667"), b("LCM_DEFAULT_URL", "memq://");
    const auto url = url_from_environment();
    ASSERT_FALSE(url);
    EXPECT_EQ(url.error().code(), Errc::Config);
    EXPECT_NE(url.error().message().find("HORUS_LCM_URL"), std::string::npos) << url.error().message();
    EXPECT_NE(url.error().message().find("10.0.0.1 is not a multicast address"), std::string::npos);
  }
  {
    EnvGuard a("HORUS_LCM_URL", nullptr), b("LCM_DEFAULT_URL", "bogus");
    const auto url = url_from_environment();
    ASSERT_FALSE(url);
    EXPECT_NE(url.error().message().find("LCM_DEFAULT_URL"), std::string::npos) << url.error().message();
    EXPECT_EQ(url.error().message().find("HORUS_LCM_URL"), std::string::npos) << url.error().message();
  }
}

TEST(LcmChannel, LengthLimits) {
  const std::string c63(63, 'c');
  const auto ok = horus::lcm::check_channel(c63);
  ASSERT_TRUE(ok) << ok.error().message();
  EXPECT_EQ(*ok, c63);

  const auto long_one = horus::lcm::check_channel(std::string(64, 'c'));
  ASSERT_FALSE(long_one);
  EXPECT_EQ(long_one.error().code(), Errc::InvalidName);
  EXPECT_NE(long_one.error().message().find("LCM channel names are at most 63 bytes"), std::string::npos)
      << long_one.error().message();
  EXPECT_NE(long_one.error().message().find("is 64 bytes"), std::string::npos);

  const auto empty = horus::lcm::check_channel("");
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().code(), Errc::InvalidName);
  EXPECT_NE(empty.error().message().find("empty LCM channel name"), std::string::npos);

  const auto control = horus::lcm::check_channel(std::string("a\nb"));
  ASSERT_FALSE(control);
  EXPECT_NE(control.error().message().find("0x0a at offset 1"), std::string::npos) << control.error().message();
}

TEST(LcmChannel, OpenRefusesATooLongWireTopic) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t) << t.error().message();
  Collector listener;
  const auto endpoint = (*t)->open(spec("horus/" + std::string(60, 'x')), listener);
  ASSERT_FALSE(endpoint);
  EXPECT_EQ(endpoint.error().code(), Errc::InvalidName);
  EXPECT_NE(endpoint.error().message().find("at most 63 bytes"), std::string::npos) << endpoint.error().message();
}

// ---------------------------------------------------------------------------- memq

TEST(LcmMemq, OneTransportPerUrl) {
  auto a = horus::lcm::lcm_transport("memq://");
  auto b = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->get(), b->get());
  EXPECT_EQ((*a)->name(), "lcm");
}

TEST(LcmMemq, RoundTripBetweenTwoEndpointsOnOneChannel) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t) << t.error().message();
  Collector la, lb;
  const std::string ch = channel("roundtrip");
  auto a = open_endpoint(**t, ch, la);
  auto b = open_endpoint(**t, ch, lb);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->matched_publishers(), 0u);  // LCM has no discovery
  EXPECT_EQ(a->matched_subscribers(), 0u);

  const auto first = bytes_of("hello lcm");
  const std::vector<std::byte> empty;
  const auto second = pattern(100000, 7);
  ASSERT_TRUE(send(*a, first));
  ASSERT_TRUE(send(*a, empty));
  ASSERT_TRUE(send(*b, second));
  ASSERT_TRUE(lb.wait_for_count(3, 5s)) << lb.count();
  ASSERT_TRUE(la.wait_for_count(3, 5s)) << la.count();
  for (const Collector* l : {&la, &lb}) {
    const auto got = l->samples();
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0], first);
    EXPECT_EQ(got[1], empty);
    EXPECT_EQ(got[2], second);
    EXPECT_FALSE(l->little_endian_seen());  // LCM is big-endian
    EXPECT_TRUE(l->errors().empty());
  }
}

TEST(LcmMemq, OwnSamplesComeBack) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t);
  EXPECT_TRUE((*t)->delivers_own_samples());
  Collector l;
  auto e = open_endpoint(**t, channel("own"), l);
  ASSERT_TRUE(e);
  const auto body = bytes_of("mine");
  ASSERT_TRUE(send(*e, body));
  ASSERT_TRUE(l.wait_for_count(1, 5s));
  EXPECT_EQ(l.samples()[0], body);
}

TEST(LcmMemq, ChannelIsMatchedExactlyNotAsARegex) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t);
  const std::string dotted = channel("a.b");
  const std::string other = channel("aXb");
  Collector l_dotted, l_other, l_star, l_pub;
  auto sub_dotted = open_endpoint(**t, dotted, l_dotted);
  auto sub_other = open_endpoint(**t, other, l_other);
  auto sub_star = open_endpoint(**t, channel("a.*"), l_star);  // would match everything below as a regex
  auto pub_other = open_endpoint(**t, other, l_pub);
  ASSERT_TRUE(sub_dotted && sub_other && sub_star && pub_other);

  ASSERT_TRUE(send(*pub_other, bytes_of("to aXb")));
  ASSERT_TRUE(send(*sub_dotted, bytes_of("marker")));  // memq is one FIFO: aXb's is handled first
  ASSERT_TRUE(l_dotted.wait_for_count(1, 5s));
  ASSERT_TRUE(l_other.wait_for_count(1, 5s));
  const auto got = l_dotted.samples();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], bytes_of("marker"));
  EXPECT_EQ(l_other.samples()[0], bytes_of("to aXb"));
  EXPECT_EQ(l_star.count(), 0u);
}

TEST(LcmMemq, TooLargeBodyIsRefusedBeforeFilling) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t);
  Collector l;
  auto e = open_endpoint(**t, channel("big"), l);
  ASSERT_TRUE(e);
  bool filled = false;
  const horus::net::BodyWriter writer{[](void* c, std::span<std::byte>) { *static_cast<bool*>(c) = true; }, &filled};
  const auto r = e->write(horus::lcm::kMaxMessageSize + 1, writer);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::MessageTooLarge);
  EXPECT_NE(r.error().message().find(channel("big")), std::string::npos) << r.error().message();
  EXPECT_NE(r.error().message().find("268435456"), std::string::npos) << r.error().message();
  EXPECT_FALSE(filled);
}

// A listener that must not be called once its endpoint is gone.
class GuardedListener final : public horus::net::Listener {
 public:
  void on_sample(const horus::net::Sample&) override {
    if (closed.load()) violations.fetch_add(1);
    calls.fetch_add(1);
  }
  void on_error(std::string_view) override {
    if (closed.load()) violations.fetch_add(1);
  }
  void on_lost(std::uint64_t) override {
    if (closed.load()) violations.fetch_add(1);
  }
  std::atomic<bool> closed{false};
  std::atomic<int> violations{0};
  std::atomic<std::uint64_t> calls{0};
};

TEST(LcmMemq, DestroyedEndpointGetsNoCallbackWhileAnotherThreadPublishes) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t);
  const std::string ch = channel("shutdown");
  Collector l_pub;
  auto pub = open_endpoint(**t, ch, l_pub);  // also sees every sample: proof that dispatch goes on
  ASSERT_TRUE(pub);

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> sent{0};
  std::thread publisher([&] {
    const auto body = pattern(256, 3);
    const auto deadline = Clock::now() + 60s;
    while (!stop.load() && Clock::now() < deadline) {
      if (send(*pub, body)) sent.fetch_add(1);
      if (sent.load() % 64 == 0) std::this_thread::yield();
    }
  });

  for (int round = 0; round < 20; round++) {
    GuardedListener listener;
    auto sub = (*t)->open(spec(ch), listener);
    ASSERT_TRUE(sub) << sub.error().message();
    const auto deadline = Clock::now() + 10s;
    while (listener.calls.load() < 5 && Clock::now() < deadline) std::this_thread::sleep_for(1ms);
    ASSERT_GE(listener.calls.load(), 5u) << "round " << round;

    sub->reset();  // must return only when no callback runs and none will
    listener.closed.store(true);
    const std::uint64_t calls_at_close = listener.calls.load();

    // More traffic reaches the other endpoint, none reaches the closed one.
    const std::size_t seen = l_pub.count();
    ASSERT_TRUE(l_pub.wait_for_count(seen + 50, 10s));
    EXPECT_EQ(listener.calls.load(), calls_at_close);
    EXPECT_EQ(listener.violations.load(), 0);
  }
  stop.store(true);
  publisher.join();
  EXPECT_GT(sent.load(), 0u);
}

// A listener that closes its own endpoint from its callback (on the receive thread).
class SelfClosingListener final : public horus::net::Listener {
 public:
  void on_sample(const horus::net::Sample&) override {
    std::lock_guard lock(mutex_);
    calls_++;
    if (endpoint_) {
      endpoint_.reset();  // the transport must neither deadlock nor call again
      calls_at_close_ = calls_;
    }
  }
  void on_error(std::string_view) override {}
  void attach(std::unique_ptr<Endpoint> endpoint) {
    std::lock_guard lock(mutex_);
    endpoint_ = std::move(endpoint);
  }
  int calls() const {
    std::lock_guard lock(mutex_);
    return calls_;
  }
  int calls_at_close() const {  // 0 while not closed
    std::lock_guard lock(mutex_);
    return calls_at_close_;
  }

 private:
  mutable std::mutex mutex_;
  std::unique_ptr<Endpoint> endpoint_;
  int calls_ = 0;
  int calls_at_close_ = 0;
};

TEST(LcmMemq, EndpointClosedFromItsOwnCallback) {
  auto t = horus::lcm::lcm_transport("memq://");
  ASSERT_TRUE(t);
  const std::string ch = channel("selfclose");
  SelfClosingListener self_closing;
  Collector l_pub;
  auto pub = open_endpoint(**t, ch, l_pub);
  auto sub = (*t)->open(spec(ch), self_closing);
  ASSERT_TRUE(pub && sub);
  self_closing.attach(std::move(*sub));
  for (int i = 0; i < 10; i++) ASSERT_TRUE(send(*pub, bytes_of("x")));
  ASSERT_TRUE(l_pub.wait_for_count(10, 5s));
  EXPECT_EQ(self_closing.calls(), 1);
  EXPECT_EQ(self_closing.calls_at_close(), 1);
}

// ---------------------------------------------------------------------------- file

TEST(LcmFile, WriteThenReadALogWithoutSpinningAtItsEnd) {
  const std::string path = "/tmp/horus_lcm_test_" + std::to_string(::getpid()) + ".lcmlog";
  const std::string ch = channel("log");
  {
    auto t = horus::lcm::lcm_transport("file://" + path + "?mode=w");
    ASSERT_TRUE(t) << t.error().message();
    EXPECT_FALSE((*t)->delivers_own_samples());
    Collector l;
    auto e = open_endpoint(**t, ch, l);
    ASSERT_TRUE(e);
    for (int i = 0; i < 3; i++) ASSERT_TRUE(send(*e, bytes_of("event " + std::to_string(i))));
  }
  {  // The log holds the three events, as LCM's own reader sees them.
    lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
    ASSERT_NE(log, nullptr);
    std::vector<std::string> events;
    while (lcm_eventlog_event_t* ev = lcm_eventlog_read_next_event(log)) {
      if (std::string(ev->channel, static_cast<std::size_t>(ev->channellen)) == ch)
        events.emplace_back(static_cast<const char*>(ev->data), static_cast<std::size_t>(ev->datalen));
      lcm_eventlog_free_event(ev);
    }
    lcm_eventlog_destroy(log);
    EXPECT_EQ(events, (std::vector<std::string>{"event 0", "event 1", "event 2"}));
  }
  {
    auto t = horus::lcm::lcm_transport("file://" + path + "?mode=r&speed=0");
    ASSERT_TRUE(t) << t.error().message();
    Collector l;
    auto e = open_endpoint(**t, ch, l);  // replay started at creation: some events may be gone already
    ASSERT_TRUE(e);
    const auto publish = e->write(1, horus::net::BodyWriter{[](void*, std::span<std::byte> b) { b[0] = {}; }, nullptr});
    ASSERT_FALSE(publish);
    EXPECT_EQ(publish.error().code(), Errc::Io);
    EXPECT_NE(publish.error().message().find("mode=w or mode=a"), std::string::npos) << publish.error().message();
    // At the end of the log the receive thread must idle, not spin on the readable fd.
    std::this_thread::sleep_for(200ms);  // not synchronisation: lets the replay reach its end
    const double cpu0 = process_cpu_seconds();
    const auto wall0 = Clock::now();
    std::this_thread::sleep_for(500ms);
    const double cpu = process_cpu_seconds() - cpu0;
    const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
    EXPECT_LT(cpu, 0.5 * wall) << "the receive thread seems to spin at the end of the log";
    EXPECT_TRUE(l.errors().empty());
  }
  ::unlink(path.c_str());
}

TEST(LcmFile, LastReferenceReleasedOnTheReceiveThread) {
  // The listener owns the endpoint, which holds the only reference to its transport: closing
  // it from the callback ends the transport on its own receive thread (no self-join).
  const std::string path = "/tmp/horus_lcm_test_last_" + std::to_string(::getpid()) + ".lcmlog";
  const std::string ch = channel("lastref");
  {
    auto t = horus::lcm::lcm_transport("file://" + path + "?mode=w");
    ASSERT_TRUE(t) << t.error().message();
    Collector l;
    auto e = open_endpoint(**t, ch, l);
    ASSERT_TRUE(e);
    for (int i = 0; i < 4; i++) {
      ASSERT_TRUE(send(*e, bytes_of("event " + std::to_string(i))));
      std::this_thread::sleep_for(150ms);  // spacing recorded in the log, replayed at speed 1
    }
  }
  SelfClosingListener self_closing;
  std::weak_ptr<Transport> weak;
  {
    auto t = horus::lcm::lcm_transport("file://" + path + "?mode=r");
    ASSERT_TRUE(t) << t.error().message();
    auto sub = (*t)->open(spec(ch), self_closing);
    ASSERT_TRUE(sub);
    weak = *t;
    t->reset();
    self_closing.attach(std::move(*sub));  // now the only owner of the transport
  }
  const auto deadline = Clock::now() + 5s;
  while ((self_closing.calls_at_close() == 0 || !weak.expired()) && Clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  EXPECT_GT(self_closing.calls_at_close(), 0);
  EXPECT_TRUE(weak.expired());
  const int closed_at = self_closing.calls_at_close();
  EXPECT_EQ(self_closing.calls(), closed_at);
  ::unlink(path.c_str());
}

// ---------------------------------------------------------------------------- udpm

}  // namespace
