// The `replay` control message (docs/protocol.md): parsing, and pause / seek / speed of a file
// replay in a real `duet serve`.
#include <gtest/gtest.h>

#include <cmath>

#include "duet/net/protocol.h"
#include "serve_support.h"

namespace duet::test {
namespace {

using net::ClientMessage;
using net::parse_client_message;

TEST(ReplayProtocol, ParsesEachSettingAndLeavesTheOthersAlone) {
  ClientMessage m;
  ASSERT_FALSE(parse_client_message(R"({"type": "replay", "paused": true})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kReplay);
  EXPECT_EQ(m.replay_paused, true);
  EXPECT_FALSE(m.replay_seek_s);
  EXPECT_FALSE(m.replay_speed);
  ASSERT_FALSE(parse_client_message(R"({"type": "replay", "seek_s": 12.5, "speed": 0.5})", m));
  EXPECT_FALSE(m.replay_paused);  // not carried over from the previous message
  EXPECT_EQ(m.replay_seek_s, 12.5);
  EXPECT_EQ(m.replay_speed, 0.5);
  const char* bad[] = {
      R"({"type": "replay"})",
      R"({"type": "replay", "paused": "yes"})",
      R"({"type": "replay", "seek_s": "end"})",
      R"({"type": "replay", "speed": 0})",
      R"({"type": "replay", "speed": 10})",
      R"({"type": "replay", "speed": null})",
  };
  for (const char* text : bad) {
    const std::optional<std::string> reason = parse_client_message(text, m);
    ASSERT_TRUE(reason) << text;
    EXPECT_NE(reason->find("replay"), std::string::npos) << *reason;
  }
}

TEST(ReplayProtocol, StateMessage) {
  ReplayState state;
  state.paused = true;
  state.speed = 2.0;
  state.position_s = 12.3456;
  state.duration_s = 30.5;
  const Json j = Json::parse(net::make_replay_state(state));
  EXPECT_EQ(j["type"], "replay_state");
  EXPECT_EQ(j["paused"], true);
  EXPECT_DOUBLE_EQ(j["speed"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["position_s"].get<double>(), 12.346);
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), 30.5);
  EXPECT_EQ(j["loop"], false);
}

// What a client saw until `done` said so (or 20 s passed).
struct Seen {
  std::vector<Json> frames;
  std::vector<Json> states;
  int stats = 0;
  bool complete = false;
};

template <class Done>
Seen read_until(WsClient& client, Done done) {
  Seen seen;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline) {
    std::optional<Json> j = client.read_json(5s);
    if (!j) break;
    const std::string type = (*j)["type"].get<std::string>();
    if (type == "frame") seen.frames.push_back(*j);
    if (type == "replay_state") seen.states.push_back(*j);
    if (type == "stats") ++seen.stats;
    if (type == "error") ADD_FAILURE() << j->dump();
    if (done(seen)) {
      seen.complete = true;
      break;
    }
  }
  return seen;
}

TEST(ServeReplay, PausesSeeksAndChangesSpeed) {
  TempDir dir("duet-serve-replay-test");
  ServeProcess server;
  ASSERT_TRUE(
      server.start({"--pair", salsa("60", "03"), salsa("61", "03"), "--fps", "60", "--source",
                    "replay:" + salsa("60", "03"), "--no-record", "--log-interval", "0"},
                   dir.path / "serve.log"))
      << server.log();
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port())) << server.log();
  ASSERT_TRUE(viewer.read_type("hello")) << server.log();
  // A state comes with the stats once a second: a viewer learns it is a replay.
  Seen seen = read_until(viewer, [](const Seen& s) { return !s.states.empty(); });
  ASSERT_TRUE(seen.complete) << server.log();
  EXPECT_EQ(seen.states.back()["paused"], false);
  EXPECT_DOUBLE_EQ(seen.states.back()["speed"].get<double>(), 1.0);
  EXPECT_NEAR(seen.states.back()["duration_s"].get<double>(), 1830 / 60.0, 1e-3);
  seen = read_until(viewer, [](const Seen& s) { return s.frames.size() >= 30; });
  ASSERT_TRUE(seen.complete);
  double last_time = seen.frames.back()["time_s"].get<double>();

