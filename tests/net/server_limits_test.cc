// The server's limits on its own (no loop, no source): per-address and global caps, idle
// timeouts, the control token, the close frame on stop. Loopback only; 127.0.0.2 stands in for
// a second machine (all of 127/8 is loopback on Linux).
#include <gtest/gtest.h>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>
#include <future>
#include <mutex>

#include "duet/net/server.h"
#include "serve_support.h"

namespace duet::test {
namespace {

using net::ClientId;
using net::Server;
using net::ServerOptions;

// A Server running on its own io thread; every call goes through post() (the server's rule).
class TestServer {
 public:
  explicit TestServer(ServerOptions options) {
    options.address = "127.0.0.1";
    options.port = 0;
    net::ServerCallbacks callbacks;
    callbacks.hello = [] { return std::make_shared<const std::string>(R"({"type":"hello"})"); };
    callbacks.on_text = [this](ClientId id, std::string_view text) {
      const bool control = server_->may_control(id);
      std::lock_guard lock(mutex_);
      texts_.push_back({std::string(text), control});
    };
    server_ = std::make_unique<Server>(io_, std::move(options), std::move(callbacks));
    started_ = static_cast<bool>(server_->start());
    thread_ = std::thread([this] { io_.run(); });
  }
  ~TestServer() {
    call([this] {
      server_->stop();
      return 0;
    });
    io_.stop();
    thread_.join();
  }

  bool started() const { return started_; }
  std::uint16_t port() const { return server_->port(); }

  template <class F>
  auto call(F f) -> decltype(f()) {
    std::packaged_task<decltype(f())()> task(std::move(f));
    auto result = task.get_future();
    boost::asio::post(io_, [&task] { task(); });
    result.wait_for(20s);
    return result.get();
  }

  int clients() {
    return call([this] { return server_->client_count(); });
  }

  // Polls until `pred` holds or `timeout` passes.
  template <class P>
  bool eventually(P pred, std::chrono::milliseconds timeout = 30s) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (pred()) return true;
      std::this_thread::sleep_for(20ms);
    }
    return pred();
  }

  std::vector<std::pair<std::string, bool>> texts() {
    std::lock_guard lock(mutex_);
    return texts_;
  }

  Server& server() { return *server_; }

 private:
  asio::io_context io_{1};
  // Keeps run() going when the server has nothing left to do (after stop()), so call() works.
  asio::executor_work_guard<asio::io_context::executor_type> work_{io_.get_executor()};
  std::unique_ptr<Server> server_;
  bool started_ = false;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::pair<std::string, bool>> texts_;
};

bool can_bind(const std::string& address) {
  asio::io_context io;
  tcp::socket socket(io);
  beast::error_code ec;
  socket.open(tcp::v4(), ec);
  if (!ec) socket.bind(tcp::endpoint(asio::ip::make_address(address), 0), ec);
  return !ec;
}

// A plain TCP connection from `from` that sends nothing.
std::unique_ptr<tcp::socket> raw_connect(asio::io_context& io, std::uint16_t port,
                                         const std::string& from = "127.0.0.1") {
  auto socket = std::make_unique<tcp::socket>(io);
  beast::error_code ec;
  socket->open(tcp::v4(), ec);
  if (!ec) socket->bind(tcp::endpoint(asio::ip::make_address(from), 0), ec);
  if (!ec) socket->connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port), ec);
  if (ec) return nullptr;
  return socket;
}

// What the server sends on `socket` until it closes it, or nullopt if it is still open after
// `timeout`.
std::optional<std::string> read_until_closed(tcp::socket& socket,
                                             std::chrono::milliseconds timeout = 30s) {
  std::string text;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd p{socket.native_handle(), POLLIN, 0};
    if (::poll(&p, 1, 50) <= 0) continue;
    char buffer[512];
    const ssize_t n = ::recv(socket.native_handle(), buffer, sizeof buffer, 0);
    if (n <= 0) return text;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return std::nullopt;
}

