#include "listen_address.h"

namespace duet::net {

std::optional<boost::asio::ip::address> listen_address(const std::string& text) {
  boost::system::error_code ec;
  const boost::asio::ip::address address =
      boost::asio::ip::make_address(text == "localhost" ? std::string("127.0.0.1") : text, ec);
  if (ec) return std::nullopt;
  return address;
}

boost::system::error_code open_udp_socket(boost::asio::ip::udp::socket& socket,
                                   const boost::asio::ip::address& address, std::uint16_t port) {
  const boost::asio::ip::udp::endpoint endpoint(address, port);
  boost::system::error_code ec;
  socket.open(endpoint.protocol(), ec);
  if (!ec) socket.bind(endpoint, ec);
  return ec;
}

}  // namespace duet::net
