#include "duet/net/server.h"

#include <algorithm>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/circular_buffer.hpp>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "duet/net/static_files.h"
#include "listen_address.h"

namespace duet::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

namespace server_detail {

constexpr std::size_t kReadChunk = 64 * 1024;
constexpr auto kHttpWriteTimeout = std::chrono::seconds(30);  // sending a response
constexpr auto kWsHandshakeTimeout = std::chrono::seconds(10);
constexpr std::string_view kBusyResponse =
    "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain\r\nContent-Length: 22\r\n"
    "Connection: close\r\n\r\nToo many connections.\n";
constexpr std::string_view kServerName = "duet-serve";

class HttpSession;
class WsSession;

}  // namespace server_detail

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
  Impl(asio::io_context& io_context, ServerOptions server_options, ServerCallbacks server_callbacks)
      : io(io_context),
        acceptor(io_context),
        retry_timer(io_context),
        options(std::move(server_options)),
        callbacks(std::move(server_callbacks)) {}

  void do_accept();

  asio::io_context& io;
  tcp::acceptor acceptor;
  asio::steady_timer retry_timer;  // accept errors (out of file descriptors): retry later
  ServerOptions options;
  ServerCallbacks callbacks;
  std::optional<std::filesystem::path> web_root;
  std::uint16_t port = 0;
  bool stopped = false;

  // Sessions register themselves and leave in their destructors (all on the io thread).
  std::unordered_map<ClientId, server_detail::WsSession*> clients;
  std::unordered_set<server_detail::HttpSession*> http_sessions;
  ClientId next_id = 1;

  int ws_from(const asio::ip::address& address) const;
  int http_from(const asio::ip::address& address) const;

  long long frames_dropped = 0;
  long long messages_dropped = 0;
  LatencyHistogram send_latency;
};

namespace server_detail {

using Request = http::request<http::string_body>;

std::string_view target_path(beast::string_view target) {
  const std::string_view t(target.data(), target.size());
  return t.substr(0, t.find_first_of("?#"));
}

// The value of `key` in the target's query ("/ws?token=abc" -> "abc"), or nullopt.
std::optional<std::string_view> query_value(beast::string_view target, std::string_view key) {
  std::string_view t(target.data(), target.size());
  const std::size_t question = t.find('?');
  if (question == std::string_view::npos) return std::nullopt;
  t = t.substr(question + 1);
  t = t.substr(0, t.find('#'));
  while (!t.empty()) {
    const std::size_t amp = t.find('&');
    const std::string_view pair = t.substr(0, amp);
    const std::size_t eq = pair.find('=');
    if (pair.substr(0, eq) == key)
      return eq == std::string_view::npos ? std::string_view() : pair.substr(eq + 1);
    if (amp == std::string_view::npos) break;
    t = t.substr(amp + 1);
  }
  return std::nullopt;
}

// Compares in time independent of where the first difference is (the token is a secret).
bool same_secret(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(s));
}

constexpr std::string_view kPlaceholderPage = R"(<!doctype html>
<html><head><meta charset="utf-8"><title>duet serve</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>duet serve is running</h1>
<p>The viewer is not built, or <code>--web</code> points nowhere. Build it with
<code>cd web &amp;&amp; npm ci &amp;&amp; npm run build</code> and start
<code>duet serve</code> again (it looks for <code>web/dist</code>), or pass
<code>--web DIR</code>.</p>
<p>The WebSocket protocol (docs/protocol.md) is served at <code>/ws</code> all the same.</p>
</body></html>
)";