// The raw text is one whole HTTP response (its Content-Length matches its body).
bool complete_response(const std::string& text) {
  http::response_parser<http::string_body> parser;
  parser.eager(true);
  beast::error_code ec;
  const std::size_t used = parser.put(asio::buffer(text), ec);
  return !ec && used == text.size() && parser.is_done() &&
         parser.get().body() == "Too many connections.\n";
}

TEST(ServerLimits, WebSocketCapsPerAddressAndGlobal) {
  if (!can_bind("127.0.0.2") || !can_bind("127.0.0.3")) GTEST_SKIP() << "no 127.0.0.2";
  ServerOptions options;
  options.max_clients = 4;
  options.max_clients_per_address = 2;
  TestServer server(options);
  ASSERT_TRUE(server.started());
  std::vector<std::unique_ptr<WsClient>> clients;
  auto connect = [&](const std::string& from) {
    clients.push_back(std::make_unique<WsClient>());
    return clients.back()->connect(server.port(), "/ws", from);
  };
  EXPECT_TRUE(connect("127.0.0.1"));
  EXPECT_TRUE(connect("127.0.0.1"));
  EXPECT_FALSE(connect("127.0.0.1"));  // a third from the same address: 503
  EXPECT_TRUE(connect("127.0.0.2"));   // another address is not locked out
  EXPECT_TRUE(connect("127.0.0.2"));
  EXPECT_FALSE(connect("127.0.0.3"));  // the global cap
  EXPECT_EQ(server.clients(), 4);
  // A slot freed is a slot for the next one.
  clients[0]->drop();
  ASSERT_TRUE(server.eventually([&] { return server.clients() == 3; }));
  EXPECT_TRUE(connect("127.0.0.1"));
}

TEST(ServerLimits, HttpCapsPerAddressAndGlobalAnswer503) {
  if (!can_bind("127.0.0.2") || !can_bind("127.0.0.3")) GTEST_SKIP() << "no 127.0.0.2";
  ServerOptions options;
  options.max_http_connections = 5;
  options.max_http_per_address = 3;
  TestServer server(options);
  ASSERT_TRUE(server.started());
  asio::io_context io;
  std::vector<std::unique_ptr<tcp::socket>> idle;
  for (int k = 0; k < 3; ++k) idle.push_back(raw_connect(io, server.port(), "127.0.0.1"));
  for (const auto& s : idle) ASSERT_TRUE(s);
  auto over = raw_connect(io, server.port(), "127.0.0.1");
  ASSERT_TRUE(over);
  const std::optional<std::string> refused = read_until_closed(*over);
  ASSERT_TRUE(refused);
  EXPECT_TRUE(refused->starts_with("HTTP/1.1 503")) << *refused;
  EXPECT_TRUE(complete_response(*refused)) << *refused;
  // The idle ones are still open, and another address still gets in, up to the global cap.
  for (int k = 0; k < 2; ++k) idle.push_back(raw_connect(io, server.port(), "127.0.0.2"));
  auto third = raw_connect(io, server.port(), "127.0.0.3");
  ASSERT_TRUE(third);
  const std::optional<std::string> global = read_until_closed(*third);
  ASSERT_TRUE(global);
  EXPECT_TRUE(global->starts_with("HTTP/1.1 503")) << *global;
  EXPECT_FALSE(read_until_closed(*idle[0], 200ms)) << "an accepted connection was closed";
  // Closing the idle ones lets requests through again.
  idle.clear();
  std::optional<HttpReply> reply;
  ASSERT_TRUE(server.eventually([&] {
    reply = http_request(server.port(), http::verb::get, "/");
    return reply && reply->status == 200;
  }));
}