  // Pause: the state says so at once; after the next stats no frame comes (up to 2 may have
  // been waiting in the queue behind the state).
  // Each wait below looks for the state it expects: the once-a-second one may come first.
  ASSERT_TRUE(viewer.write(R"({"type": "replay", "paused": true})"));
  seen = read_until(viewer,
                    [](const Seen& s) { return !s.states.empty() && s.states.back()["paused"]; });
  ASSERT_TRUE(seen.complete);
  EXPECT_EQ(seen.states.back()["paused"], true);
  seen = read_until(viewer, [](const Seen& s) { return s.stats >= 1; });
  if (!seen.frames.empty()) last_time = seen.frames.back()["time_s"].get<double>();
  seen = read_until(viewer, [](const Seen& s) { return s.stats >= 1; });
  ASSERT_TRUE(seen.complete);
  EXPECT_EQ(seen.frames.size(), 0u) << "frames while paused";

  // Seek while paused: that one frame, and the state at 20 s, still paused.
  ASSERT_TRUE(viewer.write(R"({"type": "replay", "seek_s": 20})"));
  seen = read_until(viewer, [](const Seen& s) {
    return !s.frames.empty() && !s.states.empty() &&
           std::abs(s.states.back()["position_s"].get<double>() - 20.0) < 0.5;
  });
  ASSERT_TRUE(seen.complete) << server.log();
  EXPECT_EQ(seen.states.back()["paused"], true);
  EXPECT_NEAR(seen.states.back()["position_s"].get<double>(), 20.0, 1e-3);
  ASSERT_EQ(seen.frames.size(), 1u);
  // The clock stood still while paused: the preview is one frame after the last one played.
  const double preview_time = seen.frames[0]["time_s"].get<double>();
  EXPECT_GT(preview_time, last_time);
  EXPECT_LT(preview_time, last_time + 0.1);
  seen = read_until(viewer, [](const Seen& s) { return s.stats >= 2; });
  EXPECT_EQ(seen.frames.size(), 0u) << "frames after the preview while paused";

  // Resume at 2x: the file advances twice as fast as the wall clock.
  ASSERT_TRUE(viewer.write(R"({"type": "replay", "paused": false, "speed": 2})"));
  const auto t0 = std::chrono::steady_clock::now();
  seen = read_until(
      viewer, [](const Seen& s) { return !s.states.empty() && s.states.back()["speed"] == 2; });
  ASSERT_TRUE(seen.complete);
  EXPECT_EQ(seen.states.back()["paused"], false);
  EXPECT_DOUBLE_EQ(seen.states.back()["speed"].get<double>(), 2.0);
  const double p0 = seen.states.back()["position_s"].get<double>();
  EXPECT_NEAR(p0, 20.0, 0.1);
  seen = read_until(viewer, [](const Seen& s) { return s.frames.size() >= 120; });
  ASSERT_TRUE(seen.complete);
  for (std::size_t k = 1; k < seen.frames.size(); ++k) {
    ASSERT_GT(seen.frames[k]["time_s"].get<double>(), seen.frames[k - 1]["time_s"].get<double>());
  }
  ASSERT_TRUE(viewer.write(R"({"type": "replay", "speed": 2})"));
  // Its reply, or a once-a-second state: either tells where the file is now.
  seen = read_until(viewer, [](const Seen& s) { return !s.states.empty(); });
  ASSERT_TRUE(seen.complete);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double advanced_s = seen.states.back()["position_s"].get<double>() - p0;
  EXPECT_GT(advanced_s, 1.5 * (wall_s - 0.3)) << advanced_s << " s of file in " << wall_s << " s";
  EXPECT_LT(advanced_s, 2.0 * wall_s + 0.1) << advanced_s << " s of file in " << wall_s << " s";

  // Bad controls are answered with an error and change nothing.
  for (const char* bad : {R"({"type": "replay"})", R"({"type": "replay", "speed": 100})"}) {
    ASSERT_TRUE(viewer.write(bad));
    ASSERT_TRUE(viewer.read_type("error")) << bad;
  }
  ASSERT_EQ(server.stop(SIGTERM), 0) << server.log();
}

}  // namespace
}  // namespace duet::test
