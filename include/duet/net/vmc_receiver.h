// The network side of the VMC source (duet/live/source_vmc.h): binds a local UDP port, decodes
// each datagram (vmc_decoder.h) into a VmcSource and tells the owner that input arrived. Runs on
// the io_context's thread, like the loop (live_server.h), so the source needs no lock.
#pragma once

#include <boost/asio/io_context.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "duet/base/result.h"
#include "duet/live/source_vmc.h"

namespace duet::net {

class VmcReceiver {
 public:
  using OnInput = std::function<void()>;
  using Log = std::function<void(const std::string&)>;

  // The source, callbacks and io_context must outlive the receiver or its stop().
  static Result<std::unique_ptr<VmcReceiver>> bind(boost::asio::io_context& io,
                                                   const std::string& address, std::uint16_t port,
                                                   VmcSource& source, OnInput on_input, Log log);
  ~VmcReceiver();
  VmcReceiver(const VmcReceiver&) = delete;
  VmcReceiver& operator=(const VmcReceiver&) = delete;

  void stop();

  struct State;

 private:
  explicit VmcReceiver(std::shared_ptr<State> state);
  std::shared_ptr<State> state_;
};

}  // namespace duet::net