TEST(ServerLimits, IdleHttpConnectionsAreClosed) {
  ServerOptions options;
  options.http_idle_timeout_s = 1.0;
  TestServer server(options);
  ASSERT_TRUE(server.started());
  asio::io_context io;
  auto socket = raw_connect(io, server.port());
  ASSERT_TRUE(socket);
  const auto start = std::chrono::steady_clock::now();
  const std::optional<std::string> closed = read_until_closed(*socket);
  ASSERT_TRUE(closed) << "an idle connection stayed open for 30 s";
  EXPECT_TRUE(closed->empty()) << *closed;
  EXPECT_GE(std::chrono::steady_clock::now() - start, 900ms);  // not before the timeout
}

TEST(ServerLimits, WebSocketClientsThatAnswerNoPingAreClosed) {
  ServerOptions options;
  options.ws_idle_timeout_s = 4.0;
  TestServer server(options);
  ASSERT_TRUE(server.started());
  // `silent` never reads, so it never answers the server's pings; `live` keeps a read pending
  // (Beast answers pings while reading), as a browser does.
  WsClient silent, live;
  ASSERT_TRUE(silent.connect(server.port()));
  ASSERT_TRUE(live.connect(server.port()));
  ASSERT_TRUE(live.read_text());  // hello
  beast::flat_buffer buffer;
  beast::error_code live_result = asio::error::would_block;
  int pings = 0;
  live.stream().control_callback([&](websocket::frame_type kind, beast::string_view) {
    if (kind == websocket::frame_type::ping) ++pings;
  });
  live.stream().async_read(buffer, [&](beast::error_code ec, std::size_t) { live_result = ec; });
  live.io().restart();
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (server.clients() > 1 && std::chrono::steady_clock::now() < deadline)
    live.io().run_for(50ms);
  EXPECT_EQ(server.clients(), 1) << "the silent client was not closed";
  live.io().run_for(6s);  // beyond another idle timeout: pings answered, still open
  EXPECT_GE(pings, 1);
#ifndef DUET_SANITIZED
  // A pong has 2 s to come back; a sanitizer build on a loaded machine may take longer.
  EXPECT_EQ(live_result, asio::error::would_block) << live_result.message();
  EXPECT_EQ(server.clients(), 1);
#endif
}

TEST(ServerLimits, ControlTokenSeparatesWatchersFromControllers) {
  ServerOptions options;
  options.control_token = "s3cret";
  TestServer server(options);
  ASSERT_TRUE(server.started());
  WsClient with, without, wrong;
  ASSERT_TRUE(with.connect(server.port(), "/ws?x=1&token=s3cret"));
  ASSERT_TRUE(without.connect(server.port(), "/ws"));
  ASSERT_TRUE(wrong.connect(server.port(), "/ws?token=s3cres"));
  ASSERT_TRUE(with.write(R"({"n":1})"));
  ASSERT_TRUE(server.eventually([&] { return server.texts().size() == 1; }));
  ASSERT_TRUE(without.write(R"({"n":2})"));
  ASSERT_TRUE(server.eventually([&] { return server.texts().size() == 2; }));
  ASSERT_TRUE(wrong.write(R"({"n":3})"));
  ASSERT_TRUE(server.eventually([&] { return server.texts().size() == 3; }));
  const auto texts = server.texts();
  EXPECT_TRUE(texts[0].second);
  EXPECT_FALSE(texts[1].second);
  EXPECT_FALSE(texts[2].second);
}

TEST(ServerLimits, StopSendsGoingAway) {
  TestServer server(ServerOptions{});
  ASSERT_TRUE(server.started());
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port()));
  ASSERT_TRUE(viewer.read_text());  // hello
  server.call([&] {
    server.server().stop();
    return 0;
  });
  EXPECT_FALSE(viewer.read_text(20s));  // the read ends with the close
  EXPECT_EQ(viewer.stream().reason().code, websocket::close_code::going_away);
  EXPECT_TRUE(server.eventually(
      [&] { return server.call([&] { return server.server().connection_count(); }) == 0; }));
}

}  // namespace
}  // namespace duet::test
