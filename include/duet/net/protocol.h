// The JSON messages of docs/protocol.md: building the server's messages and parsing the clients'.
// Frame messages are formatted by hand into a reused string (no allocation once it has grown, a
// few microseconds per frame); the rare messages use nlohmann::json.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "duet/live/live_loop.h"
#include "duet/live/source_frame.h"
#include "duet/live/source_replay.h"
#include "duet/motion/device_points.h"

namespace duet::net {

constexpr int kProtocolVersion = 1;

// Client messages are rejected above this size (docs/protocol.md).
constexpr std::size_t kMaxClientMessageBytes = 1 << 20;

// Nesting deeper than this is rejected before parsing (no message of the protocol needs more
// than 3 levels; a deep one would only cost stack and time).
constexpr int kMaxJsonDepth = 16;
// More values than this are refused before parsing too: a pose of 4000 joints fits, and parsing
// a message never takes the loop's thread more than about a millisecond.
constexpr std::size_t kMaxJsonValues = 16384;

// `hello`: skeletons (joints, parents, offsets, roles), takes with their contact intervals, the
// role, the template frame rate, the corrections, and the source: its description for people and
// its kind ("replay", "ws", "xr", ...) for clients (the viewer sends headset poses for "xr").
// `device_offsets` (the headset source's, or null): what the server takes out of each xr_pose, so
// a viewer can draw the user's devices where they are.
std::string make_hello(const LiveLoop& loop, const std::string& source_description,
                       std::string_view source_kind,
                       const DevicePointOffsets* device_offsets = nullptr);

// `frame`: appends to `text` after clearing it. `seq` >= 0 replaces output.seq (the server counts
// frames across role switches, which change the loop).
void format_frame(const LiveOutput& output, const PartnerParams& params, std::int64_t latency_us,
                  std::string& text, long long seq = -1);

struct LatencySummary {
  std::int64_t p50 = 0, p99 = 0, max = 0, count = 0;
};

struct StatsSnapshot {
  long long frames = 0;  // frames processed since the server started
  int clients = 0;
  long long dropped = 0;         // frame messages dropped for slow clients, all clients
  long long rejected = 0;        // client messages rejected, all clients
  double rate_hz = 0.0;          // frames processed per second over the last window
  LatencySummary latency;        // arrival -> sent, last window
  LatencySummary latency_total;  // arrival -> sent, since start
  LatencySummary loop;           // arrival -> message built, last window
  SourceStats source;
  long long recorded = 0;
  long long record_lost = 0;
  // Three points without a body calibration whose learnt posture offset is another body's
  // (CalibrationAdvice): that offset, sent as "advice"; nullopt: nothing to advise.
  std::optional<float> calibration_offset;
};
std::string make_stats(const StatsSnapshot& stats);

std::string make_error(std::string_view reason);

// `replay_state`: where a file replay is, sent after each `replay` control and once a second.
std::string make_replay_state(const ReplayState& state);

// What a client asked for.
struct ClientMessage {
  enum class Type { kSet, kRole, kReset, kPose, kXrPose, kReplay, kHeadHeight, kArmsForward };
  Type type = Type::kReset;
  // set
  std::string correction;
  bool enabled = false;
  // role
  DancerRole role = DancerRole::kLeader;
  // pose
  double time_s = 0.0;  // NaN when absent
  Vec3 root = Vec3::Zero();
  std::vector<double> rotations;  // w, x, y, z per joint
  // xr_pose: head, left hand, right hand; positions in metres, orientations w, x, y, z
  std::array<Vec3, 3> point_positions{};
  std::array<double, 12> point_orientations{};
  // head_height: the headset's height standing, metres; 0 learns it again
  double head_height_m = 0.0;
  // arms_forward: true ("forget": true) drops the body calibration; false takes it from the
  // headset's latest pose
  bool forget_arms_forward = false;
  // replay: each absent field leaves that setting alone (at least one is present)
  std::optional<bool> replay_paused;
  std::optional<double> replay_seek_s;
  std::optional<double> replay_speed;
};

// Parses one client text message. Returns nullopt on success, else the reason for the `error`
// reply. Never throws (bad input, deep nesting, huge numbers: all are reasons).
std::optional<std::string> parse_client_message(std::string_view text, ClientMessage& message);

}  // namespace duet::net
