// `duet eval` and `duet improvise` end to end, through the binary, on two short salsa takes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "apps/run_command.h"
#include "duet/eval/partner_run.h"

namespace duet {
namespace {

using testing::data_path;
using testing::run_duet;

std::string pair(const std::string& trial) {
  return "--pair " + data_path("cmu-salsa/bvh/60/60_" + trial + "_scaled.bvh") + " " +
         data_path("cmu-salsa/bvh/61/61_" + trial + "_scaled.bvh");
}

std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("duet_eval_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, sep)) out.push_back(cell);
  return out;
}

// Pooled rows of the eval CSV: (case, tracker) -> column -> value.
std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> pooled_rows(
    const std::string& csv) {
  std::stringstream s(csv);
  std::string line;
  std::getline(s, line);
  const std::vector<std::string> header = split(line, ',');
  std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> rows;
  while (std::getline(s, line)) {
    const std::vector<std::string> cells = split(line, ',');
    if (cells.size() < 3 || cells[2] != "all") continue;
    auto& row = rows[{cells[0], cells[1]}];
    for (std::size_t c = 0; c < header.size() && c < cells.size(); ++c) row[header[c]] = cells[c];
  }
  return rows;
}

TEST(CliEval, RunsCasesAndWritesTableCsvAndPlots) {
  const auto dir = scratch_dir("run");
  const std::string csv = (dir / "eval.csv").string();
  const std::string plots = (dir / "plots").string();
  const bool have_gnuplot = std::system("command -v gnuplot >/dev/null 2>&1") == 0;
  const std::string partner_csv = (dir / "partner.csv").string();
  const auto r = run_duet("eval " + pair("10") + " " + pair("05") +
                          " --fps 60 --takes 0 --cases clean,improv-pause,partner-role "
                          "--trackers hmm,nearest,naive-hmm --seed 3 --csv " +
                          csv + " --partner-csv " + partner_csv +
                          (have_gnuplot ? " --plots " + plots : std::string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The table: a header and one row per case x tracker.
  EXPECT_NE(r.output.find("acc@100"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("improv-pause"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("naive O(M^2) forward"), std::string::npos) << r.output;

  const auto rows = pooled_rows(read_text(csv));
  ASSERT_EQ(rows.size(), 6u) << read_text(csv);
  // Plausible numbers: the follower on the unperturbed take is nearly always right.
  const auto& clean = rows.at({"clean", "hmm"});
  EXPECT_GT(std::stod(clean.at("acc_100ms")), 0.9) << r.output;
  EXPECT_GT(std::stod(rows.at({"partner-role", "hmm"}).at("acc_100ms")), 0.8) << r.output;
  const auto& improv = rows.at({"improv-pause", "hmm"});
  EXPECT_GT(std::stoi(improv.at("jumps")), 3);
  EXPECT_GT(std::stoi(improv.at("pause_frames")), 0);
  EXPECT_GT(std::stod(improv.at("acc_100ms")), 0.6) << r.output;
  // What the user could see: never below acc@100, which it contains.
  for (const auto& [key, row] : rows) {
    EXPECT_GE(std::stod(row.at("acc_100ms_alike")), std::stod(row.at("acc_100ms")))
        << key.first << " " << key.second;
  }
  EXPECT_NE(r.output.find("alike"), std::string::npos) << r.output;
  // The clean take is found at once and followed from there.
  EXPECT_LT(std::stod(clean.at("median_find_s")), 0.5) << r.output;
  EXPECT_GE(std::stod(clean.at("acc_100ms_found")), std::stod(clean.at("acc_100ms")));
  EXPECT_NE(r.output.find("find s"), std::string::npos) << r.output;
  EXPECT_GT(std::stod(clean.at("mean_step_us")), 0.0);
  // The naive forward agrees with the O(M) one.
  const std::string text = read_text(csv);
  EXPECT_NE(text.find(",naive-hmm,0,60_10_scaled,"), std::string::npos);
  // Partner metrics: a table section and one pooled row per case x corrections.
  EXPECT_NE(r.output.find("partner metrics"), std::string::npos) << r.output;
  const auto partner_rows = pooled_rows(read_text(partner_csv));
  ASSERT_EQ(partner_rows.size(), 3u * standard_partner_configs().size()) << read_text(partner_csv);
  const auto& clean_all = partner_rows.at({"clean", "all"});
  EXPECT_LT(std::stod(clean_all.at("mean_joint_error_cm")), 5.0);
  EXPECT_GT(std::stoi(clean_all.at("hand_samples")), 100);
  EXPECT_LT(std::stod(clean_all.at("median_hand_error_cm")), 3.0);
  EXPECT_GT(std::stoi(partner_rows.at({"improv-pause", "no-blend"}).at("jumps")), 3);
  if (have_gnuplot) {
    EXPECT_GT(std::filesystem::file_size(std::filesystem::path(plots) / "accuracy.png"), 1000u);
    EXPECT_GT(std::filesystem::file_size(std::filesystem::path(plots) / "trace.png"), 1000u);
  }
  std::filesystem::remove_all(dir);
}

TEST(CliEval, BadOptionsExitTwoAndBadFilesExitOne) {
  const std::string pairs = pair("10") + " --fps 60";
  // Each bad command line, and what its message must name ("" for the exit code alone).
  const std::pair<std::string, std::string> bad_options[] = {
      {"--cases clean,bogus", "unknown case 'bogus'"},
      {"--takes 1", "--takes 1"},
      {"--takes 0-1", "--takes 0-1: the library has 1 pair (takes 0..0)"},
      {"--takes first", "expected a take index, FIRST-LAST or all"},
      {"--trackers hmm,magic", ""},
      {"--sigma -1", ""},
      {"--trace-case nothing", ""},
      {"--no-partner-metrics --partner-csv x.csv", "--partner-csv"},
      {"--device-offsets-cm 8,7,8", "--device-offsets-cm"},  // full body: no devices
      {"--input-points head,hands --device-offsets-cm 8,7", ""},
      {"--input-points head,hands --device-offsets-cm 8,7,80", "between -30 and 30 cm"},
      {"--taken-out-offsets-cm 6,6,7", "--taken-out-offsets-cm"},  // full body: no devices
      {"--input-points head,hands --taken-out-offsets-cm 6,nan,7", "--taken-out-offsets-cm"},
  };
  testing::CommandResult r;
  for (const auto& [options, named] : bad_options) {
    r = run_duet("eval " + pairs + " " + options);
    EXPECT_EQ(r.exit_code, 2) << options << ": " << r.output;
    if (!named.empty()) {
      EXPECT_NE(r.output.find(named), std::string::npos) << r.output;
    }
  }

  const auto dir = scratch_dir("bad");
  const std::string garbage = (dir / "garbage.bvh").string();
  std::ofstream(garbage) << "HIERARCHY\nROOT hip\n{\n";
  r = run_duet("eval --pair " + garbage + " " + garbage + " --fps 60 --cases clean");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("garbage.bvh"), std::string::npos) << r.output;
  std::filesystem::remove_all(dir);
}

TEST(CliEval, TakesAreIndicesRangesOrAll) {
  const std::string base = "eval " + pair("10") + " " + pair("05") + " " + pair("01") +
                           " --fps 60 --trackers nearest --cases clean --no-partner-metrics "
                           "--non-dance none --takes ";
  const std::pair<std::string, std::string> lists[] = {
      {"1-2", "performances from takes 1 (60_05_scaled), 2 (60_01_scaled);"},
      {"all", "takes 0 (60_10_scaled), 1 (60_05_scaled), 2 (60_01_scaled);"},
      {"2,0-1,2", "takes 2 (60_01_scaled), 0 (60_10_scaled), 1 (60_05_scaled);"},
  };
  for (const auto& [list, named] : lists) {
    const auto r = run_duet(base + list);
    ASSERT_EQ(r.exit_code, 0) << list << ": " << r.output;
    EXPECT_NE(r.output.find(named), std::string::npos) << list << ": " << r.output;
  }
  const auto backwards = run_duet(base + "2-1");
  EXPECT_EQ(backwards.exit_code, 2) << backwards.output;
  EXPECT_NE(backwards.output.find("--takes 2-1: the range ends before it begins"),
            std::string::npos)
      << backwards.output;
}

TEST(CliEval, ScoresARecordingOfATakeOnItsOwnRig) {
  // Issue 10: take 01 as CMU captured it (the original ASF/AMC, another skeleton fit than the
  // library's BVH) scored like a case, the partner metrics included. --recorded alone runs only it.
  const auto dir = scratch_dir("recorded");
  const std::string csv = (dir / "eval.csv").string();
  const std::string partner_csv = (dir / "partner.csv").string();
  const std::string recording =
      data_path("cmu-salsa/asf-amc/60.asf") + "+" + data_path("cmu-salsa/asf-amc/60_01.amc");
  const auto r = run_duet("eval " + pair("01") + " " + pair("03") +
                          " --fps 60 --trackers hmm --recorded 0=" + recording +
                          " --recorded-fps 60 --csv " + csv + " --partner-csv " + partner_csv);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = pooled_rows(read_text(csv));
  ASSERT_EQ(rows.size(), 1u) << read_text(csv);
  const auto& followed = rows.at({"recorded-60_01_scaled", "hmm"});
  EXPECT_GE(std::stod(followed.at("acc_100ms")), 0.99) << r.output;
  const auto partner_rows = pooled_rows(read_text(partner_csv));
  // The contact IK meets the hands of a body the library's rig does not have.
  const double with_ik =
      std::stod(partner_rows.at({"recorded-60_01_scaled", "all"}).at("median_hand_error_cm"));
  const double without_ik = std::stod(
      partner_rows.at({"recorded-60_01_scaled", "no-contact"}).at("median_hand_error_cm"));
  EXPECT_LT(with_ik, 2.0) << r.output;
  EXPECT_GT(without_ik, 2.0 * with_ik) << r.output;

  // Bad entries name themselves and fail before the run.
  for (const std::string& entry :
       {std::string("0"), "7=" + recording, std::string("0=/no/such/take.bvh")}) {
    const auto bad = run_duet("eval " + pair("01") + " --fps 60 --recorded " + entry);
    EXPECT_EQ(bad.exit_code, 1) << bad.output;
    EXPECT_NE(bad.output.find("--recorded " + entry), std::string::npos) << bad.output;
    EXPECT_EQ(bad.output.find("evaluating"), std::string::npos) << bad.output;
  }
  std::filesystem::remove_all(dir);
}

TEST(CliEval, DeliversCasesOnRigsOfAnotherBuild) {
  // Issue 10: the rigs made in code (a game avatar with twist joints in an A-pose, a depth
  // camera's body without clavicles, an inertial suit's five-joint spine), their roles found by
  // role detection: followed as on the library's rig, the partner's hands met on each body.
  const auto dir = scratch_dir("generic_rigs");
  const std::string csv = (dir / "eval.csv").string();
  const std::string partner_csv = (dir / "partner.csv").string();
  const std::string rigs[] = {"game-avatar", "depth-camera", "inertial-suit"};
  const auto r = run_duet("eval " + pair("01") + " " + pair("03") +
                          " --fps 60 --trackers hmm --cases clean --non-dance none "
                          "--rigs game-avatar,depth-camera,inertial-suit --csv " +
                          csv + " --partner-csv " + partner_csv);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = pooled_rows(read_text(csv));
  const auto partner_rows = pooled_rows(read_text(partner_csv));
  for (const std::string& rig : rigs) {
    const std::string row = "clean@" + rig;
    ASSERT_EQ(rows.count({row, "hmm"}), 1u) << read_text(csv);
    EXPECT_GE(std::stod(rows.at({row, "hmm"}).at("acc_100ms")), 0.98) << row;
    ASSERT_EQ(partner_rows.count({row, "all"}), 1u) << read_text(partner_csv);
    EXPECT_LT(std::stod(partner_rows.at({row, "all"}).at("median_hand_error_cm")), 2.0) << row;
  }
  const auto bad = run_duet("eval " + pair("01") + " --fps 60 --rigs game-avatr");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("game-avatar, depth-camera, inertial-suit"), std::string::npos)
      << bad.output;
  std::filesystem::remove_all(dir);
}

TEST(CliEval, ARecordingAtAnotherRateThanItsTakeFailsBeforeTheRun) {
  // The AMC read at the loader's 120 fps default has the take's frame count in half its time:
  // scored, every frame's truth would be off by 2x (0.3 % within 100 ms with 0.4 % lost).
  const std::string recording =
      data_path("cmu-salsa/asf-amc/60.asf") + "+" + data_path("cmu-salsa/asf-amc/60_01.amc");
  const auto r =
      run_duet("eval " + pair("01") + " --fps 60 --trackers hmm --recorded 0=" + recording +
               " --no-partner-metrics");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("one of the two frame rates is wrong"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--recorded-fps 60"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("evaluating"), std::string::npos) << r.output;
}

TEST(CliEval, ReportsNonDanceInputAsLost) {
  // Issue 11: motion no part of the library explains (the Bandai walk, dance and wave, on
  // another studio's rig) is reported lost on nearly every frame; a missing clip fails before
  // the evaluation runs.
  const std::string pairs = pair("10") + " --fps 60 --cases clean --no-partner-metrics";
  auto r = run_duet("eval " + pairs + " --non-dance bandai --data-dir " + data_path(""));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::size_t section = r.output.find("non-dance input");
  ASSERT_NE(section, std::string::npos) << r.output;
  for (const char* clip : {"walk", "dance-short", "byebye"}) {
    const std::size_t at = r.output.find(std::string("  ") + clip + " ", section);
    ASSERT_NE(at, std::string::npos) << clip << "\n" << r.output;
    const double lost = std::stod(r.output.substr(at + 2 + std::string(clip).size()));
    EXPECT_GE(lost, 95.0) << clip;
  }
  // The clips shorter than half a minute are also followed looped to it; the walk stays lost.
  for (const char* clip : {"walk looped", "byebye looped"}) {
    const std::size_t at = r.output.find(std::string("  ") + clip + " ", section);
    ASSERT_NE(at, std::string::npos) << clip << "\n" << r.output;
    const std::size_t of = r.output.find(" of ", at);
    ASSERT_NE(of, std::string::npos);
    EXPECT_GE(std::stoi(r.output.substr(of + 4)), 30 * 30) << clip;  // 30 s of the 30 Hz clip
    // The wave held for half a minute was 19 % lost while the lost level learnt from it
    // (explained_residual.h); the posture offset still makes parts of it look like salsa.
    const double lost = std::stod(r.output.substr(at + 2 + std::string(clip).size()));
    EXPECT_GE(lost, std::string(clip) == "walk looped" ? 95.0 : 80.0) << clip;
  }
  EXPECT_EQ(r.output.find("dance-short looped"), std::string::npos) << r.output;  // 63 s already
  EXPECT_NE(r.output.find("hmm, exact step"), std::string::npos) << r.output;

  // Under --beam the clips are followed in beam mode too, and still lost.
  r = run_duet("eval " + pairs + " --beam --non-dance bandai --data-dir " + data_path(""));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("non-dance input (motion no part of the library explains; hmm, beam "
                          "mode)"),
            std::string::npos)
      << r.output;
  for (const char* clip : {"walk", "dance-short", "byebye"}) {
    const std::size_t at = r.output.find(std::string("  ") + clip + " ");
    ASSERT_NE(at, std::string::npos) << clip << "\n" << r.output;
    EXPECT_GE(std::stod(r.output.substr(at + 2 + std::string(clip).size())), 95.0) << clip;
  }

  // Against the whole salsa library the wave's arm coming down is a take's standing pose; held
  // for half a minute it was followed in runs of 1-27 frames (93.6 % lost) until a dancer found
  // again after a spell lost had to hold the dance (FollowParams::found_confirm_per_lost_s).
  const std::string library = std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml";
  const std::string wave = "dataset-1_byebye_normal_001";
  r = run_duet("eval --library " + library + " --data-dir " + data_path("") +
               " --trackers hmm --takes 0 --cases clean --no-partner-metrics --non-dance " +
               data_path("bandai/" + wave + ".bvh"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::size_t looped = r.output.find("  " + wave + " looped ");
  ASSERT_NE(looped, std::string::npos) << r.output;
  EXPECT_GE(std::stod(r.output.substr(looped + 2 + wave.size() + 8)), 95.0) << r.output;
  r = run_duet("eval " + pairs + " --non-dance none");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("non-dance input"), std::string::npos) << r.output;
  r = run_duet("eval " + pairs + " --non-dance /no/such/walk.bvh");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("walk.bvh"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("evaluating"), std::string::npos) << r.output;  // before the run
}

TEST(CliEval, BeamModeFindsTheDanceWhereTheExactStepFindsIt) {
  // Against the whole salsa library, seed 1, where the beam once pruned the place the exact step
  // found the dance at: take 60_02 as an inertial suit with its calibration error, whose standing
  // start spreads the posterior over many takes' standing frames (88.9 % within 100 ms against
  // the exact step's 96.7 %; BeamParams::deep_prune_ratio until settled), and take 60_13 on the
  // CMU ASF rig, followed on 60_06's standing start until 60_13's fitted better (89.1 against
  // 92.0 %; BeamParams::well_fitting_ratio). The beam may do better than the exact step, not worse:
  // since the hands' speeds are measured on a standard arm (session 48) the suit's take 60_02 is
  // 94.3 % within 100 ms by the exact step (96.7 before) and 95.9 % by the beam.
  const auto dir = scratch_dir("beam");
  const std::string library = std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml";
  const std::string base = "eval --library " + library + " --data-dir " + data_path("") +
                           " --trackers hmm --seed 1 --no-partner-metrics --non-dance none ";
  const struct {
    std::string options, row;
    double exact_at_least;
  } cases[] = {{"--takes 1 --cases suit-drift", "suit-drift", 0.94},
               {"--takes 11 --cases clean --rigs asf", "clean@asf", 0.9}};
  for (const auto& c : cases) {
    std::map<std::string, double> accuracy;
    for (const std::string mode : {"exact", "beam"}) {
      const std::string csv = (dir / (mode + ".csv")).string();
      const auto r =
          run_duet(base + c.options + " --csv " + csv + (mode == "beam" ? " --beam" : ""));
      ASSERT_EQ(r.exit_code, 0) << r.output;
      const auto rows = pooled_rows(read_text(csv));
      ASSERT_EQ(rows.count({c.row, "hmm"}), 1u) << read_text(csv);
      accuracy[mode] = std::stod(rows.at({c.row, "hmm"}).at("acc_100ms"));
    }
    EXPECT_GT(accuracy["exact"], c.exact_at_least) << c.options;
    EXPECT_GE(accuracy["beam"], accuracy["exact"] - 0.005) << c.options;
  }
  std::filesystem::remove_all(dir);
}

TEST(CliEval, AStandingStartOnAnotherRigIsFollowedOnItsOwnTake) {
  // Takes 60_13 and 60_15 retargeted onto the CMU ASF rig (seed 1): their standing starts were
  // followed on other takes' for 2-3 s (91.8 and 94.0 % within 100 ms) while the hands' speeds
  // were measured on the rig's hands, whose shoulders stand twice as wide; on a standard arm
  // (FeatureSpec::standard_arm_speeds) 99.96 and 99.91 %.
  const auto dir = scratch_dir("standing-start");
  const std::string csv = (dir / "asf.csv").string();
  const std::string library = std::string(DUET_TESTDATA_DIR) + "/../../libraries/cmu-salsa.toml";
  const auto r = run_duet("eval --library " + library + " --data-dir " + data_path("") +
                          " --trackers hmm --seed 1 --no-partner-metrics --non-dance none "
                          "--takes 11,13 --cases clean --rigs asf --csv " +
                          csv);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto rows = pooled_rows(read_text(csv));
  ASSERT_EQ(rows.count({"clean@asf", "hmm"}), 1u) << read_text(csv);
  EXPECT_GT(std::stod(rows.at({"clean@asf", "hmm"}).at("acc_100ms")), 0.995);
  std::filesystem::remove_all(dir);
}

TEST(CliEval, ThreePointsHoldOnlyFromAPlaceFollowedAWhileUnlessAsked) {
  // The hold for a far place the input fits poorly: three points are made with a shorter one than
  // the full body, as `duet follow` and `duet serve` make them; an option asked for stays.
  const std::string base = "eval " + pair("10") +
                           " --fps 60 --trackers hmm --cases clean --no-partner-metrics "
                           "--non-dance none";
  auto r = run_duet(base);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("unexplained_jump_hold 0.4 s (over 2.2 x noise, after 2 s followed)"),
            std::string::npos)
      << r.output;
  r = run_duet(base + " --input-points head,hands");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("unexplained_jump_hold 0.3 s (over 2.2 x noise, after 2 s followed)"),
            std::string::npos)
      << r.output;
  r = run_duet(
      base +
      " --input-points head,hands --unexplained-jump-hold 0 --unexplained-jump-hold-after 1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("unexplained_jump_hold 0 s (over 2.2 x noise, after 1 s followed)"),
            std::string::npos)
      << r.output;
  r = run_duet(base + " --unexplained-jump-ratio 0");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = run_duet(base + " --unexplained-jump-hold-after -1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(CliEval, DistanceCapsTakeANumberOrInf) {
  // A cap on a part of the emission distance: inf turns it off, as FollowParams documents.
  const std::string base = "eval " + pair("10") +
                           " --fps 60 --trackers hmm --cases clean --no-partner-metrics "
                           "--non-dance none";
  auto r = run_duet(base + " --limb-outlier-ratio inf --velocity-cap inf");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("velocity_cap inf limb_outlier inf x"), std::string::npos) << r.output;
  r = run_duet(base);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("velocity_cap 0.05 limb_outlier 3 x (floor 0.15)"), std::string::npos)
      << r.output;
  for (const char* bad : {"-1", "nan", "many"}) {
    r = run_duet(base + " --limb-outlier-ratio " + bad);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(std::string("--limb-outlier-ratio: must be a finite number >= 0 or "
                                        "inf, got '") +
                            bad + "'"),
              std::string::npos)
        << r.output;
  }
  // Below 1 the farthest limb would count less than the second: the parameters say so.
  r = run_duet(base + " --limb-outlier-ratio 0.5");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("limb_outlier_ratio must be >= 1"), std::string::npos) << r.output;
}