// One viewer (or pose sender) on /ws.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket&& socket, std::shared_ptr<Server::Impl> server, asio::ip::address remote)
      : ws_(std::move(socket)),
        server_(std::move(server)),
        remote_(std::move(remote)),
        buffer_(server_->options.max_message_bytes + 2 * kReadChunk) {}
  ~WsSession() {
    if (id_ != 0) server_->clients.erase(id_);
  }

  void run(Request request) {
    request_ = std::move(request);
    const std::string& token = server_->options.control_token;
    control_ =
        token.empty() || same_secret(query_value(request_.target(), "token").value_or(""), token);
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().set_option(tcp::no_delay(true), ec);
    // Idle: a ping after half the timeout without input, closed after all of it. A browser
    // answers pings, so only a client that stopped reading (or vanished) is closed.
    websocket::stream_base::timeout timeout{};
    timeout.handshake_timeout = kWsHandshakeTimeout;
    timeout.idle_timeout = seconds(server_->options.ws_idle_timeout_s);
    timeout.keep_alive_pings = true;
    ws_.set_option(timeout);
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& response) {
      response.set(http::field::server, kServerName);
    }));
    // The size limit is enforced here (on_read) so an oversized message is refused without
    // closing the connection; Beast's own limit would fail the connection.
    ws_.read_message_max(0);
    ws_.auto_fragment(false);
    ws_.async_accept(request_, [self = shared_from_this()](beast::error_code accept_ec) {
      self->on_accept(accept_ec);
    });
  }

  void enqueue(std::shared_ptr<const std::string> message, bool frame,
               SteadyClock::time_point arrival) {
    if (closed_) return;
    if (frame) {
      // Behind: the oldest queued frame goes (newer motion supersedes it).
      if (frames_.full()) ++server_->frames_dropped;
      frames_.push_back({std::move(message), true, arrival});
    } else {
      if (messages_.full()) {
        ++server_->messages_dropped;
        return;
      }
      messages_.push_back({std::move(message), false, arrival});
    }
    if (!writing_) do_write();
  }

  void close() {
    closed_ = true;
    frames_.clear();
    messages_.clear();
    beast::get_lowest_layer(ws_).close();
  }

  // Shutdown: a close frame 1001 "going away" (after the write in progress, if any), so browsers
  // see a clean close instead of 1006.
  void go_away() {
    if (closed_) return;
    closed_ = true;
    frames_.clear();
    messages_.clear();
    if (writing_) {
      close_after_write_ = true;
      return;
    }
    send_close();
  }

  bool may_control() const { return control_; }
  const asio::ip::address& remote() const { return remote_; }

  bool stalled(SteadyClock::time_point now) const {
    return writing_ && std::chrono::duration<double>(now - write_started_).count() >
                           server_->options.write_timeout_s;
  }

 private:
  struct Outgoing {
    std::shared_ptr<const std::string> text;
    bool frame = false;
    SteadyClock::time_point arrival{};
  };

  void send_close() {
    ws_.async_close(websocket::close_reason(websocket::close_code::going_away, "server stopping"),
                    [self = shared_from_this()](beast::error_code) {
                      beast::get_lowest_layer(self->ws_).close();
                    });
  }

  void on_accept(beast::error_code ec) {
    if (ec || server_->stopped) return;
    id_ = server_->next_id++;
    server_->clients[id_] = this;
    if (server_->callbacks.hello) {
      if (auto hello = server_->callbacks.hello()) enqueue(std::move(hello), false, {});
    }
    do_read();
  }

  void do_read() {
    ws_.async_read_some(
        buffer_, kReadChunk,
        [self = shared_from_this()](beast::error_code ec, std::size_t n) { self->on_read(ec, n); });
  }

  void on_read(beast::error_code ec, std::size_t n) {
    if (ec) {
      // Closed by the peer, a broken connection, or stop(): whatever was half-received is gone
      // with this client and touches no one else. A protocol violation (a text message that is
      // not UTF-8, an unmasked frame, ...) fails the connection as RFC 6455 requires; it is
      // counted with the rejected messages.
      const bool violation =
          ec.category() == websocket::make_error_code(websocket::error::closed).category() &&
          ec != websocket::error::closed;
      close();
      if (violation) reject("WebSocket protocol error (" + ec.message() + "): connection closed");
      return;
    }
    message_bytes_ += n;
    if (message_bytes_ > server_->options.max_message_bytes) {
      oversized_ = true;  // keep reading (and discarding) to the end of the message
      buffer_.clear();
    }
    if (ws_.is_message_done()) {
      if (oversized_) {
        reject("message larger than " + std::to_string(server_->options.max_message_bytes) +
               " bytes");
      } else if (!ws_.got_text()) {
        reject("binary messages are not part of the protocol");
      } else if (server_->callbacks.on_text) {
        const auto data = buffer_.cdata();
        server_->callbacks.on_text(
            id_, std::string_view(static_cast<const char*>(data.data()), data.size()));
      }
      buffer_.clear();
      message_bytes_ = 0;
      oversized_ = false;
    }
    if (!closed_) do_read();
  }

  void reject(const std::string& reason) {
    if (server_->callbacks.on_rejected) server_->callbacks.on_rejected(id_, reason);
  }

  void do_write() {
    // Other messages first: hello must precede the first frame; stats and errors are rare.
    boost::circular_buffer<Outgoing>& queue = messages_.empty() ? frames_ : messages_;
    current_ = std::move(queue.front());
    queue.pop_front();
    writing_ = true;
    write_started_ = SteadyClock::now();
    ws_.text(true);
    ws_.async_write(
        asio::buffer(*current_.text),
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_write(ec); });
  }

  void on_write(beast::error_code ec) {
    writing_ = false;
    if (ec) {
      close();
      return;
    }
    if (close_after_write_) {
      close_after_write_ = false;
      send_close();
      return;
    }
    if (current_.frame) {
      const auto us = std::chrono::duration_cast<std::chrono::microseconds>(SteadyClock::now() -
                                                                            current_.arrival);
      server_->send_latency.record(us.count());
    }
    current_.text.reset();
    if ((!frames_.empty() || !messages_.empty()) && !closed_) do_write();
  }

  websocket::stream<beast::tcp_stream> ws_;
  std::shared_ptr<Server::Impl> server_;
  asio::ip::address remote_;
  bool control_ = true;
  bool close_after_write_ = false;
  Request request_;
  beast::flat_buffer buffer_;
  std::size_t message_bytes_ = 0;
  bool oversized_ = false;
  ClientId id_ = 0;
  bool closed_ = false;
  // Sized once: queuing allocates nothing.
  boost::circular_buffer<Outgoing> frames_{
      static_cast<std::size_t>(std::max(server_->options.max_queued_frames, 1))};
  boost::circular_buffer<Outgoing> messages_{
      static_cast<std::size_t>(std::max(server_->options.max_queued_messages, 1))};
  bool writing_ = false;
  Outgoing current_;
  SteadyClock::time_point write_started_{};
};

