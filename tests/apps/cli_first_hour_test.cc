// What a new user meets in the first hour (issue 14): files duet writes read back at their true
// size, failures that must not exit 0, command-line mistakes answered with a clear message and
// exit 2, sizes from the command line bounded.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "apps/run_command.h"

namespace duet::testing {
namespace {

const std::string kAsf = data_path("cmu-salsa/asf-amc/60.asf");
const std::string kAmc = data_path("cmu-salsa/asf-amc/60_01.amc");
const std::string kLeader01 = data_path("cmu-salsa/bvh/60/60_01_scaled.bvh");
const std::string kPartner01 = data_path("cmu-salsa/bvh/61/61_01_scaled.bvh");
const std::string kPair01 = " --pair " + kLeader01 + " " + kPartner01 + " --fps 60";

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("duet_first_hour_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

nlohmann::json inspect_json(const std::string& files) {
  const CommandResult r = run_duet("inspect --json " + files);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? nlohmann::json::parse(r.output) : nlohmann::json();
}

double extent_m(const nlohmann::json& doc, int axis) {
  return doc["bounding_box_m"]["max"][axis].get<double>() -
         doc["bounding_box_m"]["min"][axis].get<double>();
}

// The written file, inspected with no flags, shows the same body as its source (and, unless it
// was moved, the same extent of motion).
void expect_same_size(const nlohmann::json& source, const nlohmann::json& written,
                      bool same_place = true) {
  ASSERT_TRUE(source.contains("body_m") && written.contains("body_m"));
  const double height = source["body_m"]["standing_height"].get<double>();
  EXPECT_GT(height, 1.5);
  EXPECT_NEAR(written["body_m"]["standing_height"].get<double>(), height, 1e-3 * height);
  for (int axis = 0; axis < 3 && same_place; ++axis) {
    EXPECT_NEAR(extent_m(written, axis), extent_m(source, axis), 1e-3) << "axis " << axis;
  }
  EXPECT_EQ(written["units"]["warning"], "");
}

TEST(CliFirstHour, ConvertedAsfAmcReadsBackAtItsTrueSize) {
  const std::string out = temp_path("asf.bvh");
  const CommandResult r = run_duet("convert " + kAsf + " " + kAmc + " -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json converted = inspect_json(out);
  expect_same_size(inspect_json(kAsf + " " + kAmc), converted);
  EXPECT_NEAR(converted["body_m"]["standing_height"].get<double>(), 1.71, 0.05);  // not 0.10
  std::filesystem::remove(out);
}

TEST(CliFirstHour, ConvertedSalsaBvhReadsBackAtItsTrueSize) {
  const std::string out = temp_path("salsa.bvh");
  CommandResult r = run_duet("convert " + kLeader01 + " -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expect_same_size(inspect_json(kLeader01), inspect_json(out));  // not 1.3x too big
  // Other units on request, with the --scale that reads them back.
  r = run_duet("convert " + kLeader01 + " --units-per-metre 100 -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "--scale 0.01")) << r.output;
  expect_same_size(inspect_json(kLeader01), inspect_json("--scale 0.01 " + out));
  std::filesystem::remove(out);
}

TEST(CliFirstHour, FollowOutputsOfAnAsfUserReadBackAtTheirTrueSize) {
  // The user's file comes from an ASF (read in metres); written in metres its CMU joint names
  // would make it read back 18x too small.
  const std::string user = temp_path("user.bvh");
  const std::string partner = temp_path("partner.bvh");
  const CommandResult r = run_duet("follow" + kPair01 + " --input " + kAsf + "+" + kAmc +
                                   " --input-fps 60 -o " + partner + " --user-output " + user);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expect_same_size(inspect_json(kAsf + " " + kAmc), inspect_json(user), false);
  expect_same_size(inspect_json(kPartner01), inspect_json(partner), false);
  std::filesystem::remove(user);
  std::filesystem::remove(partner);
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = temp_path(name);
  std::ofstream(path) << text;
  return path;
}

TEST(CliFirstHour, TruthOfAnotherLibraryIsAnErrorNamingTheFile) {
  // A performance of take 1 of a two-pair library, scored against a one-pair library.
  const std::string perf = temp_path("perf.bvh");
  const std::string truth = temp_path("truth.csv");
  const std::string pair03 = " --pair " + data_path("cmu-salsa/bvh/60/60_03_scaled.bvh") + " " +
                             data_path("cmu-salsa/bvh/61/61_03_scaled.bvh");
  CommandResult r = run_duet("improvise" + kPair01 + pair03 + " --take 1 --duration 4 -o " + perf +
                             " --truth " + truth);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_duet("follow" + kPair01 + " --input " + perf + " --truth " + truth);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, truth + ":2: take 1 is not in the library, which has 1 take(s)"))
      << r.output;
  // The right library scores it.
  r = run_duet("follow" + kPair01 + pair03 + " --input " + perf + " --truth " + truth);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "accuracy against the ground truth")) << r.output;
  // A template frame past the take's end: the library read at another rate.
  std::string text;
  {
    std::ifstream in(truth);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string bad = write_file(
      "bad-truth.csv", text.substr(0, text.find('\n') + 1) + "0,0.000000,1,99999.000,0,0\n");
  r = run_duet("follow" + kPair01 + pair03 + " --input " + perf + " --truth " + bad);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, bad + ":2: template frame 99999 is outside take 1")) << r.output;
  for (const std::string& path : {perf, truth, bad}) std::filesystem::remove(path);
}

TEST(CliFirstHour, SwappedPairOrderExitsThreeAndSaysSo) {
  // --pair PARTNER LEADER while dancing the leader.
  const CommandResult r = run_duet("follow --pair " + kPartner01 + " " + kLeader01 +
                                   " --fps 60 --input " + kLeader01 + " --input-fps 60");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_TRUE(contains(r.output, "check the order of each --pair (LEADER then PARTNER)"))
      << r.output;
}

TEST(CliFirstHour, EveryFrameLostExitsThreeWithCauses) {
  // The salsa leader with arms and legs swapped by a skeleton map: no frame is any part of the
  // dance.
  const std::string map = write_file("swap.json", R"({"name": "arms-as-legs", "roles": {
    "hips": "hip", "spine": "abdomen", "chest": "chest", "neck": "neck", "head": "head",
    "left_shoulder": "rThigh", "left_elbow": "rShin", "left_wrist": "rFoot",
    "right_shoulder": "lThigh", "right_elbow": "lShin", "right_wrist": "lFoot",
    "left_hip": "rShldr", "left_knee": "rForeArm", "left_ankle": "rHand", "left_toe": "rMid2",
    "right_hip": "lShldr", "right_knee": "lForeArm", "right_ankle": "lHand", "right_toe": "lMid2"}})");
  CommandResult r =
      run_duet("follow" + kPair01 + " --input " + kLeader01 + " --input-fps 60 --input-map " + map);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_TRUE(contains(r.output, "100% of the input's frames are lost")) << r.output;
  EXPECT_TRUE(contains(r.output, "Likely causes")) << r.output;
  r = run_duet("follow" + kPair01 + " --input " + kLeader01 + " --input-fps 60 --input-map " + map +
               " --allow-lost");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::filesystem::remove(map);
}

