// `duet serve` end to end over loopback: the real binary, a replayed salsa take, Beast clients.
#include <gtest/gtest.h>

#include <cmath>

#include "duet/io/bvh.h"
#include "duet/io/motion_file.h"
#include "serve_support.h"

namespace duet::test {
namespace {

std::vector<std::string> salsa_pair_args() {
  return {"--pair", salsa("60", "03"), salsa("61", "03"), "--fps", "60"};
}

// Every number of a pose array is finite (the server writes null for NaN/inf), and rotations
// are unit quaternions.
::testing::AssertionResult valid_pose(const Json& pose, std::size_t joints) {
  if (!pose.is_object() || !pose["positions"].is_array() || !pose["rotations"].is_array()) {
    return ::testing::AssertionFailure() << "no positions/rotations";
  }
  if (pose["positions"].size() != joints || pose["rotations"].size() != joints) {
    return ::testing::AssertionFailure()
           << pose["positions"].size() << " positions, " << pose["rotations"].size()
           << " rotations, expected " << joints;
  }
  for (const Json& p : pose["positions"]) {
    if (p.size() != 3) return ::testing::AssertionFailure() << "position " << p.dump();
    for (const Json& v : p) {
      if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > 100) {
        return ::testing::AssertionFailure() << "position " << p.dump();
      }
    }
  }
  for (const Json& q : pose["rotations"]) {
    if (q.size() != 4) return ::testing::AssertionFailure() << "rotation " << q.dump();
    double norm2 = 0.0;
    for (const Json& v : q) {
      if (!v.is_number()) return ::testing::AssertionFailure() << "rotation " << q.dump();
      norm2 += v.get<double>() * v.get<double>();
    }
    if (std::abs(std::sqrt(norm2) - 1.0) > 1e-3) {
      return ::testing::AssertionFailure() << "rotation " << q.dump();
    }
  }
  return ::testing::AssertionSuccess();
}

std::vector<fs::path> files_ending(const fs::path& dir, const std::string& suffix) {
  std::vector<fs::path> found;
  if (!fs::exists(dir)) return found;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.size() >= suffix.size() && name.ends_with(suffix)) found.push_back(entry.path());
  }
  return found;
}

