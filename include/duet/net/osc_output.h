// `--osc-out HOST:PORT`: the follower's state as OSC over UDP, one bundle per processed frame, for
// TouchDesigner, Max, Pd, Ableton (docs/osc.md lists the addresses). Built in a buffer sized once
// (osc_writer.h) and sent with a non-blocking socket from the loop's thread: a frame the socket
// cannot take at once is dropped and counted, never waited for.
#pragma once

#include <boost/asio/io_context.hpp>
#include <cstdint>
#include <memory>
#include <string>

#include "duet/base/result.h"
#include "duet/live/live_loop.h"

namespace duet::net {

// "HOST:PORT" or "[V6]:PORT" (HOST may be a name, resolved once at start).
bool parse_osc_target(const std::string& text, std::string& host, std::uint16_t& port);

class OscOutput {
 public:
  // Resolves the host (blocking, once) and opens the socket.
  static Result<std::unique_ptr<OscOutput>> open(boost::asio::io_context& io,
                                                 const std::string& host, std::uint16_t port);
  ~OscOutput();
  OscOutput(const OscOutput&) = delete;
  OscOutput& operator=(const OscOutput&) = delete;

  // One bundle for `out`, the frame `loop` just produced. Allocates nothing, never blocks.
  void send(const LiveOutput& out, const LiveLoop& loop, long long seq) noexcept;

  long long sent() const noexcept;
  long long dropped() const noexcept;  // bundles the socket refused (full buffer, no route)
  std::string where() const;

  struct Impl;

 private:
  explicit OscOutput(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace duet::net