// A bad command line exits 2 with a message that names the mistake.
void expect_usage_error(const std::string& arguments, const std::string& message) {
  const CommandResult r = run_duet(arguments);
  EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.output;
  EXPECT_TRUE(contains(r.output, message)) << arguments << "\n" << r.output;
  EXPECT_LT(r.output.size(), 400u) << arguments << "\n" << r.output;  // no 309-digit bounds
}

TEST(CliFirstHour, UnknownOptionsAndCommandsAreNamedWithTheClosestValidOne) {
  const std::string library = std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml";
  expect_usage_error("follow --fsp 60 --library " + library + " --input " + kLeader01,
                     "duet follow: unknown option --fsp (did you mean --fps?)");
  // CLI11 alone took the 60 for the file argument: "File does not exist: 60".
  expect_usage_error("inspect --fsp 60 " + kLeader01,
                     "duet inspect: unknown option --fsp (did you mean --fps?)");
  expect_usage_error("convert " + kLeader01 + " -o x.bvh --fps=30 --unit-per-metre=100",
                     "unknown option --unit-per-metre (did you mean --units-per-metre?)");
  expect_usage_error("eval --noise-dg 3", "unknown option --noise-dg (did you mean --noise-deg?)");
  expect_usage_error("folow", "duet: unknown command 'folow' (did you mean 'follow'?)");
  expect_usage_error("inpsect " + kLeader01, "unknown command 'inpsect' (did you mean 'inspect'?)");
  expect_usage_error("frobnicate", "the commands are inspect, convert, follow");
  // Still understood: the main app's flags, negative numbers as values.
  EXPECT_EQ(run_duet("--version").exit_code, 0);
  EXPECT_EQ(run_duet("inspect --help").exit_code, 0);
}

TEST(CliFirstHour, FrameRatesAndScalesOutsideTheirRangesAreBadCommandLines) {
  for (const char* fps : {"0", "-3", "nan", "inf", "1e9", "1e400", "0.5", "60fps"}) {
    expect_usage_error(std::string("inspect --fps ") + fps + " " + kLeader01,
                       "--fps: must be between 1 and 1000 fps");
  }
  for (const char* scale : {"1e-300", "1e300", "0", "nan"}) {
    expect_usage_error(std::string("inspect --scale ") + scale + " " + kLeader01,
                       "--scale: must be between 0.0001 and 1000 metres per file unit");
  }
  // The same check for every command that reads motion.
  expect_usage_error("follow" + kPair01 + " --input " + kLeader01 + " --input-fps nan",
                     "--input-fps: must be between 1 and 1000 fps");
  expect_usage_error(
      "follow --pair " + kLeader01 + " " + kPartner01 + " --fps 0 --input " + kLeader01,
      "--fps: must be between 1 and 1000 fps");
  expect_usage_error("convert " + kLeader01 + " -o x.bvh --fps 1e9",
                     "--fps: must be between 1 and 1000 fps");
  expect_usage_error("convert " + kLeader01 + " -o x.bvh --scale 1e300",
                     "--scale: must be between 0.0001 and 1000");
  expect_usage_error("improvise --from " + kLeader01 + " -o x.bvh --rate 1e-300",
                     "--rate: must be between 1 and 1000 fps");
  expect_usage_error("improvise --from " + kLeader01 + " -o x.bvh --tempo nan",
                     "--tempo: must be between 0.1 and 10");
  expect_usage_error(
      "retarget " + kLeader01 + " --rig " + kLeader01 + " --rig-scale 1e-300 -o x.bvh",
      "--rig-scale: must be between 0.0001 and 1000");
  // In range is fine.
  EXPECT_EQ(run_duet("inspect --fps 1000 --scale 0.0001 " + kLeader01).exit_code, 0);
}

