// `duet serve` without the command line: a frame source, the live loop, the HTTP/WebSocket server,
// the recorder and the statistics, run on one thread.
//
// Why one thread: the path from a frame's arrival to its messages reaching the sockets then has no
// hand-off between threads (each one is a scheduler wake-up, the main risk for the latency
// budget on a loaded machine). A frame arrives (a timer for replays, a socket read for network
// sources), the loop steps, the frame message is formatted once and written to every client
// (non-blocking sends); a client that is behind gets its queue trimmed instead. Only the file
// writing of the recorder, and building a library for the other role, run on other threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "duet/base/result.h"
#include "duet/live/live_loop.h"
#include "duet/live/recorder.h"
#include "duet/live/source_frame.h"
#include "duet/live/source_spec.h"
#include "duet/net/server.h"

namespace duet::net {

struct LiveServerOptions {
  ServerOptions server;
  // Recording: files under `record_dir` named <record_stem>-user.bvh, ... (empty dir: none).
  std::string record_dir = "recordings";
  std::string record_stem;        // empty: the start time, "20250101-120000"
  double stats_interval_s = 1.0;  // `stats` messages
  double log_interval_s = 5.0;    // log lines (0: none)
  bool exit_at_end = false;       // stop when a source finishes (a replay without loop)
  bool handle_signals = true;     // SIGINT and SIGTERM stop the server cleanly
  // Raise the loop thread's scheduling priority (see thread_priority.h) while run() runs.
  bool realtime = true;
  std::function<void(const std::string&)> log;  // default: a line on stderr
  // --osc-out: the follower's state as OSC to this host and port (osc_output.h); empty: none.
  std::string osc_host;
  std::uint16_t osc_port = 0;
};

// Builds the loop for a role (the library of that role, a tracker, the partner models). Called on
// a background thread when a client asks for the other role; must be thread-safe.
using LoopFactory =
    std::function<Result<std::unique_ptr<LiveLoop>>(DancerRole role, const PartnerParams& params)>;

struct ServeSummary {
  long long frames = 0;                 // processed (and offered to every client)
  long long clients_seen = 0;           // WebSocket clients that connected
  long long rejected = 0;               // client messages rejected
  long long dropped = 0;                // frame messages dropped for slow clients
  LatencySummary latency_total;         // arrival -> sent
  LatencySummary loop_total;            // arrival -> message built
  std::vector<std::string> recordings;  // files written, in order
  long long recorded = 0;
  long long record_lost = 0;
  long long osc_sent = 0;     // --osc-out bundles sent
  long long osc_dropped = 0;  // and refused by the socket
};

class LiveServer {
 public:
  // `source` is fed according to `spec` (a timer for replay, a socket for neuron-tcp/udp and vmc,
  // `pose` messages for ws). `loop` must have been made for the source's skeleton.
  LiveServer(LiveServerOptions options, SourceSpec spec, std::unique_ptr<FrameSource> source,
             std::unique_ptr<LiveLoop> loop, LoopFactory factory);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  // Binds the port, opens the source's socket and the recording files.
  Status start();
  std::uint16_t port() const;
  const std::filesystem::path* web_root() const;

  // Runs until stop() or a signal, then closes connections and the recording. Returns the
  // recorder's status (a write error) and fills summary().
  Status run();
  // Thread-safe; may be called before or during run().
  void stop();

  const ServeSummary& summary() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace duet::net
