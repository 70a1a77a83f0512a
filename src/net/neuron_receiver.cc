#include "duet/net/neuron_receiver.h"

#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "listen_address.h"

namespace duet::net {

namespace asio = boost::asio;
using boost::system::error_code;

namespace {

constexpr std::size_t kBufferBytes = 64 * 1024;

struct Shared {
  NeuronSource* source = nullptr;
  NeuronReceiver::OnInput on_input;
  NeuronReceiver::Log log;
  bool stopped = false;

  void feed(const char* data, std::size_t n) {
    const auto arrival = SteadyClock::now();
    source->feed(std::string_view(data, n), arrival);
  }
};

class TcpReceiver final : public NeuronReceiver {
 public:
  struct State : std::enable_shared_from_this<State>, Shared {
    State(asio::io_context& io, std::string h, std::uint16_t p)
        : resolver(io), socket(io), retry(io), host(std::move(h)), port(p) {}

    void connect() {
      if (stopped) return;
      resolver.async_resolve(
          host, std::to_string(port),
          [self = shared_from_this()](error_code ec, asio::ip::tcp::resolver::results_type r) {
            if (self->stopped) return;
            if (ec) return self->fail("cannot resolve", ec);
            asio::async_connect(self->socket, r,
                                [self](error_code connect_ec, const asio::ip::tcp::endpoint&) {
                                  if (self->stopped) return;
                                  if (connect_ec) return self->fail("cannot connect", connect_ec);
                                  self->failing = false;
                                  error_code option_ec;
                                  self->socket.set_option(asio::ip::tcp::no_delay(true), option_ec);
                                  self->log("neuron-tcp: connected to " + self->where());
                                  self->read();
                                });
          });
    }

    void read() {
      socket.async_read_some(asio::buffer(buffer),
                             [self = shared_from_this()](error_code ec, std::size_t n) {
                               if (self->stopped) return;
                               if (ec) {
                                 // A record cut by the close is not a frame.
                                 self->source->end_record(SteadyClock::now());
                                 return self->fail("connection lost", ec);
                               }
                               self->feed(self->buffer.data(), n);
                               if (self->on_input) self->on_input();
                               self->read();
                             });
    }

    void fail(const char* what, error_code ec) {
      // Log the first failure of a series, not one line per retry.
      if (!failing)
        log("neuron-tcp: " + where() + ": " + what + ": " + ec.message() +
            "; retrying every second");
      failing = true;
      error_code close_ec;
      socket.close(close_ec);
      retry.expires_after(std::chrono::seconds(1));
      retry.async_wait([self = shared_from_this()](error_code wait_ec) {
        if (!wait_ec) self->connect();
      });
    }

    std::string where() const { return host + ":" + std::to_string(port); }

    asio::ip::tcp::resolver resolver;
    asio::ip::tcp::socket socket;
    asio::steady_timer retry;
    std::string host;
    std::uint16_t port;
    bool failing = false;
    std::array<char, kBufferBytes> buffer{};
  };

  explicit TcpReceiver(std::shared_ptr<State> state) : state_(std::move(state)) {}
  ~TcpReceiver() override { stop(); }

  void stop() override {
    State& s = *state_;
    if (s.stopped) return;
    s.stopped = true;
    error_code ec;
    s.resolver.cancel();
    s.retry.cancel();
    s.socket.close(ec);
  }

 private:
  std::shared_ptr<State> state_;
};

class UdpReceiver final : public NeuronReceiver {
 public:
  struct State : std::enable_shared_from_this<State>, Shared {
    explicit State(asio::io_context& io) : socket(io) {}

    void receive() {
      socket.async_receive_from(asio::buffer(buffer), sender,
                                [self = shared_from_this()](error_code ec, std::size_t n) {
                                  if (self->stopped || ec == asio::error::operation_aborted) return;
                                  if (!ec) {
                                    self->feed(self->buffer.data(), n);
                                    // A datagram is whole: its last record ends with it.
                                    self->source->end_record(SteadyClock::now());
                                    if (self->on_input) self->on_input();
                                  }
                                  self->receive();
                                });
    }

    asio::ip::udp::socket socket;
    asio::ip::udp::endpoint sender;
    std::array<char, kBufferBytes> buffer{};
  };

  explicit UdpReceiver(std::shared_ptr<State> state) : state_(std::move(state)) {}
  ~UdpReceiver() override { stop(); }

  void stop() override {
    if (state_->stopped) return;
    state_->stopped = true;
    error_code ec;
    state_->socket.close(ec);
  }

 private:
  std::shared_ptr<State> state_;
};

}  // namespace

std::unique_ptr<NeuronReceiver> NeuronReceiver::connect_tcp(asio::io_context& io, std::string host,
                                                            std::uint16_t port,
                                                            NeuronSource& source, OnInput on_input,
                                                            Log log) {
  auto state = std::make_shared<TcpReceiver::State>(io, std::move(host), port);
  state->source = &source;
  state->on_input = std::move(on_input);
  state->log = std::move(log);
  state->connect();
  return std::make_unique<TcpReceiver>(std::move(state));
}

Result<std::unique_ptr<NeuronReceiver>> NeuronReceiver::bind_udp(asio::io_context& io,
                                                                 const std::string& address,
                                                                 std::uint16_t port,
                                                                 NeuronSource& source,
                                                                 OnInput on_input, Log log) {
  const std::string where = address + ":" + std::to_string(port);
  const std::optional<asio::ip::address> ip = listen_address(address);
  if (!ip) return Error{"neuron-udp: " + where + ": not an IP address"};
  auto state = std::make_shared<UdpReceiver::State>(io);
  state->source = &source;
  state->on_input = std::move(on_input);
  state->log = std::move(log);
  if (const error_code ec = open_udp_socket(state->socket, *ip, port); ec) {
    return Error{"neuron-udp: cannot bind " + where + ": " + ec.message()};
  }
  state->log("neuron-udp: listening on " + where);
  state->receive();
  return std::unique_ptr<NeuronReceiver>(std::make_unique<UdpReceiver>(std::move(state)));
}

}  // namespace duet::net