// Plain HTTP: static files, the placeholder page, and the upgrade to a WebSocket at /ws.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, std::shared_ptr<Server::Impl> server, asio::ip::address remote)
      : stream_(std::move(socket)), server_(std::move(server)), remote_(std::move(remote)) {
    server_->http_sessions.insert(this);
  }
  ~HttpSession() { server_->http_sessions.erase(this); }

  void run() { do_read(); }
  void close() { stream_.close(); }
  const asio::ip::address& remote() const { return remote_; }

 private:
  void do_read() {
    parser_.emplace();
    parser_->header_limit(16 * 1024);
    parser_->body_limit(64 * 1024);
    // Covers a keep-alive connection waiting for its next request: idle ones do not pile up.
    stream_.expires_after(seconds(server_->options.http_idle_timeout_s));
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec || server_->stopped) {
      // End of stream, timeout, or a request we cannot parse (too large, malformed): close.
      close();
      return;
    }
    const Request& request = parser_->get();
    if (websocket::is_upgrade(request)) {
      if (target_path(request.target()) != "/ws") {
        send_text(request, http::status::not_found, "No WebSocket here: connect to /ws.\n");
        return;
      }
      if (static_cast<int>(server_->clients.size()) >= server_->options.max_clients) {
        send_text(request, http::status::service_unavailable, "Too many clients.\n");
        return;
      }
      if (server_->ws_from(remote_) >= server_->options.max_clients_per_address) {
        send_text(request, http::status::service_unavailable,
                  "Too many clients from this address.\n");
        return;
      }
      stream_.expires_never();
      std::make_shared<WsSession>(stream_.release_socket(), server_, remote_)
          ->run(parser_->release());
      return;
    }
    handle(request);
  }

  void handle(const Request& request) {
    const bool head = request.method() == http::verb::head;
    if (request.method() != http::verb::get && !head) {
      http::response<http::string_body> response{http::status::method_not_allowed,
                                                 request.version()};
      response.set(http::field::allow, "GET, HEAD");
      fill_text(response, request, "Only GET and HEAD.\n");
      send(std::move(response));
      return;
    }
    if (!server_->web_root) {
      const std::string_view path = target_path(request.target());
      if (path == "/" || path == "/index.html") {
        send_body(request, head, std::string(kPlaceholderPage), "text/html; charset=utf-8");
      } else {
        send_text(request, http::status::not_found, "Not found.\n");
      }
      return;
    }
    const StaticFile file = find_static_file(
        *server_->web_root, std::string_view(request.target().data(), request.target().size()));
    if (file.status == StaticLookup::kBadTarget) {
      send_text(request, http::status::bad_request, "Bad path.\n");
      return;
    }
    beast::error_code ec;
    http::file_body::value_type body;
    if (file.status == StaticLookup::kFound)
      body.open(file.path.c_str(), beast::file_mode::scan, ec);
    if (file.status != StaticLookup::kFound || ec) {
      send_text(request, http::status::not_found, "Not found.\n");
      return;
    }
    const std::uint64_t size = body.size();
    const std::string_view type = content_type_for(file.path);
    if (head) {
      http::response<http::empty_body> response{http::status::ok, request.version()};
      set_common_headers(response, request, type);
      response.content_length(size);
      send(std::move(response));
      return;
    }
    http::response<http::file_body> response{std::piecewise_construct,
                                             std::make_tuple(std::move(body)),
                                             std::make_tuple(http::status::ok, request.version())};
    set_common_headers(response, request, type);
    response.content_length(size);
    send(std::move(response));
  }

  template <class Body>
  static void set_common_headers(http::response<Body>& response, const Request& request,
                                 std::string_view type) {
    response.set(http::field::server, kServerName);
    response.set(http::field::content_type, type);
    response.set(http::field::cache_control, "no-cache");
    response.set("X-Content-Type-Options", "nosniff");
    response.keep_alive(request.keep_alive());
  }

  static void fill_text(http::response<http::string_body>& response, const Request& request,
                        std::string text) {
    set_common_headers(response, request, "text/plain; charset=utf-8");
    response.body() = std::move(text);
    response.prepare_payload();
  }

  void send_text(const Request& request, http::status status, std::string text) {
    http::response<http::string_body> response{status, request.version()};
    fill_text(response, request, std::move(text));
    send(std::move(response));
  }

  void send_body(const Request& request, bool head, std::string body, std::string_view type) {
    http::response<http::string_body> response{http::status::ok, request.version()};
    set_common_headers(response, request, type);
    const std::size_t size = body.size();
    if (!head) response.body() = std::move(body);
    response.prepare_payload();
    if (head) response.content_length(size);
    send(std::move(response));
  }

  template <class Body>
  void send(http::response<Body>&& response) {
    auto message = std::make_shared<http::response<Body>>(std::move(response));
    stream_.expires_after(kHttpWriteTimeout);
    http::async_write(stream_, *message,
                      [self = shared_from_this(), message](beast::error_code ec, std::size_t) {
                        if (ec || message->need_eof() || self->server_->stopped) {
                          self->close();
                          return;
                        }
                        self->do_read();
                      });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_{16 * 1024};
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<Server::Impl> server_;
  asio::ip::address remote_;
};

}  // namespace server_detail

