// Library files, --library DIR recognition, ASF+AMC pair members, known dataset rates: on the
// real salsa data and the shipped libraries/*.toml.
#include "duet/live/library_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "duet/follow/hmm_follower.h"
#include "duet/io/known_datasets.h"
#include "duet/io/motion_argument.h"
#include "duet/live/follow_session.h"

namespace duet {
namespace {

namespace fs = std::filesystem;

const std::string kData = DUET_DATA_DIR;
const std::string kSalsa = kData + "/cmu-salsa";
const std::string kLibraries = std::string(DUET_TESTDATA_DIR) + "/../../libraries";

std::string bvh(const std::string& subject, const std::string& trial) {
  return kSalsa + "/bvh/" + subject + "/" + subject + "_" + trial + "_scaled.bvh";
}

// A temporary directory holding one library file with the given text.
struct TempLibrary {
  fs::path dir;
  fs::path file;
  explicit TempLibrary(const std::string& text, const std::string& name = "lib.toml") {
    dir = fs::temp_directory_path() /
          ("duet_library_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
           "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    file = dir / name;
    std::ofstream(file) << text;
  }
  ~TempLibrary() { fs::remove_all(dir); }
};

std::string error_of(const std::string& text) {
  TempLibrary lib(text);
  Result<LibrarySpec> spec = read_library_file(lib.file.string(), kData);
  return spec ? std::string("(no error)") : spec.error().message;
}

TEST(LibraryFile, ShippedSalsaFileLoadsTheSameLibraryAsFourteenPairOptions) {
  Result<LibrarySpec> spec = read_library(kLibraries + "/cmu-salsa.toml", kData);
  ASSERT_TRUE(spec) << spec.error().message;
  ASSERT_EQ(spec.value().pairs.size(), 14u);
  EXPECT_EQ(spec.value().frame_rate, 60.0);  // the 120 fps header trap, handled once
  EXPECT_EQ(spec.value().leader_name, "subject 60 (male)");
  EXPECT_EQ(spec.value().pairs[2].leader, MotionFiles{bvh("60", "03")});
  EXPECT_EQ(spec.value().pairs[2].partner, MotionFiles{bvh("61", "03")});

  LibraryOptions options;
  options.load.frame_rate = spec.value().frame_rate;
  Result<DuetLibrary> from_file = DuetLibrary::load(spec.value().pairs, options);
  ASSERT_TRUE(from_file) << from_file.error().message;
  // What 14 --pair options typed by hand give (with --fps 60).
  std::vector<PairFiles> by_hand;
  for (const char* t :
       {"01", "02", "03", "04", "05", "06", "07", "09", "10", "11", "12", "13", "14", "15"}) {
    by_hand.push_back({{bvh("60", t)}, {bvh("61", t)}});
  }
  options.load.frame_rate = 60.0;
  Result<DuetLibrary> typed = DuetLibrary::load(by_hand, options);
  ASSERT_TRUE(typed) << typed.error().message;
  EXPECT_EQ(from_file.value().model().num_states(), typed.value().model().num_states());
  EXPECT_EQ(from_file.value().model().num_states(), 27495);  // the data README table's sum
  EXPECT_DOUBLE_EQ(from_file.value().frame_rate(), 60.0);
  EXPECT_EQ(from_file.value().takes()[2].name, "03");
}

TEST(LibraryFile, AsfAmcFileResolvesTheDownloadLayout) {
  // The originals' library points at data/cmu-salsa/asf-amc; only 60.asf + 60_01.amc are in the
  // shared folder, so it must stop at the first missing file and name it with its key and line.
  Result<LibrarySpec> spec = read_library(kLibraries + "/cmu-salsa-asf-amc.toml", kData);
  ASSERT_FALSE(spec);
  EXPECT_NE(spec.error().message.find("cmu-salsa-asf-amc.toml:"), std::string::npos);
  EXPECT_NE(spec.error().message.find("key 'pair 1.partner': no such file: " + kSalsa +
                                      "/asf-amc/61.asf"),
            std::string::npos)
      << spec.error().message;
}

TEST(LibraryFile, ErrorsNameTheFileTheLineAndTheKey) {
  Result<LibrarySpec> missing = read_library("/nonexistent/salsa.toml");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "/nonexistent/salsa.toml: no such library file or directory");

