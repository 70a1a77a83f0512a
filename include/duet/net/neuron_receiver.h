// The network side of the Perception Neuron source (duet/live/source_neuron.h): receives Axis
// Neuron's BVH broadcast over TCP (we connect to Axis, which listens; reconnects every second
// after a failure or a close) or UDP (we bind a local port), feeds the bytes to a NeuronSource and
// tells the owner that input arrived. Runs on the io_context's thread.
#pragma once

#include <boost/asio/io_context.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "duet/base/result.h"
#include "duet/live/source_neuron.h"

namespace duet::net {

class NeuronReceiver {
 public:
  using OnInput = std::function<void()>;
  using Log = std::function<void(const std::string&)>;

  // The source, callbacks and io_context must outlive the receiver or its stop().
  static std::unique_ptr<NeuronReceiver> connect_tcp(boost::asio::io_context& io, std::string host,
                                                     std::uint16_t port, NeuronSource& source,
                                                     OnInput on_input, Log log);
  static Result<std::unique_ptr<NeuronReceiver>> bind_udp(boost::asio::io_context& io,
                                                          const std::string& address,
                                                          std::uint16_t port, NeuronSource& source,
                                                          OnInput on_input, Log log);

  virtual ~NeuronReceiver() = default;
  virtual void stop() = 0;

 protected:
  NeuronReceiver() = default;
};

}  // namespace duet::net
