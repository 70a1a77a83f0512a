#include "duet/live/recorder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "duet/io/bvh.h"
#include "duet/io/motion_file.h"

namespace duet {
namespace {

namespace fs = std::filesystem;

std::string salsa(const std::string& subject, const std::string& trial) {
  return std::string(DUET_DATA_DIR) + "/cmu-salsa/bvh/" + subject + "/" + subject + "_" + trial +
         "_scaled.bvh";
}

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("duet-recorder-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  static int& counter() {
    static int n = 0;
    return n;
  }
};

const Clip& salsa_clip() {
  static const Clip clip = [] {
    MotionLoadOptions options;
    options.frame_rate = 60.0;
    Result<LoadedMotion> m = load_motion({salsa("61", "03")}, options);
    EXPECT_TRUE(m) << m.error().message;
    return std::move(m).value().clip;
  }();
  return clip;
}

void expect_same_motion(const Clip& a, const Clip& b, int frames) {
  ASSERT_GE(a.frame_count(), frames);
  ASSERT_GE(b.frame_count(), frames);
  ASSERT_EQ(a.joint_count(), b.joint_count());
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < a.joint_count(); ++j) {
      const auto jj = static_cast<std::size_t>(j);
      if (a.skeleton().joints[jj].channels.empty()) continue;
      ASSERT_LT((a.translations_ls(f)[jj] - b.translations_ls(f)[jj]).norm(), 1e-5);
      ASSERT_LT(a.rotations_ls(f)[jj].angularDistance(b.rotations_ls(f)[jj]), 1e-5)
          << "frame " << f << " joint " << j;
    }
  }
}

TEST(Recorder, StreamWriterPatchesTheFrameCount) {
  TempDir dir;
  const Clip& clip = salsa_clip();
  const std::string path = (dir.path / "take.bvh").string();
  Result<BvhStreamWriter> opened = BvhStreamWriter::open(path, clip.skeleton_ptr(), 60.0);
  ASSERT_TRUE(opened) << opened.error().message;
  BvhStreamWriter writer = std::move(opened).value();
  for (int f = 0; f < 100; ++f) writer.append(clip.translations_ls(f), clip.rotations_ls(f));
  ASSERT_TRUE(writer.checkpoint());
  // Mid-recording: the .part file is a valid BVH with every frame so far.
  Result<Clip> partial = read_bvh(path + ".part");
  ASSERT_TRUE(partial) << partial.error().message;
  EXPECT_EQ(partial.value().frame_count(), 100);
  for (int f = 100; f < 250; ++f) writer.append(clip.translations_ls(f), clip.rotations_ls(f));
  ASSERT_TRUE(writer.close());
  EXPECT_FALSE(fs::exists(path + ".part"));
  Result<Clip> done = read_bvh(path);
  ASSERT_TRUE(done) << done.error().message;
  EXPECT_EQ(done.value().frame_count(), 250);
  EXPECT_NEAR(done.value().frame_rate(), 60.0, 1e-3);
  expect_same_motion(clip, done.value(), 250);
}

TEST(Recorder, StreamWriterWritesInTheGivenUnits) {
  // The salsa files' units (1.30208 m per unit): read back with that scale, the motion is the
  // same; the hierarchy's offsets are in file units.
  TempDir dir;
  const Clip& clip = salsa_clip();
  const std::string path = (dir.path / "units.bvh").string();
  BvhWriteOptions units;
  units.units_per_metre = 1.0 / 1.30208;
  Result<BvhStreamWriter> opened = BvhStreamWriter::open(path, clip.skeleton_ptr(), 60.0, units);
  ASSERT_TRUE(opened) << opened.error().message;
  BvhStreamWriter writer = std::move(opened).value();
  for (int f = 0; f < 50; ++f) writer.append(clip.translations_ls(f), clip.rotations_ls(f));
  ASSERT_TRUE(writer.close());
  BvhReadOptions read;
  read.scale = 1.30208;
  Result<Clip> done = read_bvh(path, read);
  ASSERT_TRUE(done) << done.error().message;
  expect_same_motion(clip, done.value(), 50);
  Result<Clip> raw = read_bvh(path);
  ASSERT_TRUE(raw);
  EXPECT_NEAR(raw.value().skeleton().joints[1].offset.norm() * 1.30208,
              clip.skeleton().joints[1].offset.norm(), 1e-5);

  BvhWriteOptions bad;
  bad.units_per_metre = 0.0;
  EXPECT_FALSE(
      BvhStreamWriter::open((dir.path / "bad.bvh").string(), clip.skeleton_ptr(), 60.0, bad));
  EXPECT_FALSE(fs::exists(dir.path / "bad.bvh.part"));
}

TEST(Recorder, EmptyRecordingParses) {
  TempDir dir;
  const std::string path = (dir.path / "empty.bvh").string();
  {
    Result<BvhStreamWriter> writer =
        BvhStreamWriter::open(path, salsa_clip().skeleton_ptr(), 120.0);
    ASSERT_TRUE(writer);
  }  // the destructor closes
  Result<Clip> clip = read_bvh(path);
  ASSERT_TRUE(clip) << clip.error().message;
  EXPECT_EQ(clip.value().frame_count(), 0);
}

