// `duet serve` with live sources: the test plays Axis Neuron (a BVH broadcast over TCP or UDP,
// good and bad records), and switches the user's role while a replay runs.
#include <gtest/gtest.h>

#include <boost/asio/ip/udp.hpp>
#include <cmath>

#include "duet/io/bvh.h"
#include "serve_support.h"

namespace duet::test {
namespace {

// The motion lines of a salsa take, as Axis would send them: "0 Avatar00 <values> ||".
std::vector<std::string> axis_records(const std::string& path, int count) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("Frame Time", 0) != 0) {
  }
  std::vector<std::string> records;
  while (static_cast<int>(records.size()) < count && std::getline(in, line)) {
    records.push_back("0 Avatar00 " + line + " ||");
  }
  return records;
}

std::vector<std::string> neuron_args(const std::string& source) {
  return {"--pair",
          salsa("60", "03"),
          salsa("61", "03"),
          "--fps",
          "60",
          "--source",
          source,
          "--source-skeleton",
          salsa("60", "03"),
          "--source-fps",
          "60",
          "--no-record",
          "--log-interval",
          "0"};
}

const std::vector<std::string> kBadRecords = {
    "0 Avatar00 1 2 3 ||",               // far too few values
    "0 Avatar00 not numbers at all ||",  // not numbers
    std::string(100000, '9') + " ||",    // a record longer than the limit
};

// Reads frames until `count` arrived or the source's stats show `rejected`; returns frames seen.
int read_frames_and_stats(WsClient& viewer, int good, int rejected, Json& last_stats) {
  int frames = 0;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (std::chrono::steady_clock::now() < deadline) {
    std::optional<Json> message = viewer.read_json(3s);
    if (!message) break;
    if ((*message)["type"] == "frame") {
      ++frames;
      for (const Json& v : (*message)["user"]["positions"][0]) {
        EXPECT_TRUE(v.is_number());
      }
    } else if ((*message)["type"] == "stats") {
      last_stats = *message;
      if (last_stats["source"]["frames"].get<int>() + last_stats["source"]["dropped"].get<int>() >=
              good &&
          last_stats["source"]["rejected"].get<int>() >= rejected) {
        break;
      }
    }
  }
  return frames;
}

TEST(ServeSources, NeuronOverTcp) {
  TempDir dir("duet-serve-neuron-tcp-test");
  asio::io_context io;
  tcp::acceptor axis(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  const std::uint16_t axis_port = axis.local_endpoint().port();

  ServeProcess server;
  ASSERT_TRUE(server.start(neuron_args("neuron-tcp:127.0.0.1:" + std::to_string(axis_port)),
                           dir.path / "serve.log"))
      << server.log();
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port()));
  ASSERT_TRUE(viewer.read_type("hello"));

  // duet serve connects to "Axis".
  tcp::socket stream(io);
  axis.accept(stream);
  const std::vector<std::string> records = axis_records(salsa("60", "03"), 240);
  for (std::size_t k = 0; k < records.size(); ++k) {
    std::string chunk = records[k];
    if (k % 80 == 40) chunk += kBadRecords[k / 80];
    asio::write(stream, asio::buffer(chunk));
    std::this_thread::sleep_for(2ms);
  }
  Json stats;
  const int frames = read_frames_and_stats(viewer, static_cast<int>(records.size()), 3, stats);
  EXPECT_GT(frames, 20);  // the viewer only reads after the burst: it sees some, with gaps
  ASSERT_TRUE(stats.is_object()) << server.log();
  EXPECT_EQ(stats["source"]["rejected"], 3) << stats.dump();
  EXPECT_EQ(stats["source"]["frames"].get<int>() + stats["source"]["dropped"].get<int>(),
            static_cast<int>(records.size()))
      << stats.dump();
  // Axis goes away and comes back: duet serve reconnects.
  stream.close();
  tcp::socket again(io);
  axis.accept(again);
  asio::write(again, asio::buffer(records[0]));
  EXPECT_TRUE(viewer.read_type("frame", 20s));
  EXPECT_EQ(server.stop(SIGTERM), 0) << server.log();
  EXPECT_NE(server.log().find("neuron-tcp: connected"), std::string::npos) << server.log();
}

TEST(ServeSources, NeuronOverUdp) {
  TempDir dir("duet-serve-neuron-udp-test");
  asio::io_context io;
  std::uint16_t port = 0;
  {
    asio::ip::udp::socket probe(io,
                                asio::ip::udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    port = probe.local_endpoint().port();
  }
  ServeProcess server;
  ASSERT_TRUE(server.start(neuron_args("neuron-udp:127.0.0.1:" + std::to_string(port)),
                           dir.path / "serve.log"))
      << server.log();
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port()));
  ASSERT_TRUE(viewer.read_type("hello"));

  asio::ip::udp::socket axis(io, asio::ip::udp::v4());
  const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), port);
  const std::vector<std::string> records = axis_records(salsa("60", "03"), 120);
  for (std::size_t k = 0; k < records.size(); ++k) {
    axis.send_to(asio::buffer(records[k]), to);
    if (k == 60) {
      axis.send_to(asio::buffer(kBadRecords[0]), to);
      axis.send_to(asio::buffer(std::string("0 Avatar00 1 2")), to);  // cut short, no "||"
    }
    std::this_thread::sleep_for(3ms);
  }
  Json stats;
  const int frames = read_frames_and_stats(viewer, static_cast<int>(records.size()), 2, stats);
  EXPECT_GT(frames, 20);
  ASSERT_TRUE(stats.is_object()) << server.log();
  EXPECT_EQ(stats["source"]["rejected"], 2) << stats.dump();
  EXPECT_EQ(server.stop(SIGTERM), 0) << server.log();
}

TEST(ServeSources, RoleSwitchStartsANewHelloAndRecording) {
  TempDir dir("duet-serve-role-test");
  ServeProcess server;
  ASSERT_TRUE(server.start(
      {"--pair", salsa("60", "03"), salsa("61", "03"), "--fps", "60", "--source",
       "replay:" + salsa("60", "03") + "?loop=1", "--record", (dir.path / "rec").string()},
      dir.path / "serve.log"))
      << server.log();
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port()));
  const std::optional<Json> hello = viewer.read_type("hello");
  ASSERT_TRUE(hello);
  EXPECT_EQ((*hello)["role"], "leader");
  ASSERT_TRUE(viewer.read_type("frame"));
  ASSERT_TRUE(viewer.write(R"({"type": "role", "role": "partner"})"));
  const std::optional<Json> second = viewer.read_type("hello", 30s);
  ASSERT_TRUE(second) << server.log();
  EXPECT_EQ((*second)["role"], "partner");
  const std::size_t partner_joints = (*second)["partner_skeleton"]["joints"].size();
  const std::optional<Json> frame = viewer.read_type("frame");
  ASSERT_TRUE(frame);
  EXPECT_EQ((*frame)["partner"]["positions"].size(), partner_joints);
  ASSERT_TRUE(viewer.write(R"({"type": "reset"})"));
  ASSERT_TRUE(viewer.read_type("frame"));
  ASSERT_EQ(server.stop(SIGTERM), 0) << server.log();
  int users = 0;
  for (const auto& entry : fs::directory_iterator(dir.path / "rec")) {
    const std::string name = entry.path().filename().string();
    EXPECT_FALSE(name.ends_with(".part")) << name;
    if (name.ends_with("-user.bvh")) {
      ++users;
      EXPECT_TRUE(read_bvh(entry.path().string())) << name;
    }
  }
  EXPECT_EQ(users, 2);  // one per role
}

}  // namespace
}  // namespace duet::test
