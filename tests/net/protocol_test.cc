#include "duet/net/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

namespace duet::net {
namespace {

using nlohmann::json;

std::optional<std::string> parse(std::string_view text, ClientMessage& m) {
  return parse_client_message(text, m);
}

TEST(Protocol, ParsesControlMessages) {
  ClientMessage m;
  EXPECT_FALSE(parse(R"({"type": "set", "correction": "footlock", "enabled": false})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kSet);
  EXPECT_EQ(m.correction, "footlock");
  EXPECT_FALSE(m.enabled);
  EXPECT_FALSE(parse(R"({"type": "role", "role": "partner"})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kRole);
  EXPECT_EQ(m.role, DancerRole::kPartner);
  EXPECT_FALSE(parse(R"({"type": "reset", "extra": [1, 2]})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kReset);
  EXPECT_FALSE(parse(R"({"type": "head_height", "metres": 1.62})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kHeadHeight);
  EXPECT_DOUBLE_EQ(m.head_height_m, 1.62);
  EXPECT_FALSE(parse(R"({"type": "head_height", "metres": 0})", m));  // learn it again
  EXPECT_EQ(m.head_height_m, 0.0);
  EXPECT_FALSE(parse(R"({"type": "arms_forward"})", m));
  EXPECT_EQ(m.type, ClientMessage::Type::kArmsForward);
  EXPECT_FALSE(m.forget_arms_forward);
  EXPECT_FALSE(parse(R"({"type": "arms_forward", "forget": true})", m));
  EXPECT_TRUE(m.forget_arms_forward);
}

TEST(Protocol, ParsesPoses) {
  ClientMessage m;
  EXPECT_FALSE(parse(R"({"type": "pose", "time_s": 1.25, "root": [0.1, 0.9, -0.2],
                         "rotations": [[1, 0, 0, 0], [0.7071, 0, 0.7071, 0]]})",
                     m));
  EXPECT_EQ(m.type, ClientMessage::Type::kPose);
  EXPECT_DOUBLE_EQ(m.time_s, 1.25);
  EXPECT_TRUE(m.root.isApprox(Vec3(0.1, 0.9, -0.2)));
  ASSERT_EQ(m.rotations.size(), 8u);
  EXPECT_DOUBLE_EQ(m.rotations[6], 0.7071);
  EXPECT_FALSE(parse(R"({"type": "pose", "root": [0, 1, 0], "rotations": []})", m));
  EXPECT_TRUE(std::isnan(m.time_s));
}

TEST(Protocol, RejectsWithAReason) {
  ClientMessage m;
  const char* bad[] = {
      "",
      "nope",
      "{\"type\": \"set\"",
      "[1, 2]",
      "\"set\"",
      "{}",
      R"({"type": 3})",
      R"({"type": "jump"})",
      R"({"type": "set", "correction": "glitter", "enabled": true})",
      R"({"type": "set", "correction": "align"})",
      R"({"type": "set", "correction": "align", "enabled": 1})",
      R"({"type": "role", "role": "both"})",
      R"({"type": "role"})",
      R"({"type": "pose", "root": [0, 1], "rotations": []})",
      R"({"type": "pose", "root": [0, 1, "a"], "rotations": []})",
      R"({"type": "pose", "root": [0, 1, 1e999], "rotations": []})",
      R"({"type": "pose", "root": [0, 1, 0], "rotations": [[1, 0, 0]]})",
      R"({"type": "pose", "root": [0, 1, 0], "rotations": [[1, 0, 0, null]]})",
      R"({"type": "pose", "root": [0, 1, 0], "rotations": {"a": 1}})",
      R"({"type": "pose", "time_s": "now", "root": [0, 1, 0], "rotations": []})",
      R"({"type": "head_height"})",
      R"({"type": "head_height", "metres": "tall"})",
      R"({"type": "head_height", "metres": 162})",  // centimetres
      R"({"type": "head_height", "metres": -1.6})",
      R"({"type": "head_height", "metres": 0.3})",
      R"({"type": "arms_forward", "forget": 1})",
  };
  for (const char* text : bad) {
    const std::optional<std::string> reason = parse(text, m);
    ASSERT_TRUE(reason) << text;
    EXPECT_FALSE(reason->empty());
    // The reason always makes a valid error message, even when it quotes bad UTF-8.
    EXPECT_TRUE(json::accept(make_error(*reason))) << *reason;
  }
  const std::string deep = std::string(10000, '[') + std::string(10000, ']');
  EXPECT_EQ(parse(deep, m).value_or(""), "message nested too deeply");
  const std::string deep_in_string =
      "{\"type\": \"reset\", \"s\": \"" + std::string(100, '[') + "\"}";
  EXPECT_FALSE(parse(deep_in_string, m));
  std::string many = "[0";
  for (int k = 0; k < 20000; ++k) many += ",0";
  many += "]";
  EXPECT_EQ(parse(many, m).value_or(""), "message holds too many values");
  const std::string big(kMaxClientMessageBytes + 1, ' ');
  EXPECT_TRUE(parse(big, m));
  const std::optional<std::string> unknown = parse("{\"type\": \"\xff\xfe\"}", m);
  ASSERT_TRUE(unknown);
  EXPECT_TRUE(json::accept(make_error(*unknown)));
}

TEST(Protocol, FrameMessageIsValidJson) {
  LiveOutput out;
  out.seq = 41;
  out.time_s = 0.6833333;
  out.follow.take = 2;
  out.follow.frame_in_take = 1033;
  out.follow.confidence = 0.9412f;
  out.follow.jumped = true;
  out.contact_right = true;
  out.user_positions_ws = {Vec3(0.1, 0.9, -0.00004), Vec3(-1.23456, 1e-7, 250.5)};
  out.user_rotations_ws = {Quat::Identity(), Quat(0.5, -0.5, 0.5, -0.5)};
  out.partner_positions_ws = {Vec3(std::nan(""), 1.0, INFINITY)};
  out.partner_rotations_ws = {Quat(0.0, 0.0, 1.0, 0.0)};
  PartnerParams params;
  params.smooth = false;
  std::string text;
  format_frame(out, params, 412, text);
  const json j = json::parse(text);
  EXPECT_EQ(j["type"], "frame");
  EXPECT_EQ(j["seq"], 41);
  EXPECT_NEAR(j["time_s"].get<double>(), 0.6833, 1e-9);
  EXPECT_EQ(j["follower"]["take"], 2);
  EXPECT_EQ(j["follower"]["template_frame"], 1033);
  EXPECT_NEAR(j["follower"]["confidence"].get<double>(), 0.941, 1e-9);
  EXPECT_EQ(j["follower"]["jumped"], true);
  EXPECT_EQ(j["follower"]["lost"], false);
  EXPECT_EQ(j["user"]["positions"][0][0], 0.1);
  EXPECT_EQ(j["user"]["positions"][0][2], 0);  // -0.00004 rounds to 0, without a sign
  EXPECT_NEAR(j["user"]["positions"][1][0].get<double>(), -1.2346, 1e-12);
  EXPECT_EQ(j["user"]["positions"][1][2], 250.5);
  EXPECT_EQ(j["user"]["rotations"][1][1], -0.5);
  EXPECT_TRUE(j["partner"]["positions"][0][0].is_null());  // NaN is not JSON
  EXPECT_TRUE(j["partner"]["positions"][0][2].is_null());
  EXPECT_EQ(j["partner"]["rotations"][0][2], 1);
  EXPECT_EQ(j["corrections"]["smooth"], false);
  EXPECT_EQ(j["corrections"]["align"], true);
  EXPECT_EQ(j["contact"]["right"], true);
  EXPECT_EQ(j["contact"]["left"], false);
  EXPECT_EQ(j["latency_us"], 412);
  // Reusing the buffer replaces the message.
  format_frame(out, params, 7, text);
  EXPECT_EQ(json::parse(text)["latency_us"], 7);
}

TEST(Protocol, StatsAndErrors) {
  StatsSnapshot s;
  s.frames = 7200;
  s.clients = 3;
  s.latency = {250, 700, 1900, 960};
  const json stats = json::parse(make_stats(s));
  EXPECT_EQ(stats["type"], "stats");
  EXPECT_EQ(stats["frames"], 7200);
  EXPECT_EQ(stats["latency_us"]["p99"], 700);
  EXPECT_FALSE(stats.contains("advice"));  // nothing to advise
  s.calibration_offset = 0.0943f;
  const json advised = json::parse(make_stats(s));
  EXPECT_DOUBLE_EQ(advised["advice"]["calibrate"]["rig_offset"].get<double>(), 0.094);
  const json error = json::parse(make_error("unknown correction 'foo'"));
  EXPECT_EQ(error["type"], "error");
  EXPECT_EQ(error["reason"], "unknown correction 'foo'");
}

}  // namespace
}  // namespace duet::net