void Server::Impl::do_accept() {
  acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
    if (self->stopped || ec == asio::error::operation_aborted) return;
    if (ec) {
      // Out of descriptors or a transient failure: try again shortly, without spinning.
      self->retry_timer.expires_after(std::chrono::milliseconds(100));
      self->retry_timer.async_wait([self](beast::error_code wait_ec) {
        if (!wait_ec && !self->stopped) self->do_accept();
      });
      return;
    }
    beast::error_code option_ec;
    const asio::ip::address remote = socket.remote_endpoint(option_ec).address();
    if (option_ec) {
      self->do_accept();  // already gone
      return;
    }
    if (static_cast<int>(self->http_sessions.size()) >= self->options.max_http_connections ||
        self->http_from(remote) >= self->options.max_http_per_address) {
      // Over a cap: a short 503 into the empty send buffer (never blocks), then close.
      socket.non_blocking(true, option_ec);
      socket.write_some(asio::buffer(server_detail::kBusyResponse), option_ec);
      socket.shutdown(tcp::socket::shutdown_both, option_ec);
      socket.close(option_ec);
      self->do_accept();
      return;
    }
    socket.set_option(tcp::no_delay(true), option_ec);
    std::make_shared<server_detail::HttpSession>(std::move(socket), self, remote)->run();
    self->do_accept();
  });
}

