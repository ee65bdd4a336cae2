// Boost.Beast (Debian's libboost-dev) carries the WebSocket and HTTP framing; this file is the only one of the build
// that includes it.
#include "server.hpp"

#include <atomic>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>

#include "protocol.hpp"
#include "status_page.hpp"

namespace horus::tools::fox {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Steady = std::chrono::steady_clock;

constexpr std::size_t kMaxQueuedFrames = 8192;                // data frames a client may have queued
constexpr std::size_t kMaxQueuedText = std::size_t{8} << 20;  // JSON bytes queued before it is closed

struct Shared {
  Hub& hub;
  ServerOptions options;
  std::atomic<std::size_t> clients{0};
};

// The first subprotocol of a client's Sec-WebSocket-Protocol offer ("a, b") that this server
// speaks: foxglove.websocket.v1 or foxglove.sdk.v1 (the same messages); empty when none.
std::string_view chosen_subprotocol(std::string_view offered) {
  for (std::size_t at = 0; at <= offered.size();) {
    auto end = offered.find(',', at);
    if (end == std::string_view::npos) end = offered.size();
    auto item = offered.substr(at, end - at);
    while (!item.empty() && (item.front() == ' ' || item.front() == '\t')) item.remove_prefix(1);
    while (!item.empty() && (item.back() == ' ' || item.back() == '\t')) item.remove_suffix(1);
    if (item == kSubprotocol) return kSubprotocol;
    if (item == kSdkSubprotocol) return kSdkSubprotocol;
    at = end + 1;
  }
  return {};
}

class WsSession final : public Client, public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, Shared& shared) : ws_(std::move(socket)), shared_(shared) {
    beast::error_code ec;
    auto ep = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    peer_ = ec ? std::string("?") : fmt::format("{}:{}", ep.address().to_string(), ep.port());
    ++shared_.clients;
  }
  ~WsSession() override { --shared_.clients; }

  // `subprotocol`: the one of the client's offer this server speaks (chosen_subprotocol).
  void accept(http::request<http::string_body> req, std::string_view subprotocol) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& res) {
      res.set(http::field::sec_websocket_protocol, std::string(subprotocol));
      res.set(http::field::server, "horus foxglove");
    }));
    ws_.read_message_max(0);   // read() enforces kMaxClientFrame as the parts arrive
    ws_.auto_fragment(false);  // a message is one frame, written in one gather (not 4 KiB frames)
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->id_ = self->shared_.hub.add_client(self, self->peer_);
      self->added_ = true;
      self->read();
    });
  }

  // ---- Client (any thread) ----
  void send_text(std::string text) override {
    std::lock_guard lock(mu_);
    if (dead_) return;
    text_bytes_ += text.size();
    if (text_bytes_ > kMaxQueuedText && !close_code_) {
      close_code_ = 1008;
      close_why_ = "the client does not read what the server sends";
    }
    Frame f;
    f.text = std::move(text);
    queue_.push_back(std::move(f));
    schedule();
  }

  void send_data(std::uint32_t subscription, std::uint64_t receive_ns, Payload payload) override {
    std::lock_guard lock(mu_);
    if (dead_) return;
    const std::size_t size = payload->size() + 13;
    // Over the bound: the oldest data frames go (not the one being written), newest kept.
    while ((data_bytes_ + size > shared_.options.queue_bytes || data_frames_ >= kMaxQueuedFrames) && data_frames_ > 0) {
      auto it = std::find_if(queue_.begin(), queue_.end(), [](const Frame& f) { return f.payload != nullptr; });
      if (it == queue_.end()) break;
      data_bytes_ -= it->payload->size() + 13;
      --data_frames_;
      ++dropped_;
      queue_.erase(it);
    }
    if (dropped_ > warned_ && Steady::now() - last_warning_ > std::chrono::seconds(2)) {
      Frame w;
      w.text = status(Level::Warning, fmt::format("{} messages dropped so far: this client reads slower than its "
                                                  "subscriptions publish (the newest are kept)",
                                                  dropped_));
      text_bytes_ += w.text.size();
      queue_.push_back(std::move(w));
      warned_ = dropped_;
      last_warning_ = Steady::now();
    }
    Frame f;
    f.header = message_data_header(subscription, receive_ns);
    f.payload = std::move(payload);
    data_bytes_ += size;
    ++data_frames_;
    queue_.push_back(std::move(f));
    schedule();
  }

  void send_time(std::uint64_t ns) override {
    std::lock_guard lock(mu_);
    if (dead_) return;
    time_ = ns;  // only the latest is worth sending
    schedule();
  }

  void close(std::uint16_t code, std::string reason) override {
    std::lock_guard lock(mu_);
    if (dead_ || close_code_) return;
    close_code_ = code;
    close_why_ = std::move(reason);
    schedule();
  }

  Stats stats() const override {
    std::lock_guard lock(mu_);
    return {sent_, dropped_, data_bytes_};
  }

  // The server closes it (its destructor): the hub forgets it first.
  void shutdown() {
    finish();
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  struct Frame {
    std::string text;  // a JSON message when payload is null
    std::array<std::byte, 13> header{};
    Payload payload;
  };

  // Holds mu_: makes the I/O thread write what is queued.
  void schedule() {
    if (scheduled_ || writing_) return;
    scheduled_ = true;
    asio::post(ws_.get_executor(), [self = shared_from_this()] { self->write(); });
  }

  // Reads a message in parts, so that one larger than kMaxClientFrame is refused after the limit, not buffered: the
  // connection is then closed with 1009 (the close drains the rest).
  void read() {
    ws_.async_read_some(in_, 256 * 1024, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->finish();
        return;
      }
      if (self->in_.size() > kMaxClientFrame) {
        self->in_.clear();
        self->close(1009, close_reason(fmt::format("a message of more than {} MiB (the most a client may send)",
                                                   kMaxClientFrame >> 20)));
        return;  // no more reads: the close reads until the client's close frame
      }
      if (!self->ws_.is_message_done()) {
        self->read();
        return;
      }
      const auto data = self->in_.cdata();
      const auto* p = static_cast<const std::byte*>(data.data());
      if (self->ws_.got_text())
        self->shared_.hub.on_text(self->id_, std::string_view(reinterpret_cast<const char*>(p), data.size()));
      else
        self->shared_.hub.on_binary(self->id_, std::span<const std::byte>(p, data.size()));
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  // The I/O thread: writes the next frame (time first), or the close when all is written.
  void write() {
    std::unique_lock lock(mu_);
    scheduled_ = false;
    if (writing_ || dead_) return;
    auto done = [self = shared_from_this()](beast::error_code ec, std::size_t) {
      std::unique_lock held(self->mu_);
      self->writing_ = false;
      if (self->current_.payload) ++self->sent_;
      self->current_ = {};
      held.unlock();
      if (ec) {
        self->finish();
        return;
      }
      self->write();
    };
    if (time_) {
      time_buf_ = time_frame(*time_);
      time_.reset();
      writing_ = true;
      lock.unlock();
      ws_.binary(true);
      ws_.async_write(asio::buffer(time_buf_), std::move(done));
      return;
    }
    if (queue_.empty()) {
      if (close_code_ && !closing_) {
        closing_ = true;
        writing_ = true;
        const websocket::close_reason why(static_cast<websocket::close_code>(*close_code_), close_why_);
        lock.unlock();
        ws_.async_close(why, [self = shared_from_this()](beast::error_code) {
          {
            std::lock_guard held(self->mu_);
            self->writing_ = false;
          }
          self->finish();
        });
      }
      return;
    }
    current_ = std::move(queue_.front());
    queue_.pop_front();
    writing_ = true;
    if (current_.payload) {
      data_bytes_ -= current_.payload->size() + 13;
      --data_frames_;
      lock.unlock();
      ws_.binary(true);
      const std::array<asio::const_buffer, 2> bufs{asio::buffer(current_.header),
                                                   asio::buffer(current_.payload->data(), current_.payload->size())};
      ws_.async_write(bufs, std::move(done));
    } else {
      text_bytes_ -= current_.text.size();
      lock.unlock();
      ws_.text(true);
      ws_.async_write(asio::buffer(current_.text), std::move(done));
    }
  }

  void finish() {
    {
      std::lock_guard lock(mu_);
      if (dead_) return;
      dead_ = true;
      queue_.clear();
    }
    if (added_) shared_.hub.remove_client(id_);
  }

  websocket::stream<beast::tcp_stream> ws_;
  Shared& shared_;
  std::string peer_;
  std::uint64_t id_ = 0;
  bool added_ = false;
  beast::flat_buffer in_;

  mutable std::mutex mu_;  // what follows
  std::deque<Frame> queue_;
  Frame current_;
  std::array<std::byte, 9> time_buf_{};
  std::optional<std::uint64_t> time_;
  std::size_t data_bytes_ = 0, data_frames_ = 0, text_bytes_ = 0;
  std::uint64_t sent_ = 0, dropped_ = 0, warned_ = 0;
  Steady::time_point last_warning_{};
  std::optional<std::uint16_t> close_code_;
  std::string close_why_;
  bool scheduled_ = false, writing_ = false, closing_ = false, dead_ = false;
};

class HttpSession final : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Shared& shared, std::function<void(std::shared_ptr<WsSession>)> keep)
      : stream_(std::move(socket)), shared_(shared), keep_(std::move(keep)) {}

  void read() {
    parser_.emplace();
    parser_->body_limit(64 * 1024);
    parser_->header_limit(16 * 1024);
    stream_.expires_after(std::chrono::seconds(30));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_request(ec); });
  }

 private:
  void on_request(beast::error_code ec) {
    if (ec) {
      if (ec != http::error::end_of_stream) fail_request(ec);
      close();
      return;
    }
    auto req = parser_->release();
    if (websocket::is_upgrade(req)) {
      const auto offered = std::string(req[http::field::sec_websocket_protocol]);
      const std::string_view subprotocol = chosen_subprotocol(offered);
      if (subprotocol.empty()) {
        respond(req, http::status::bad_request, "text/plain",
                fmt::format("a WebSocket here speaks subprotocol {} or {} (Sec-WebSocket-Protocol offered: '{}')\n",
                            kSubprotocol, kSdkSubprotocol, offered),
                false);
        return;
      }
      if (shared_.clients.load() >= shared_.options.max_clients) {
        respond(req, http::status::service_unavailable, "text/plain",
                fmt::format("{} clients are connected, the most this server takes (--max-clients)\n",
                            shared_.options.max_clients),
                false);
        return;
      }
      auto ws = std::make_shared<WsSession>(stream_.release_socket(), shared_);
      keep_(ws);
      ws->accept(std::move(req), subprotocol);
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      respond(req, http::status::method_not_allowed, "text/plain", "only GET\n", req.keep_alive());
      return;
    }
    const auto target = std::string_view(req.target().data(), req.target().size());
    if (target == "/" || target == "/index.html")
      respond(req, http::status::ok, "text/html; charset=utf-8", std::string(status_page_html()), req.keep_alive());
    else if (target == "/status.json")
      respond(req, http::status::ok, "application/json", shared_.hub.status_json(), req.keep_alive());
    else
      respond(req, http::status::not_found, "text/plain",
              fmt::format("{} is not here: / is the status page, /status.json its figures, and a WebSocket with "
                          "subprotocol {} (or {}) is the Foxglove connection\n",
                          target, kSubprotocol, kSdkSubprotocol),
              req.keep_alive());
  }

  void fail_request(beast::error_code ec) {
    if (ec == http::error::body_limit || ec == http::error::header_limit) {
      http::request<http::string_body> dummy;
      respond(dummy, http::status::payload_too_large, "text/plain", "the request is too large\n", false);
    }
  }

  void respond(const http::request<http::string_body>& req, http::status status, std::string_view type,
               std::string body, bool keep_alive) {
    auto res = std::make_shared<http::response<http::string_body>>(status, req.version() ? req.version() : 11);
    res->set(http::field::server, "horus foxglove");
    res->set(http::field::content_type, std::string(type));
    res->set(http::field::cache_control, "no-store");
    res->keep_alive(keep_alive);
    if (req.method() != http::verb::head) res->body() = std::move(body);
    res->prepare_payload();
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec || !res->keep_alive()) {
        self->close();
        return;
      }
      self->read();
    });
  }

  void close() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
  }

  beast::tcp_stream stream_;
  Shared& shared_;
  std::function<void(std::shared_ptr<WsSession>)> keep_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