  const std::string pair =
      "[[pair]]\nleader = \"" + bvh("60", "10") + "\"\npartner = \"" + bvh("61", "10") + "\"\n";
  EXPECT_EQ(error_of(pair), "(no error)");
  std::string e = error_of("fsp = 60\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: unknown key 'fsp'"), std::string::npos) << e;
  e = error_of("fps = \"sixty\"\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: key 'fps' must be a number, not a string"), std::string::npos) << e;
  e = error_of("fps = -60\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: key 'fps' must be between 1 and 1000 fps, got -60"),
            std::string::npos)
      << e;
  // The command line's ranges: no frame rate of 1e9 or scale of 1e-300 from a file either.
  e = error_of("fps = inf\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: key 'fps' must be between 1 and 1000 fps, got inf"),
            std::string::npos)
      << e;
  e = error_of("\nscale = 1e-300\n" + pair);
  EXPECT_NE(e.find("lib.toml:2: key 'scale' must be between 0.0001 and 1000 metres per file unit"),
            std::string::npos)
      << e;
  e = error_of("name = \"x\"\n" + pair + "\n[[pair]]\nleader = \"" + bvh("60", "10") +
               "\"\npartner = \"61_99.bvh\"\n");
  EXPECT_NE(e.find("lib.toml:8: key 'pair 2.partner': no such file: "), std::string::npos) << e;
  EXPECT_NE(e.find("61_99.bvh"), std::string::npos) << e;
  e = error_of("[[pair]]\nleader = 3\npartner = \"x.bvh\"\n");
  EXPECT_NE(e.find("lib.toml:2: key 'pair 1.leader' must be a .bvh path or an array"),
            std::string::npos)
      << e;
  e = error_of("[[pair]]\nleader = \"" + bvh("60", "10") + "\"\n");
  EXPECT_NE(e.find("lib.toml:1: pair 1 has no 'partner'"), std::string::npos) << e;
  e = error_of("[[pair]]\nleader = \"" + bvh("60", "10") + "\"\npartner = \"" + bvh("61", "10") +
               "\"\nrole = \"leader\"\n");
  EXPECT_NE(e.find("lib.toml:4: unknown key 'pair 1.role'"), std::string::npos) << e;
  e = error_of("[[pair]]\nleader = [\"" + kSalsa + "/asf-amc/60.asf\"]\npartner = \"" +
               bvh("61", "10") + "\"\n");
  EXPECT_NE(e.find("lib.toml:2: key 'pair 1.leader': a dancer is one .bvh file or"),
            std::string::npos)
      << e;
  e = error_of("name = \"x\"\n");
  EXPECT_NE(e.find("lib.toml: no pairs"), std::string::npos) << e;
  e = error_of("name = \"x\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: not a valid TOML library file"), std::string::npos) << e;
  e = error_of("root = \"${home}/x\"\n" + pair);
  EXPECT_NE(e.find("lib.toml:1: key 'root': unknown variable ${home}"), std::string::npos) << e;
  // ${data} with no data directory says how to give one.
  TempLibrary lib("root = \"${data}/cmu-salsa\"\n" + pair);
  const char* saved = std::getenv("DUET_DATA_DIR");
  const std::string saved_value = saved != nullptr ? saved : "";
  ::unsetenv("DUET_DATA_DIR");
  Result<LibrarySpec> no_data = read_library_file(lib.file.string());
  if (saved != nullptr) ::setenv("DUET_DATA_DIR", saved_value.c_str(), 1);
  ASSERT_FALSE(no_data);
  EXPECT_NE(no_data.error().message.find("key 'root' uses ${data}, the data directory: give "
                                         "--data-dir DIR or set DUET_DATA_DIR"),
            std::string::npos)
      << no_data.error().message;
}

TEST(LibraryFile, RelativePathsStartAtTheRootOrTheFilesDirectory) {
  TempLibrary lib(
      "root = \"${data}/cmu-salsa/bvh\"\n[[pair]]\nname = \"ten\"\n"
      "leader = \"60/60_10_scaled.bvh\"\npartner = \"61/61_10_scaled.bvh\"\n");
  Result<LibrarySpec> spec = read_library_file(lib.file.string(), kData);
  ASSERT_TRUE(spec) << spec.error().message;
  EXPECT_EQ(spec.value().pairs[0].leader, MotionFiles{bvh("60", "10")});
  EXPECT_EQ(spec.value().pairs[0].name, "ten");
  // Without root: relative to the file's own directory.
  fs::copy_file(bvh("60", "10"), lib.dir / "a.bvh");
  fs::copy_file(bvh("61", "10"), lib.dir / "b.bvh");
  std::ofstream(lib.file) << "[[pair]]\nleader = \"a.bvh\"\npartner = \"b.bvh\"\n";
  spec = read_library_file(lib.file.string());
  ASSERT_TRUE(spec) << spec.error().message;
  EXPECT_EQ(spec.value().pairs[0].leader, MotionFiles{(lib.dir / "a.bvh").string()});
  // --library DIR finds the one library file in it.
  Result<LibrarySpec> from_dir = read_library(lib.dir.string());
  ASSERT_TRUE(from_dir) << from_dir.error().message;
  EXPECT_EQ(from_dir.value().source, lib.file.string());
}

