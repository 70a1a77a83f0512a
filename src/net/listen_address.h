// Where a server or a receiver listens: the address on the command line ("localhost" or an IP
// literal; no name lookup, a listener binds to an address of this machine), and a UDP socket
// opened and bound to it. Shared by the HTTP server and the Neuron and VMC receivers.
#pragma once

#include <boost/asio/ip/address.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/system/error_code.hpp>
#include <cstdint>
#include <optional>
#include <string>

namespace duet::net {

// "localhost" -> 127.0.0.1, an IPv4 or IPv6 literal -> itself, anything else -> nullopt.
std::optional<boost::asio::ip::address> listen_address(const std::string& text);

// Opens `socket` for address:port and binds it; the error of the step that failed (none on
// success).
boost::system::error_code open_udp_socket(boost::asio::ip::udp::socket& socket,
                                   const boost::asio::ip::address& address, std::uint16_t port);

}  // namespace duet::net