TEST(Serve, ServesFramesSurvivesBadClientsAndRecordsEverything) {
  TempDir dir("duet-serve-test");
  const fs::path recordings = dir.path / "recordings";
  ServeProcess server;
  std::vector<std::string> args = salsa_pair_args();
  args.insert(args.end(), {"--source", "replay:" + salsa("60", "03") + "?loop=1", "--record",
                           recordings.string(), "--log-interval", "1"});
  ASSERT_TRUE(server.start(args, dir.path / "serve.log")) << server.log();

  WsClient viewer;
  ASSERT_TRUE(viewer.connect(server.port())) << server.log();
  const std::optional<Json> hello = viewer.read_json();
  ASSERT_TRUE(hello) << server.log();
  EXPECT_EQ((*hello)["type"], "hello");
  EXPECT_EQ((*hello)["version"], 1);
  EXPECT_EQ((*hello)["role"], "leader");
  EXPECT_EQ((*hello)["source_kind"], "replay");
  EXPECT_DOUBLE_EQ((*hello)["fps"].get<double>(), 60.0);
  const std::size_t user_joints = (*hello)["user_skeleton"]["joints"].size();
  const std::size_t partner_joints = (*hello)["partner_skeleton"]["joints"].size();
  EXPECT_GT(user_joints, 20u);
  EXPECT_GT(partner_joints, 20u);
  EXPECT_EQ((*hello)["user_skeleton"]["joints"][0]["parent"], -1);
  EXPECT_TRUE((*hello)["partner_skeleton"]["roles"].contains("right_wrist"));
  ASSERT_EQ((*hello)["takes"].size(), 1u);
  EXPECT_EQ((*hello)["takes"][0]["name"], "60_03_scaled");
  EXPECT_EQ((*hello)["takes"][0]["frames"], 1830);
  EXPECT_TRUE((*hello)["takes"][0]["contacts"].is_array());
  for (const char* c : {"align", "contact", "smooth", "footlock", "blend", "foothold"}) {
    EXPECT_EQ((*hello)["corrections"][c], true) << c;
  }

  long long last_seq = -1;
  auto read_frames = [&](int count) {
    for (int k = 0; k < count; ++k) {
      const std::optional<Json> frame = viewer.read_type("frame");
      ASSERT_TRUE(frame) << server.log();
      const long long seq = (*frame)["seq"].get<long long>();
      ASSERT_GT(seq, last_seq);
      last_seq = seq;
      ASSERT_TRUE(valid_pose((*frame)["partner"], partner_joints));
      ASSERT_TRUE(valid_pose((*frame)["user"], user_joints));
      ASSERT_TRUE((*frame)["follower"]["take"].is_number_integer());
      ASSERT_GE((*frame)["latency_us"].get<long long>(), 0);
    }
  };
  read_frames(60);

  // A second client misbehaves in every way the protocol names; each is answered with an error.
  WsClient rogue;
  ASSERT_TRUE(rogue.connect(server.port()));
  ASSERT_TRUE(rogue.read_type("hello"));
  const std::vector<std::string> bad = {
      "not json",
      "[1, 2, 3]",
      "{\"type\": 5}",
      "{\"type\": \"dance\"}",
      "{\"type\": \"set\", \"correction\": \"sparkle\", \"enabled\": true}",
      "{\"type\": \"set\", \"correction\": \"contact\", \"enabled\": \"no\"}",
      "{\"type\": \"role\", \"role\": \"soloist\"}",
      std::string(200, '[') + std::string(200, ']'),
      "{\"type\": \"pose\", \"root\": [0, 0, 0], \"rotations\": []}",  // not a ws source
  };
  for (const std::string& message : bad) {
    ASSERT_TRUE(rogue.write(message));
    const std::optional<Json> error = rogue.read_type("error");
    ASSERT_TRUE(error) << "no error reply to " << message;
    EXPECT_FALSE((*error)["reason"].get<std::string>().empty());
  }
  ASSERT_TRUE(rogue.write("{\"type\": \"reset\"}", /*binary=*/true));
  ASSERT_TRUE(rogue.read_type("error"));
  const std::string oversized =
      "{\"type\": \"set\", \"pad\": \"" + std::string(1536 * 1024, 'x') + "\"}";
  ASSERT_TRUE(rogue.write(oversized));
  const std::optional<Json> too_big = rogue.read_type("error", 20s);
  ASSERT_TRUE(too_big);
  EXPECT_NE((*too_big)["reason"].get<std::string>().find("larger"), std::string::npos);
  // Text that is not UTF-8 breaks the WebSocket protocol itself: that connection is failed (RFC
  // 6455, status 1007) and counted; nobody else notices.
  {
    WsClient mangler;
    ASSERT_TRUE(mangler.connect(server.port()));
    ASSERT_TRUE(mangler.read_type("hello"));
    ASSERT_TRUE(mangler.write("{\"type\": \"set\", \"correction\": \"\xff\xfe\"}"));
    EXPECT_FALSE(mangler.read_type("error", 3s));
  }
  const int rejected_sent = static_cast<int>(bad.size()) + 3;

  // A client that disconnects in the middle of a message, one that leaves in the middle of its
  // HTTP upgrade request.
  {
    WsClient quitter;
    ASSERT_TRUE(quitter.connect(server.port()));
    ASSERT_TRUE(quitter.write_partial("{\"type\": \"set\", \"corr"));
    quitter.drop();
  }
  {
    asio::io_context io;
    tcp::socket raw(io);
    raw.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server.port()));
    const std::string half = "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websock";
    asio::write(raw, asio::buffer(half));
    raw.close();
  }

  // The viewer was never disturbed, and the rogue's connection still works.
  read_frames(60);
  ASSERT_TRUE(rogue.write("{\"type\": \"set\", \"correction\": \"contact\", \"enabled\": false}"));
  bool switched = false;
  for (int k = 0; k < 30 && !switched; ++k) {
    const std::optional<Json> frame = viewer.read_type("frame");
    ASSERT_TRUE(frame);
    last_seq = (*frame)["seq"].get<long long>();
    switched = (*frame)["corrections"]["contact"] == false;
  }
  EXPECT_TRUE(switched);
  const std::optional<Json> stats = rogue.read_type("stats", 20s);
  ASSERT_TRUE(stats);
  EXPECT_GE((*stats)["rejected"].get<int>(), rejected_sent);
  EXPECT_GE((*stats)["clients"].get<int>(), 2);
  EXPECT_TRUE((*stats)["latency_us"].contains("p99"));
  read_frames(10);

  // SIGTERM: a clean exit, and recordings that parse and hold every frame served.
  ASSERT_EQ(server.stop(SIGTERM), 0) << server.log();
  const std::string log = server.log();
  const std::size_t served = log.find("served ");
  ASSERT_NE(served, std::string::npos) << log;
  const long long frames = std::stoll(log.substr(served + 7));
  EXPECT_GT(frames, last_seq);
  EXPECT_TRUE(files_ending(recordings, ".part").empty());
  const std::vector<fs::path> users = files_ending(recordings, "-user.bvh");
  const std::vector<fs::path> partners = files_ending(recordings, "-partner.bvh");
  const std::vector<fs::path> follows = files_ending(recordings, "-follow.csv");
  ASSERT_EQ(users.size(), 1u) << log;
  ASSERT_EQ(partners.size(), 1u);
  ASSERT_EQ(follows.size(), 1u);
  Result<Clip> user = read_bvh(users[0].string());
  ASSERT_TRUE(user) << user.error().message;
  Result<Clip> partner = read_bvh(partners[0].string());
  ASSERT_TRUE(partner) << partner.error().message;
  EXPECT_EQ(user.value().frame_count(), frames);
  EXPECT_EQ(partner.value().frame_count(), frames);
  EXPECT_EQ(static_cast<std::size_t>(partner.value().joint_count()), partner_joints);
  EXPECT_EQ(static_cast<std::size_t>(user.value().joint_count()), user_joints);
  EXPECT_NEAR(user.value().frame_rate(), 60.0, 0.01);
  const std::string csv = read_text(follows[0]);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), frames + 1);
}