TEST(LibraryFile, RelativeDataDirStartsWhereTheUserIs) {
  // `--data-dir ../shared/data` means from the working directory, not from the library file's.
  TempLibrary lib(
      "root = \"${data}/cmu-salsa/bvh\"\n[[pair]]\n"
      "leader = \"60/60_10_scaled.bvh\"\npartner = \"61/61_10_scaled.bvh\"\n");
  const fs::path before = fs::current_path();
  fs::current_path(fs::path(kData).parent_path());
  Result<LibrarySpec> spec =
      read_library_file(lib.file.string(), fs::path(kData).filename().string());
  fs::current_path(before);
  ASSERT_TRUE(spec) << spec.error().message;
  // The same file (the working directory may be reached through a symbolic link).
  const fs::path resolved = spec.value().pairs[0].leader[0];
  EXPECT_TRUE(resolved.is_absolute()) << resolved;
  EXPECT_TRUE(fs::equivalent(resolved, bvh("60", "10"))) << resolved;
}

TEST(LibraryDir, RecognisesTheSalsaFolderAsFourteenDuetsAt60Fps) {
  Result<LibrarySpec> spec = read_library(kSalsa);
  ASSERT_TRUE(spec) << spec.error().message;
  ASSERT_EQ(spec.value().pairs.size(), 14u);
  EXPECT_EQ(spec.value().frame_rate, 60.0);
  // Trial 01 has a BVH and the AMC for 60: the BVH is preferred, 60 leads (known dataset).
  EXPECT_EQ(spec.value().pairs[0].leader, MotionFiles{bvh("60", "01")});
  EXPECT_EQ(spec.value().pairs[0].partner, MotionFiles{bvh("61", "01")});
  EXPECT_EQ(spec.value().pairs[0].name, "60_01");
  EXPECT_EQ(spec.value().pairs[13].partner, MotionFiles{bvh("61", "15")});
  // The whole data folder holds four subjects: not one duet.
  Result<LibrarySpec> all = read_library(kData);
  ASSERT_FALSE(all);
  EXPECT_NE(all.error().message.find("subject(s) (18, 19"), std::string::npos)
      << all.error().message;
  Result<LibrarySpec> none = read_library(kData + "/bandai");
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("no duets recognised"), std::string::npos);
}

TEST(MotionArgument, SplitsSkeletonPlusMotion) {
  const std::string asf = kSalsa + "/asf-amc/60.asf", amc = kSalsa + "/asf-amc/60_01.amc";
  Result<std::vector<std::string>> both = split_motion_argument(amc + "+" + asf);
  ASSERT_TRUE(both) << both.error().message;
  EXPECT_EQ(both.value(), (std::vector<std::string>{asf, amc}));  // skeleton first
  EXPECT_EQ(split_motion_argument(bvh("60", "01")).value(),
            std::vector<std::string>{bvh("60", "01")});
  EXPECT_NE(split_motion_argument(asf).error().message.find("skeleton without motion"),
            std::string::npos);
  EXPECT_NE(split_motion_argument(asf + "+x.amc").error().message.find("no such file: x.amc"),
            std::string::npos);
  EXPECT_NE(split_motion_argument(asf + "+" + bvh("60", "01"))
                .error()
                .message.find("one .asf and one .amc"),
            std::string::npos);
  EXPECT_FALSE(split_motion_argument(asf + "+" + amc + "+" + amc));
  EXPECT_EQ(join_motion_argument({asf, amc}), asf + "+" + amc);
  // A path that exists but is no file (a directory, a device) is not called missing.
  EXPECT_NE(split_motion_argument(kSalsa).error().message.find("not a regular file: " + kSalsa),
            std::string::npos);
}

