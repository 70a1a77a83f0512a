#include "duet/net/vmc_receiver.h"

#include <array>
#include <boost/asio/ip/udp.hpp>

#include "duet/net/vmc_decoder.h"
#include "listen_address.h"

namespace duet::net {

namespace asio = boost::asio;
using boost::system::error_code;

struct VmcReceiver::State : std::enable_shared_from_this<VmcReceiver::State> {
  explicit State(asio::io_context& io) : socket(io) {}

  void receive() {
    socket.async_receive_from(
        asio::buffer(buffer), sender, [self = shared_from_this()](error_code ec, std::size_t n) {
          if (self->stopped || ec == asio::error::operation_aborted) return;
          if (!ec) {
            decode_vmc_packet(self->buffer.data(), n, SteadyClock::now(), *self->source);
            if (self->on_input) self->on_input();
          }
          self->receive();
        });
  }

  VmcSource* source = nullptr;
  OnInput on_input;
  Log log;
  bool stopped = false;
  asio::ip::udp::socket socket;
  asio::ip::udp::endpoint sender;
  std::array<char, 65536> buffer{};  // the largest UDP datagram
};

VmcReceiver::VmcReceiver(std::shared_ptr<State> state) : state_(std::move(state)) {}

VmcReceiver::~VmcReceiver() { stop(); }

void VmcReceiver::stop() {
  if (state_->stopped) return;
  state_->stopped = true;
  error_code ec;
  state_->socket.close(ec);
}

Result<std::unique_ptr<VmcReceiver>> VmcReceiver::bind(asio::io_context& io,
                                                       const std::string& address,
                                                       std::uint16_t port, VmcSource& source,
                                                       OnInput on_input, Log log) {
  const std::string where = address + ":" + std::to_string(port);
  const std::optional<asio::ip::address> ip = listen_address(address);
  if (!ip) return Error{"vmc: " + where + ": not an IP address"};
  auto state = std::make_shared<State>(io);
  state->source = &source;
  state->on_input = std::move(on_input);
  state->log = std::move(log);
  error_code ec = open_udp_socket(state->socket, *ip, port);
  if (ec) return Error{"vmc: cannot bind UDP " + where + ": " + ec.message()};
  // A frame of VMC is ~60 datagram-sized messages; a larger receive buffer rides out a stall.
  state->socket.set_option(asio::socket_base::receive_buffer_size(1 << 20), ec);
  state->log("vmc: listening on UDP " + where);
  state->receive();
  return std::unique_ptr<VmcReceiver>(new VmcReceiver(std::move(state)));
}

}  // namespace duet::net