TEST(Serve, StaticFilesStayInsideTheWebDirectory) {
  TempDir dir("duet-serve-static-test");
  const fs::path web = dir.path / "web";
  fs::create_directories(web / "assets");
  std::ofstream(web / "index.html") << "<!doctype html><title>viewer</title>";
  std::ofstream(web / "assets" / "app.js") << "console.log('hi');";
  std::ofstream(web / "assets" / "style.css") << "body {}";
  std::ofstream(dir.path / "secret.txt") << "do not serve";
  fs::create_symlink(dir.path / "secret.txt", web / "link.txt");

  ServeProcess server;
  std::vector<std::string> args = salsa_pair_args();
  args.insert(args.end(), {"--source", "ws", "--no-record", "--web", web.string()});
  ASSERT_TRUE(server.start(args, dir.path / "serve.log")) << server.log();
  const std::uint16_t port = server.port();

  auto get = [&](const std::string& target, http::verb verb = http::verb::get) {
    std::optional<HttpReply> reply = http_request(port, verb, target);
    EXPECT_TRUE(reply) << target;
    return reply.value_or(HttpReply{});
  };
  HttpReply index = get("/");
  EXPECT_EQ(index.status, 200);
  EXPECT_EQ(index.content_type, "text/html; charset=utf-8");
  EXPECT_NE(index.body.find("viewer"), std::string::npos);
  EXPECT_EQ(get("/index.html?v=3").status, 200);
  HttpReply js = get("/assets/app.js");
  EXPECT_EQ(js.status, 200);
  EXPECT_EQ(js.content_type, "text/javascript; charset=utf-8");
  EXPECT_EQ(js.body, "console.log('hi');");
  EXPECT_EQ(get("/assets/style.css").content_type, "text/css; charset=utf-8");
  EXPECT_EQ(get("/assets/").status, 404);  // a directory without index.html
  EXPECT_EQ(get("/missing.js").status, 404);
  for (const char* escape :
       {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E%2Fsecret.txt",
        "/..%2fsecret.txt", "/a%00b", "/%zz", "/assets\\..\\..\\secret.txt"}) {
    const HttpReply reply = get(escape);
    EXPECT_TRUE(reply.status == 400 || reply.status == 404) << escape << " -> " << reply.status;
    EXPECT_EQ(reply.body.find("do not serve"), std::string::npos) << escape;
  }
  EXPECT_EQ(get("/link.txt").status, 404);  // a link leading outside
  HttpReply head = get("/assets/app.js", http::verb::head);
  EXPECT_EQ(head.status, 200);
  EXPECT_TRUE(head.body.empty());
  EXPECT_EQ(head.content_length, std::string("console.log('hi');").size());
  EXPECT_EQ(get("/", http::verb::post).status, 405);
  EXPECT_EQ(get("/", http::verb::delete_).status, 405);

  WsClient elsewhere;
  EXPECT_FALSE(elsewhere.connect(port, "/not-ws"));
  WsClient viewer;
  ASSERT_TRUE(viewer.connect(port));
  EXPECT_TRUE(viewer.read_type("hello"));
  EXPECT_EQ(server.stop(SIGINT), 0) << server.log();
}

