// Recording a live session to disk while it runs: the user's and the partner's motion as BVH files
// and the follower's estimate per frame as CSV.
//
// A BVH header states the frame count before the motion, which is unknown while recording. The
// writer reserves a fixed-width "Frames:" field, streams motion lines after it, and patches the
// count at every checkpoint (once a second) and on close. It writes "<name>.part" and renames it
// to <name> on close, so a finished file is always complete; a ".part" left by a crash is still a
// valid BVH holding every frame up to its last checkpoint.
//
// SessionRecorder moves the file work off the loop's thread: the loop copies each frame into a
// preallocated ring (no allocation, no I/O, never blocks), a worker thread formats and writes.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "duet/base/result.h"
#include "duet/io/bvh.h"
#include "duet/live/live_loop.h"
#include "duet/motion/skeleton.h"

namespace duet {

class BvhStreamWriter {
 public:
  BvhStreamWriter() = default;
  BvhStreamWriter(BvhStreamWriter&& other) noexcept;
  BvhStreamWriter& operator=(BvhStreamWriter&& other) noexcept;
  BvhStreamWriter(const BvhStreamWriter&) = delete;
  BvhStreamWriter& operator=(const BvhStreamWriter&) = delete;
  ~BvhStreamWriter();  // closes (as close()) if still open

  // Creates "<path>.part" with the hierarchy of `skeleton` and an empty motion. Poses are given
  // in metres and written in options.units_per_metre (as format_bvh writes them).
  static Result<BvhStreamWriter> open(const std::string& path,
                                      std::shared_ptr<const Skeleton> skeleton, double frame_rate,
                                      const BvhWriteOptions& options = {});

  // One motion line; the spans have the skeleton's joint count. Buffered in memory until the next
  // checkpoint.
  void append(std::span<const Vec3> translations_ls, std::span<const Quat> rotations_ls);
  // Writes the buffered lines, then the frame count, and flushes.
  Status checkpoint();
  // Checkpoints, closes and renames "<path>.part" to <path>.
  Status close();

  bool is_open() const { return file_ != nullptr; }
  long long frames() const { return frames_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string part_path_;
  std::shared_ptr<const Skeleton> skeleton_;
  BvhFrameFormatter formatter_;  // points into *skeleton_
  std::FILE* file_ = nullptr;
  long frames_field_offset_ = 0;  // where the Frames: digits start
  long long frames_ = 0;
  long long frames_on_disk_ = 0;
  std::string pending_;  // motion lines not yet written
};

struct RecorderOptions {
  std::string directory = "recordings";
  // File names are <stem>-user.bvh, <stem>-partner.bvh, <stem>-follow.csv; a number is appended
  // to the stem when such files exist already.
  std::string stem = "session";
  int ring_frames = 2048;  // frames the loop may run ahead of the disk (17 s at 120 Hz)
  // The units the two BVH files are written in (metres per file unit): the source's and the
  // response takes', so duet reads the recordings back at the size they were danced (units the
  // reader would not infer, such as an ASF source's metres, give way to readable_metres_per_unit).
  double user_metres_per_unit = 1.0;
  double partner_metres_per_unit = 1.0;
  double checkpoint_interval_s = 1.0;
};

class SessionRecorder {
 public:
  // Creates the directory and the three files and starts the worker thread.
  static Result<std::unique_ptr<SessionRecorder>> start(const RecorderOptions& options,
                                                        std::shared_ptr<const Skeleton> user,
                                                        std::shared_ptr<const Skeleton> partner,
                                                        double frame_rate);
  ~SessionRecorder();  // stop()s if needed
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  // The loop's thread: copies the user's local pose and the loop's output into the ring. Returns
  // false when the ring is full (the disk is stalled); the frame is then not recorded and counted
  // in frames_lost(). Never blocks, allocates nothing.
  bool push(const SourceFrame& user, const LiveOutput& output) noexcept;

  // Writes everything pushed so far, closes and renames the files, joins the worker. Idempotent;
  // returns the first error the worker met, if any.
  Status stop();

  long long frames_recorded() const { return recorded_.load(std::memory_order_relaxed); }
  long long frames_lost() const { return lost_.load(std::memory_order_relaxed); }
  const std::string& user_path() const { return user_path_; }
  const std::string& partner_path() const { return partner_path_; }
  const std::string& follow_path() const { return follow_path_; }

 private:
  struct Slot {
    long long seq = 0;
    double time_s = 0.0;
    FollowResult follow;
    bool contact_left = false;
    bool contact_right = false;
    std::vector<Vec3> user_translations;
    std::vector<Quat> user_rotations;
    std::vector<Vec3> partner_translations;
    std::vector<Quat> partner_rotations;
  };

  SessionRecorder() = default;
  void run() noexcept;
  void drain();
  Status finish();

  RecorderOptions options_;
  BvhStreamWriter user_;
  BvhStreamWriter partner_;
  std::FILE* follow_ = nullptr;
  std::string follow_path_;
  std::string follow_part_path_;
  std::string user_path_;
  std::string partner_path_;
  std::string follow_pending_;

  std::vector<Slot> ring_;
  std::atomic<long long> head_{0};  // next slot the worker reads
  std::atomic<long long> tail_{0};  // next slot the loop writes
  std::atomic<long long> recorded_{0};
  std::atomic<long long> lost_{0};

  std::thread worker_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_requested_ = false;  // guarded by mutex_
  std::atomic<bool> stopped_{false};
  Status status_ = Ok{};  // ok, or the worker's first error; read after join
};

}  // namespace duet
