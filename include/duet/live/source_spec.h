// The text that picks a source on the command line (`duet serve --source SPEC`):
//
//   replay:FILE.bvh[?speed=S&loop=0|1&start=SECONDS]   a file played in real time
//   neuron-tcp:[HOST:]PORT[?reference=0|1]             connect to Axis Neuron's BVH TCP server
//   neuron-udp:[ADDR:]PORT[?reference=0|1]             receive Axis Neuron's BVH UDP broadcast
//   ws[:SKELETON.bvh]                                  poses from WebSocket clients
//   xr                                                 a VR headset and two controllers over
//                                                      the WebSocket (the viewer's VR session)
//   vmc[:[ADDR:]PORT]                                  receive VMC protocol (OSC over UDP), from
//                                                      XR Animator, SlimeVR, VSeeFace, Warudo, ...
//
// vmc without a port listens on VMC's usual port, 39539.
// HOST defaults to 127.0.0.1; ADDR (the local address to bind) too. IPv6 addresses go in
// brackets: neuron-tcp:[::1]:7001.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "duet/base/result.h"
#include "duet/live/source_replay.h"

namespace duet {

enum class SourceKind { kReplay, kNeuronTcp, kNeuronUdp, kWebSocket, kXr, kVmc };

// The port VMC performers (XR Animator, VSeeFace, ...) send to by default.
constexpr std::uint16_t kVmcDefaultPort = 39539;
const char* source_kind_name(SourceKind kind);

struct SourceSpec {
  SourceKind kind = SourceKind::kWebSocket;
  std::string path;  // replay: the file; ws: the skeleton file (empty: the template's skeleton)
  std::string host;  // neuron-tcp: the server; neuron-udp, vmc: the local address to bind
  std::uint16_t port = 0;
  ReplayOptions replay;
  bool reference = false;  // neuron: records start with a reference bone's 6 values
};

Result<SourceSpec> parse_source_spec(std::string_view text);

}  // namespace duet