TEST(KnownDatasets, WarnsWhenAHeaderRateDisagrees) {
  EXPECT_NE(find_known_dataset(bvh("61", "03")), nullptr);
  EXPECT_NE(find_known_dataset("x/60.asf"), nullptr);
  EXPECT_EQ(find_known_dataset(kData + "/cmu-handshake/18_01.bvh"), nullptr);
  EXPECT_EQ(find_known_dataset(kData + "/crosscheck/cmu_60_01.bvh"), nullptr);
  const std::string w = known_dataset_rate_warning(bvh("60", "01"), 120.0);
  EXPECT_NE(w.find("60_01_scaled.bvh: read at 120 fps"), std::string::npos) << w;
  EXPECT_NE(w.find("--fps 60"), std::string::npos) << w;
  EXPECT_EQ(known_dataset_rate_warning(bvh("60", "01"), 60.0), "");
  EXPECT_EQ(known_dataset_rate_warning(kData + "/cmu-handshake/18_01.bvh", 120.0), "");
}

// The leader as the CMU originals (60.asf + 60_01.amc) and the partner as its BVH: a duet, and
// it follows like the all-BVH library.
TEST(LibraryDir, AsfAmcLeaderFollowsLikeTheBvhLeader) {
  LibraryOptions options;
  options.load.frame_rate = 60.0;
  const MotionFiles originals = {kSalsa + "/asf-amc/60.asf", kSalsa + "/asf-amc/60_01.amc"};
  const std::vector<PairFiles> mixed = {{originals, {bvh("61", "01")}},
                                        {{bvh("60", "10")}, {bvh("61", "10")}},
                                        {{bvh("60", "05")}, {bvh("61", "05")}}};
  std::vector<PairFiles> all_bvh = mixed;
  all_bvh[0].leader = {bvh("60", "01")};
  Result<DuetLibrary> a = DuetLibrary::load(mixed, options);
  ASSERT_TRUE(a) << a.error().message;
  Result<DuetLibrary> b = DuetLibrary::load(all_bvh, options);
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_EQ(a.value().takes()[0].name, "60_01");
  EXPECT_EQ(a.value().takes()[0].template_motion.clip.frame_count(), 2242);
  EXPECT_EQ(a.value().model().num_states(), b.value().model().num_states());
  EXPECT_EQ(a.value().takes()[0].template_motion.roles.convention, "cmu-asf");

  // The same user (the CMU original of take 01, 60_01.amc) followed through both libraries.
  const LoadedMotion& user = a.value().takes()[0].template_motion;
  auto session = [&](const DuetLibrary& library) {
    Result<HmmFollower> follower = HmmFollower::create(library.model(), FollowParams{});
    EXPECT_TRUE(follower);
    return FollowSession::create(library, user.clip.skeleton_ptr(), user.roles,
                                 std::make_unique<HmmFollower>(std::move(follower).value()));
  };
  Result<FollowSession> sa = session(a.value());
  Result<FollowSession> sb = session(b.value());
  ASSERT_TRUE(sa) << sa.error().message;
  ASSERT_TRUE(sb) << sb.error().message;
  int same = 0, same_take = 0, near = 0, a_right = 0, b_right = 0;
  const int frames = user.clip.frame_count();
  for (int f = 0; f < frames; ++f) {
    const FollowResult ra =
        sa.value().step(user.clip.translations_ls(f), user.clip.rotations_ls(f), f / 60.0);
    const FollowResult rb =
        sb.value().step(user.clip.translations_ls(f), user.clip.rotations_ls(f), f / 60.0);
    if (ra.take == rb.take && ra.frame_in_take == rb.frame_in_take) ++same;
    if (ra.take == rb.take) ++same_take;
    if (ra.take == rb.take && std::abs(ra.frame_in_take - rb.frame_in_take) <= 3) ++near;
    if (ra.take == 0 && std::abs(ra.frame_in_take - f) <= 3) ++a_right;
    if (rb.take == 0 && std::abs(rb.frame_in_take - f) <= 3) ++b_right;
  }
  // Measured: same take on every frame, the same frame on about half (the ASF keeps subject
  // 60's own bone lengths, the BVH a generic body, so the features differ slightly and the
  // two libraries often settle one or two frames apart), within 3 frames on 97%.
  EXPECT_GE(same_take, frames * 99 / 100) << same_take << " of " << frames;
  EXPECT_GE(near, frames * 95 / 100) << near << " of " << frames;
  EXPECT_GE(a_right, frames * 99 / 100) << a_right << " of " << frames;
  EXPECT_GE(b_right, frames * 95 / 100) << b_right << " of " << frames;
  std::printf(
      "ASF+AMC leader vs BVH leader: same take and frame on %d of %d frames, within 3 on "
      "%d, same take on %d; right within 3: %d and %d\n",
      same, frames, near, same_take, a_right, b_right);
}

}  // namespace
}  // namespace duet