TEST(Recorder, SessionRecorderWritesEveryPushedFrame) {
  TempDir dir;
  const Clip& clip = salsa_clip();
  RecorderOptions options;
  options.directory = (dir.path / "sub" / "dir").string();  // created
  options.stem = "session";
  options.ring_frames = 64;
  options.checkpoint_interval_s = 0.05;
  Result<std::unique_ptr<SessionRecorder>> started =
      SessionRecorder::start(options, clip.skeleton_ptr(), clip.skeleton_ptr(), 60.0);
  ASSERT_TRUE(started) << started.error().message;
  SessionRecorder& recorder = *started.value();

  SourceFrame user;
  user.resize(clip.joint_count());
  LiveOutput out;
  out.partner_translations_ls.resize(static_cast<std::size_t>(clip.joint_count()));
  out.partner_rotations_ls.resize(static_cast<std::size_t>(clip.joint_count()));
  const int frames = 600;
  int pushed = 0;
  for (int f = 0; f < frames; ++f) {
    std::ranges::copy(clip.translations_ls(f), user.translations_ls.begin());
    std::ranges::copy(clip.rotations_ls(f), user.rotations_ls.begin());
    // The partner track is the same motion played backwards.
    std::ranges::copy(clip.translations_ls(frames - 1 - f), out.partner_translations_ls.begin());
    std::ranges::copy(clip.rotations_ls(frames - 1 - f), out.partner_rotations_ls.begin());
    out.seq = f;
    out.time_s = f / 60.0;
    out.follow.take = 0;
    out.follow.frame_in_take = f;
    out.follow.missing = f == 100;
    out.follow.outlier = f == 200;
    // A 64-frame ring: wait for the worker rather than lose frames in this test.
    while (!recorder.push(user, out)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ++pushed;
  }
  ASSERT_TRUE(recorder.stop());
  EXPECT_EQ(recorder.frames_recorded(), frames);
  // The options say metres, but a salsa skeleton in metres would read back 1.3x too big: the
  // recordings are in the units duet infers for it, and read back at their true size.
  Result<LoadedMotion> user_motion = load_motion({recorder.user_path()});
  ASSERT_TRUE(user_motion) << user_motion.error().message;
  const Clip& user_clip = user_motion.value().clip;
  EXPECT_EQ(user_clip.frame_count(), frames);
  expect_same_motion(clip, user_clip, frames);
  Result<Clip> partner_clip = read_bvh(recorder.partner_path());
  ASSERT_TRUE(partner_clip) << partner_clip.error().message;
  EXPECT_EQ(partner_clip.value().frame_count(), frames);
  EXPECT_LT(
      partner_clip.value().rotations_ls(0)[1].angularDistance(clip.rotations_ls(frames - 1)[1]),
      1e-5);
  std::ifstream csv(recorder.follow_path());
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) {
    if (lines == 0) {
      EXPECT_EQ(line.substr(line.size() - 45), ",missing,outlier,partly_observed,frame_offset");
    }
    // Row f + 1 is frame f: missing on frame 100, outlier on frame 200, neither elsewhere.
    if (lines > 0) {
      const int f = lines - 1;
      const std::string end =
          std::string(",") + (f == 100 ? "1" : "0") + "," + (f == 200 ? "1" : "0") + ",0";
      // The last column is the place between frames (a number), the three before it the flags.
      const std::size_t last = line.rfind(',');
      ASSERT_NE(last, std::string::npos) << line;
      EXPECT_TRUE(std::isfinite(std::stod(line.substr(last + 1)))) << line;
      EXPECT_EQ(line.substr(last - 6, 6), end) << line;
    }
    ++lines;
  }
  EXPECT_EQ(lines, frames + 1);

  // A second session with the same stem does not overwrite the first.
  Result<std::unique_ptr<SessionRecorder>> second =
      SessionRecorder::start(options, clip.skeleton_ptr(), clip.skeleton_ptr(), 60.0);
  ASSERT_TRUE(second);
  EXPECT_NE(second.value()->user_path(), recorder.user_path());
  EXPECT_NE(second.value()->user_path().find("session-2-user.bvh"), std::string::npos);
}

TEST(Recorder, FullRingLosesFramesWithoutBlocking) {
  TempDir dir;
  const Clip& clip = salsa_clip();
  RecorderOptions options;
  options.directory = dir.path.string();
  options.ring_frames = 4;
  options.checkpoint_interval_s = 10.0;
  auto recorder =
      SessionRecorder::start(options, clip.skeleton_ptr(), clip.skeleton_ptr(), 60.0).value();
  SourceFrame user;
  user.resize(clip.joint_count());
  LiveOutput out;
  out.partner_translations_ls.resize(static_cast<std::size_t>(clip.joint_count()));
  out.partner_rotations_ls.resize(static_cast<std::size_t>(clip.joint_count()));
  int accepted = 0;
  for (int f = 0; f < 1000; ++f) accepted += recorder->push(user, out) ? 1 : 0;
  ASSERT_TRUE(recorder->stop());
  EXPECT_EQ(recorder->frames_recorded(), accepted);
  EXPECT_EQ(recorder->frames_lost(), 1000 - accepted);
  Result<Clip> user_clip = read_bvh(recorder->user_path());
  ASSERT_TRUE(user_clip) << user_clip.error().message;
  EXPECT_EQ(user_clip.value().frame_count(), accepted);
}

}  // namespace
}  // namespace duet