class ServerImpl final : public Server {
 public:
  ServerImpl(Hub& hub, const ServerOptions& o) : shared_{hub, o, {}}, acceptor_(ioc_) {}

  bool listen(std::string& error) {
    beast::error_code ec;
    const auto address = asio::ip::make_address(shared_.options.address, ec);
    if (ec) {
      error = fmt::format("--address '{}' is not an IP address ({})", shared_.options.address, ec.message());
      return false;
    }
    const tcp::endpoint ep(address, shared_.options.port);
    acceptor_.open(ep.protocol(), ec);
    if (!ec) acceptor_.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor_.bind(ep, ec);
    if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      error = fmt::format("cannot listen on {}:{}: {}", shared_.options.address, shared_.options.port, ec.message());
      return false;
    }
    port_ = acceptor_.local_endpoint().port();
    accept();
    thread_ = std::thread([this] { ioc_.run(); });
    return true;
  }

  ~ServerImpl() override {
    asio::post(ioc_, [this] {
      beast::error_code ec;
      acceptor_.close(ec);
      std::lock_guard lock(mu_);
      for (auto& w : sessions_)
        if (auto s = w.lock()) s->shutdown();
      sessions_.clear();
    });
    // Let the closes go out, then stop.
    asio::post(ioc_, [this] { ioc_.stop(); });
    if (thread_.joinable()) thread_.join();
  }

  std::uint16_t port() const override { return port_; }

 private:
  void accept() {
    acceptor_.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec) return;  // closed
      socket.set_option(tcp::no_delay(true), ec);
      std::make_shared<HttpSession>(std::move(socket), shared_, [this](std::shared_ptr<WsSession> s) {
        std::lock_guard lock(mu_);
        std::erase_if(sessions_, [](const auto& w) { return w.expired(); });
        sessions_.push_back(s);
      })->read();
      accept();
    });
  }

  Shared shared_;
  asio::io_context ioc_{1};
  tcp::acceptor acceptor_;
  std::uint16_t port_ = 0;
  std::mutex mu_;
  std::vector<std::weak_ptr<WsSession>> sessions_;
  std::thread thread_;
};

}  // namespace

std::unique_ptr<Server> Server::start(Hub& hub, const ServerOptions& options, std::string& error) {
  auto s = std::make_unique<ServerImpl>(hub, options);
  if (!s->listen(error)) return nullptr;
  return s;
}

}  // namespace horus::tools::fox