TEST(CliImprovise, WritesAPerformanceAndItsTruthThatFollowReads) {
  const auto dir = scratch_dir("improvise");
  const std::string perf = (dir / "perf.bvh").string();
  const std::string truth = (dir / "truth.csv").string();
  auto r = run_duet("improvise " + pair("05") + " " + pair("10") +
                    " --fps 60 --take 1 --rate 30 --noise-deg 2 --seed 4 -o " + perf + " --truth " +
                    truth);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string truth_text = read_text(truth);
  std::stringstream lines(truth_text);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "frame,time_s,take,template_frame,in_pause,jump");
  int frames = 0, jumps = 0;
  while (std::getline(lines, line)) {
    const auto cells = split(line, ',');
    ASSERT_EQ(cells.size(), 6u);
    EXPECT_EQ(cells[2], "1");  // take index among the pairs given
    jumps += cells[5] == "1" ? 1 : 0;
    ++frames;
  }
  EXPECT_GT(jumps, 2);
  // 1197 frames at 60 Hz = 19.95 s at 30 Hz.
  EXPECT_NEAR(frames, 19.95 * 30, 2);

  const std::string trace = (dir / "trace.csv").string();
  r = run_duet("follow " + pair("05") + " " + pair("10") + " --fps 60 --input " + perf +
               " --trace " + trace);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string trace_text = read_text(trace);
  EXPECT_EQ(std::count(trace_text.begin(), trace_text.end(), '\n'), frames + 1);

  // Usage errors.
  r = run_duet("improvise -o " + perf);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = run_duet("improvise " + pair("05") + " --take 3 -o " + perf);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace duet
