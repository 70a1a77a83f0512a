// The HTTP + WebSocket server of `duet serve`: static files of the viewer over HTTP, the protocol
// of docs/protocol.md over a WebSocket at /ws, on one port.
//
// Threading: everything runs on the thread that runs the io_context (one thread); the callbacks
// are called there, and every method must be called there too (post to the io_context from other
// threads).
//
// Back-pressure: each client has a bounded queue. A frame message waits for at most
// `max_queued_frames` frames ahead of it; beyond that the client's oldest queued frame is dropped
// (counted), so a slow client sees gaps in `seq` and the loop never waits for it. Other messages
// (hello, stats, error) are bounded separately. A write that does not complete within
// `write_timeout_s` closes the connection.
//
// Limits (so that no one viewer, or one address, can lock the others out or exhaust descriptors):
// WebSocket clients and plain HTTP connections are capped globally and per remote address, idle
// HTTP connections are closed after `http_idle_timeout_s`, WebSocket clients that answer no ping
// for `ws_idle_timeout_s`. With a `control_token`, only clients that connected with
// `/ws?token=...` may send messages (Server::may_control); the others can watch.
#pragma once

#include <boost/asio/io_context.hpp>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "duet/base/result.h"
#include "duet/live/source_frame.h"
#include "duet/net/latency_histogram.h"
#include "duet/net/protocol.h"

namespace duet::net {

using ClientId = std::uint64_t;

struct ServerOptions {
  std::string address = "127.0.0.1";  // loopback unless told otherwise
  std::uint16_t port = 8080;          // 0: any free port (see Server::port())
  std::filesystem::path web_dir;      // the viewer's files; empty or missing: a placeholder page
  std::size_t max_message_bytes = kMaxClientMessageBytes;
  int max_queued_frames = 2;         // per client, besides the one being written
  int max_queued_messages = 32;      // per client: hello, stats, error replies
  int max_clients = 64;              // WebSocket connections; more are refused with 503
  int max_clients_per_address = 16;  // WebSocket connections from one remote address (503)
  int max_http_connections = 256;    // plain HTTP connections; more get 503 and are closed
  int max_http_per_address = 32;     // plain HTTP connections from one remote address
  double write_timeout_s = 10.0;
  double http_idle_timeout_s = 15.0;  // waiting for (the rest of) a request
  // Nothing received for half of it: a ping; for all of it: closed (browsers answer pings).
  double ws_idle_timeout_s = 30.0;
  // Non-empty: clients must connect to /ws?token=<control_token> to send messages.
  std::string control_token;
};

struct ServerCallbacks {
  // The hello message for a new client (sent before anything else).
  std::function<std::shared_ptr<const std::string>()> hello;
  // A complete text message of at most max_message_bytes.
  std::function<void(ClientId, std::string_view text)> on_text;
  // A message the server refused before parsing (too large, binary). The connection stays open.
  std::function<void(ClientId, std::string_view reason)> on_rejected;
};

class Server {
 public:
  Server(boost::asio::io_context& io, ServerOptions options, ServerCallbacks callbacks);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens. Errors name the address and the reason ("address in use").
  Status start();
  // Closes the listener and the HTTP connections, and sends every WebSocket client a close frame
  // (1001 "going away") once its current write is done. Keep running the io_context until
  // connection_count() is 0 (or a deadline) for the close frames to go out.
  void stop();
  int connection_count() const;  // WebSocket + HTTP connections still open

  std::uint16_t port() const;
  const std::filesystem::path* web_root() const;  // null when serving the placeholder

  void broadcast_frame(std::shared_ptr<const std::string> message, SteadyClock::time_point arrival);
  void broadcast(std::shared_ptr<const std::string> message);
  void send(ClientId client, std::shared_ptr<const std::string> message);

  // Closes connections whose current write has not completed within the write timeout.
  void close_stalled_clients();

  int client_count() const;
  // Whether this client may send messages (no control token, or it connected with the token).
  bool may_control(ClientId client) const;
  long long frames_dropped() const;    // frame messages dropped for slow clients
  long long messages_dropped() const;  // other messages dropped (a client that never reads)
  // arrival -> write completed, one sample per frame message per client. The owner reads and
  // clears it (e.g. once a second).
  LatencyHistogram& send_latency();

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace duet::net