TEST(CliFirstHour, PairWithOneFileIsABadCommandLine) {
  expect_usage_error("follow --pair " + kLeader01 + " --input " + kLeader01,
                     "--pair: takes two files, LEADER and PARTNER; got only");
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(CliFirstHour, SizesFromTheCommandLineAreBoundedWithAClearError) {
  // Was an uncaught std::length_error (exit 134).
  expect_usage_error("convert " + kLeader01 + " -o x.bvh --fps 1e9", "--fps: must be between");
  // Two frames 20000 s apart (a salsa skeleton): 1000 fps would be 2e7 frames.
  const std::string text = read_text(kLeader01);
  const std::size_t motion = text.find("Frame Time:");
  const std::size_t first_line = text.find('\n', motion) + 1;
  const std::size_t third_line = text.find('\n', text.find('\n', first_line) + 1) + 1;
  const std::string slow = write_file(
      "slow.bvh", text.substr(0, text.find("Frames:")) + "Frames: 2\nFrame Time: 20000\n" +
                      text.substr(first_line, third_line - first_line));
  const std::string out = temp_path("resampled.bvh");
  CommandResult r = run_duet("convert " + slow + " --fps 1000 -o " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "--fps 1000 would make 2e+07 frames of " + slow +
                                     ", over the limit of 10000000 frames per clip"))
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // A day at 1000 Hz.
  r = run_duet("improvise --from " + kLeader01 + " --fps 60 --duration 86400 --rate 1000 -o " +
               out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "8.64e+07 frames, over the limit of 10000000 frames per clip"))
      << r.output;
  std::filesystem::remove(slow);
  std::filesystem::remove(out);
}

TEST(CliFirstHour, NoExceptionEndsTheToolWithAnAbort) {
  // Joint names that are not UTF-8: nlohmann::json threw from inspect --json (exit 134).
  const std::string latin1 =
      write_file("latin1.bvh",
                 "HIERARCHY\nROOT h\xfc"
                 "fte\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition "
                 "Zposition\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: "
                 "0.1\n0 0 0\n");
  CommandResult r = run_duet("inspect --json " + latin1);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["joint_names"][0],
            "h\xef\xbf\xbd"
            "fte");
  std::filesystem::remove(latin1);

  // A library folder with a subject number past 19 digits: std::stoll threw.
  const std::filesystem::path dir = temp_path("library");
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink(kLeader01, dir / "60_01.bvh");
  std::filesystem::create_symlink(kPartner01, dir / "61000000000000000000000_01.bvh");
  r = run_duet("follow --library " + dir.string() + " --fps 60 --input " + kLeader01 +
               " --input-fps 60");
  EXPECT_EQ(r.exit_code, 0) << r.output;  // 60 is the smaller number: the leader
  std::filesystem::remove_all(dir);

  // Whatever else escapes a command is reported as a bug, with exit 1.
  ::setenv("DUET_TEST_THROW", "1", 1);
  r = run_duet("inspect " + kLeader01);
  ::unsetenv("DUET_TEST_THROW");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "duet: internal error: DUET_TEST_THROW")) << r.output;
}

TEST(CliFirstHour, OutputToAPipeOrDeviceIsWrittenNotReplaced) {
  // `-o /dev/null` as root renamed a regular file over the device. A FIFO stands in for it here
  // (a regression would leave the reader waiting: hence its timeout).
  const std::filesystem::path dir = temp_path("fifo");
  std::filesystem::create_directories(dir);
  const std::string fifo = (dir / "out.bvh").string();
  const std::string copy = (dir / "copy.bvh").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string command = "timeout 20 cat " + fifo + " > " + copy + " & " +
                              std::string(DUET_BINARY) + " convert " + kLeader01 + " -o " + fifo +
                              " 2>/dev/null; status=$?; wait; exit $status";
  EXPECT_EQ(std::system(command.c_str()), 0);
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_TRUE(read_text(copy).starts_with("HIERARCHY")) << read_text(copy).substr(0, 100);
  EXPECT_FALSE(std::filesystem::exists(fifo + ".tmp"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace duet::testing