int Server::Impl::ws_from(const asio::ip::address& address) const {
  int n = 0;
  for (const auto& [id, session] : clients) n += session->remote() == address ? 1 : 0;
  return n;
}

int Server::Impl::http_from(const asio::ip::address& address) const {
  int n = 0;
  for (const server_detail::HttpSession* session : http_sessions)
    n += session->remote() == address ? 1 : 0;
  return n;
}

Server::Server(asio::io_context& io, ServerOptions options, ServerCallbacks callbacks)
    : impl_(std::make_shared<Impl>(io, std::move(options), std::move(callbacks))) {}

Server::~Server() { stop(); }

Status Server::start() {
  Impl& s = *impl_;
  const std::string where = s.options.address + ":" + std::to_string(s.options.port);
  beast::error_code ec;
  const std::optional<asio::ip::address> address = listen_address(s.options.address);
  if (!address) return Error{"--http " + where + ": not an IP address"};
  const tcp::endpoint endpoint(*address, s.options.port);
  auto fail = [&](const char* what) {
    // The reason first: closing the acceptor resets `ec` ("cannot bind: Success").
    std::string reason = ec.message();
    if (ec == asio::error::address_in_use) {
      reason += " (another program, or another duet serve, listens on this port)";
    } else if (ec == boost::system::errc::address_not_available) {
      reason += " (not an address of this machine)";
    }
    beast::error_code close_ec;
    s.acceptor.close(close_ec);
    return Error{"--http " + where + ": cannot " + what + ": " + reason};
  };
  s.acceptor.open(endpoint.protocol(), ec);
  if (ec) return fail("open a socket");
  s.acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (ec) return fail("set SO_REUSEADDR");
  s.acceptor.bind(endpoint, ec);
  if (ec) return fail("bind");
  s.acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return fail("listen");
  s.port = s.acceptor.local_endpoint(ec).port();
  if (!s.options.web_dir.empty()) s.web_root = canonical_web_root(s.options.web_dir);
  s.do_accept();
  return Ok{};
}

void Server::stop() {
  Impl& s = *impl_;
  if (s.stopped) return;
  s.stopped = true;
  beast::error_code ec;
  s.acceptor.close(ec);
  s.retry_timer.cancel();
  std::vector<server_detail::WsSession*> clients;
  for (auto& [id, session] : s.clients) clients.push_back(session);
  for (server_detail::WsSession* session : clients) session->go_away();
  const std::vector<server_detail::HttpSession*> https(s.http_sessions.begin(),
                                                       s.http_sessions.end());
  for (server_detail::HttpSession* session : https) session->close();
}

std::uint16_t Server::port() const { return impl_->port; }

const std::filesystem::path* Server::web_root() const {
  return impl_->web_root ? &*impl_->web_root : nullptr;
}

void Server::broadcast_frame(std::shared_ptr<const std::string> message,
                             SteadyClock::time_point arrival) {
  for (auto& [id, session] : impl_->clients) session->enqueue(message, true, arrival);
}

void Server::broadcast(std::shared_ptr<const std::string> message) {
  for (auto& [id, session] : impl_->clients) session->enqueue(message, false, {});
}

void Server::send(ClientId client, std::shared_ptr<const std::string> message) {
  const auto it = impl_->clients.find(client);
  if (it != impl_->clients.end()) it->second->enqueue(std::move(message), false, {});
}

void Server::close_stalled_clients() {
  const auto now = SteadyClock::now();
  std::vector<server_detail::WsSession*> stalled;
  for (auto& [id, session] : impl_->clients) {
    if (session->stalled(now)) stalled.push_back(session);
  }
  for (server_detail::WsSession* session : stalled) session->close();
}

int Server::client_count() const { return static_cast<int>(impl_->clients.size()); }
int Server::connection_count() const {
  return static_cast<int>(impl_->clients.size() + impl_->http_sessions.size());
}
bool Server::may_control(ClientId client) const {
  const auto it = impl_->clients.find(client);
  return it != impl_->clients.end() && it->second->may_control();
}
long long Server::frames_dropped() const { return impl_->frames_dropped; }
long long Server::messages_dropped() const { return impl_->messages_dropped; }
LatencyHistogram& Server::send_latency() { return impl_->send_latency; }

}  // namespace duet::net