TEST(Serve, WebSocketPoseSource) {
  TempDir dir("duet-serve-pose-test");
  ServeProcess server;
  std::vector<std::string> args = salsa_pair_args();
  args.insert(args.end(), {"--source", "ws", "--record", (dir.path / "rec").string()});
  ASSERT_TRUE(server.start(args, dir.path / "serve.log")) << server.log();

  MotionLoadOptions load;
  load.frame_rate = 60.0;
  Result<LoadedMotion> motion = load_motion({salsa("60", "03")}, load);
  ASSERT_TRUE(motion) << motion.error().message;
  const Clip& clip = motion.value().clip;

  WsClient dancer;
  ASSERT_TRUE(dancer.connect(server.port()));
  const std::optional<Json> hello = dancer.read_type("hello");
  ASSERT_TRUE(hello);
  ASSERT_EQ((*hello)["user_skeleton"]["joints"].size(),
            static_cast<std::size_t>(clip.joint_count()));

  const int poses = 120;
  for (int f = 0; f < poses; ++f) {
    Json rotations = Json::array();
    for (const Quat& q : clip.rotations_ls(f)) rotations.push_back({q.w(), q.x(), q.y(), q.z()});
    const Vec3 root = clip.translations_ls(f)[0];
    const Json pose = {{"type", "pose"},
                       {"time_s", f / 60.0},
                       {"root", {root.x(), root.y(), root.z()}},
                       {"rotations", rotations}};
    ASSERT_TRUE(dancer.write(pose.dump()));
    const std::optional<Json> frame = dancer.read_type("frame");
    ASSERT_TRUE(frame) << server.log();
    EXPECT_EQ((*frame)["seq"], f);
    EXPECT_NEAR((*frame)["time_s"].get<double>(), f / 60.0, 1e-4);
    // The user's root comes back where it was sent (world = local for the root).
    const Json& p0 = (*frame)["user"]["positions"][0];
    EXPECT_NEAR(p0[0].get<double>(), root.x(), 1e-3);
    EXPECT_NEAR(p0[1].get<double>(), root.y(), 1e-3);
    EXPECT_NEAR(p0[2].get<double>(), root.z(), 1e-3);
  }
  // A pose for another skeleton is refused; the next good one is accepted.
  ASSERT_TRUE(dancer.write(R"({"type": "pose", "root": [0, 1, 0], "rotations": [[1, 0, 0, 0]]})"));
  ASSERT_TRUE(dancer.read_type("error"));
  ASSERT_EQ(server.stop(SIGTERM), 0) << server.log();
  const std::vector<fs::path> users = files_ending(dir.path / "rec", "-user.bvh");
  ASSERT_EQ(users.size(), 1u);
  Result<Clip> recorded = read_bvh(users[0].string());
  ASSERT_TRUE(recorded) << recorded.error().message;
  EXPECT_EQ(recorded.value().frame_count(), poses);
  // Written in the salsa convention's units: duet reads it back at the size it was danced.
  Result<LoadedMotion> reloaded = load_motion({users[0].string()}, MotionLoadOptions{});
  ASSERT_TRUE(reloaded) << reloaded.error().message;
  for (const int f : {0, 60, poses - 1}) {
    EXPECT_LT((reloaded.value().clip.translations_ls(f)[0] - clip.translations_ls(f)[0]).norm(),
              1e-4)
        << f;
  }
}

}  // namespace
}  // namespace duet::test
