#include "duet/live/recorder.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <system_error>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#endif

#include "duet/io/bvh.h"
#include "duet/io/motion_file.h"
#include "duet/math/rotation.h"

namespace duet {

namespace {

// "Frames: " is followed by this many characters: the count, left-aligned, padded with spaces.
// Readers take the number as a token, so the padding is harmless; 12 digits never run out.
constexpr int kFramesFieldWidth = 12;

std::string errno_text() { return std::strerror(errno); }

std::string frames_field(long long frames) {
  std::string field = std::to_string(frames);
  field.resize(kFramesFieldWidth, ' ');
  return field;
}

// The first of "<stem>", "<stem>-2", ... whose files do not exist yet.
std::string unused_stem(const std::filesystem::path& dir, const std::string& stem) {
  for (int n = 1;; ++n) {
    const std::string candidate = n == 1 ? stem : stem + "-" + std::to_string(n);
    bool taken = false;
    for (const char* suffix : {"-user.bvh", "-partner.bvh", "-follow.csv"}) {
      std::error_code ec;
      const std::filesystem::path p = dir / (candidate + suffix);
      if (std::filesystem::exists(p, ec) || std::filesystem::exists(p.string() + ".part", ec)) {
        taken = true;
      }
    }
    if (!taken) return candidate;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// BvhStreamWriter

BvhStreamWriter::BvhStreamWriter(BvhStreamWriter&& other) noexcept { *this = std::move(other); }

BvhStreamWriter& BvhStreamWriter::operator=(BvhStreamWriter&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr) (void)close();
    path_ = std::move(other.path_);
    part_path_ = std::move(other.part_path_);
    skeleton_ = std::move(other.skeleton_);
    formatter_ = std::move(other.formatter_);
    file_ = std::exchange(other.file_, nullptr);
    frames_field_offset_ = other.frames_field_offset_;
    frames_ = other.frames_;
    frames_on_disk_ = other.frames_on_disk_;
    pending_ = std::move(other.pending_);
  }
  return *this;
}

BvhStreamWriter::~BvhStreamWriter() {
  if (file_ != nullptr) (void)close();
}

Result<BvhStreamWriter> BvhStreamWriter::open(const std::string& path,
                                              std::shared_ptr<const Skeleton> skeleton,
                                              double frame_rate, const BvhWriteOptions& options) {
  if (!skeleton) return make_error(path, 0, "cannot record: no skeleton");
  if (const std::string problem = skeleton->validate(); !problem.empty()) {
    return make_error(path, 0, "cannot record: invalid skeleton: " + problem);
  }
  if (!(frame_rate > 0.0) || !std::isfinite(frame_rate)) {
    return make_error(path, 0, "cannot record: the frame rate must be positive");
  }
  if (!(options.units_per_metre > 0.0) || !std::isfinite(options.units_per_metre)) {
    return make_error(path, 0, "cannot record: units_per_metre must be positive and finite");
  }
  std::string header = format_bvh(Clip(skeleton, frame_rate, 0), options);
  const std::string marker = "\nFrames: 0\n";
  const std::size_t at = header.rfind(marker);
  if (at == std::string::npos) return make_error(path, 0, "cannot record: unexpected BVH header");
  header.replace(at, marker.size(), "\nFrames: " + frames_field(0) + "\n");

  BvhStreamWriter writer;
  writer.path_ = path;
  writer.part_path_ = path + ".part";
  writer.file_ = std::fopen(writer.part_path_.c_str(), "wb");
  if (writer.file_ == nullptr) {
    return make_error(writer.part_path_, 0, "cannot create: " + errno_text());
  }
  if (std::fwrite(header.data(), 1, header.size(), writer.file_) != header.size() ||
      std::fflush(writer.file_) != 0) {
    const std::string why = errno_text();
    std::fclose(std::exchange(writer.file_, nullptr));
    std::remove(writer.part_path_.c_str());
    return make_error(writer.part_path_, 0, "cannot write: " + why);
  }
  writer.frames_field_offset_ = static_cast<long>(at + std::string_view("\nFrames: ").size());
  writer.skeleton_ = std::move(skeleton);
  // The same values, order and precision as format_bvh(), so the file reads back like one.
  writer.formatter_ = BvhFrameFormatter(*writer.skeleton_, options);
  writer.pending_.reserve(1 << 16);
  return writer;
}

void BvhStreamWriter::append(std::span<const Vec3> translations_ls,
                             std::span<const Quat> rotations_ls) {
  if (file_ == nullptr) return;
  formatter_.append(translations_ls, rotations_ls, pending_);
  pending_ += '\n';
  ++frames_;
}

Status BvhStreamWriter::checkpoint() {
  if (file_ == nullptr) return Ok{};
  if (!pending_.empty()) {
    if (std::fwrite(pending_.data(), 1, pending_.size(), file_) != pending_.size()) {
      return make_error(part_path_, 0, "cannot write: " + errno_text());
    }
    pending_.clear();
  }
  if (frames_ != frames_on_disk_) {
    // The motion lines reach the file before the count that covers them.
    const std::string field = frames_field(frames_);
    if (std::fflush(file_) != 0 || std::fseek(file_, frames_field_offset_, SEEK_SET) != 0 ||
        std::fwrite(field.data(), 1, field.size(), file_) != field.size() ||
        std::fseek(file_, 0, SEEK_END) != 0) {
      return make_error(part_path_, 0, "cannot write: " + errno_text());
    }
    frames_on_disk_ = frames_;
  }
  if (std::fflush(file_) != 0) return make_error(part_path_, 0, "cannot write: " + errno_text());
  return Ok{};
}

Status BvhStreamWriter::close() {
  if (file_ == nullptr) return Ok{};
  Status status = checkpoint();
  if (std::fclose(std::exchange(file_, nullptr)) != 0 && status) {
    status = make_error(part_path_, 0, "cannot close: " + errno_text());
  }
  if (!status) return status;
  std::error_code ec;
  std::filesystem::rename(part_path_, path_, ec);
  if (ec) return make_error(path_, 0, "cannot rename " + part_path_ + ": " + ec.message());
  return Ok{};
}

// ---------------------------------------------------------------------------------------------
// SessionRecorder

Result<std::unique_ptr<SessionRecorder>> SessionRecorder::start(
    const RecorderOptions& options, std::shared_ptr<const Skeleton> user,
    std::shared_ptr<const Skeleton> partner, double frame_rate) {
  namespace fs = std::filesystem;
  if (!user || !partner) return Error{"recorder: no skeleton"};
  const fs::path dir = options.directory.empty() ? fs::path(".") : fs::path(options.directory);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    return make_error(dir.string(), 0, "cannot create the recording directory: " + ec.message());
  const std::string stem = unused_stem(dir, options.stem);

  std::unique_ptr<SessionRecorder> recorder(new SessionRecorder());
  recorder->options_ = options;
  recorder->options_.ring_frames = std::max(options.ring_frames, 2);
  recorder->user_path_ = (dir / (stem + "-user.bvh")).string();
  recorder->partner_path_ = (dir / (stem + "-partner.bvh")).string();
  recorder->follow_path_ = (dir / (stem + "-follow.csv")).string();
  recorder->follow_part_path_ = recorder->follow_path_ + ".part";

  Result<BvhStreamWriter> user_writer =
      BvhStreamWriter::open(recorder->user_path_, user, frame_rate,
                            BvhWriteOptions::in_file_units(
                                readable_metres_per_unit(*user, options.user_metres_per_unit)));
  if (!user_writer) return user_writer.error();
  Result<BvhStreamWriter> partner_writer =
      BvhStreamWriter::open(recorder->partner_path_, partner, frame_rate,
                            BvhWriteOptions::in_file_units(readable_metres_per_unit(
                                *partner, options.partner_metres_per_unit)));
  if (!partner_writer) return partner_writer.error();
  recorder->user_ = std::move(user_writer).value();
  recorder->partner_ = std::move(partner_writer).value();
  recorder->follow_ = std::fopen(recorder->follow_part_path_.c_str(), "wb");
  if (recorder->follow_ == nullptr) {
    return make_error(recorder->follow_part_path_, 0, "cannot create: " + errno_text());
  }
  recorder->follow_pending_ =
      "seq,time_s,take,template_frame,confidence,jumped,lost,in_pause,contact_left,"
      "contact_right,missing,outlier,partly_observed,frame_offset\n";
  recorder->follow_pending_.reserve(1 << 16);

  recorder->ring_.resize(static_cast<std::size_t>(recorder->options_.ring_frames));
  for (Slot& slot : recorder->ring_) {
    slot.user_translations.resize(static_cast<std::size_t>(user->joint_count()));
    slot.user_rotations.resize(static_cast<std::size_t>(user->joint_count()));
    slot.partner_translations.resize(static_cast<std::size_t>(partner->joint_count()));
    slot.partner_rotations.resize(static_cast<std::size_t>(partner->joint_count()));
  }
  SessionRecorder* self = recorder.get();
  recorder->worker_ = std::thread([self] { self->run(); });
  return recorder;
}

SessionRecorder::~SessionRecorder() { (void)stop(); }

bool SessionRecorder::push(const SourceFrame& user, const LiveOutput& output) noexcept {
  const long long tail = tail_.load(std::memory_order_relaxed);
  const long long head = head_.load(std::memory_order_acquire);
  const auto capacity = static_cast<long long>(ring_.size());
  if (stopped_.load(std::memory_order_relaxed) || tail - head >= capacity) {
    lost_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  Slot& slot = ring_[static_cast<std::size_t>(tail % capacity)];
  slot.seq = output.seq;
  slot.time_s = output.time_s;
  slot.follow = output.follow;
  slot.contact_left = output.contact_left;
  slot.contact_right = output.contact_right;
  auto copy = [](const auto& from, auto& to) {
    std::copy_n(from.begin(), std::min(from.size(), to.size()), to.begin());
  };
  copy(user.translations_ls, slot.user_translations);
  copy(user.rotations_ls, slot.user_rotations);
  copy(output.partner_translations_ls, slot.partner_translations);
  copy(output.partner_rotations_ls, slot.partner_rotations);
  tail_.store(tail + 1, std::memory_order_release);
  return true;
}

void SessionRecorder::drain() {
  const long long tail = tail_.load(std::memory_order_acquire);
  long long head = head_.load(std::memory_order_relaxed);
  const auto capacity = static_cast<long long>(ring_.size());
  for (; head < tail; ++head) {
    const Slot& slot = ring_[static_cast<std::size_t>(head % capacity)];
    if (status_) {
      user_.append(slot.user_translations, slot.user_rotations);
      partner_.append(slot.partner_translations, slot.partner_rotations);
      const FollowResult& r = slot.follow;
      fmt::format_to(std::back_inserter(follow_pending_),
                     "{},{:.6f},{},{},{:.4f},{},{},{},{},{},{},{},{},{:.3f}\n", slot.seq,
                     slot.time_s, r.take, r.frame_in_take, r.confidence, r.jumped ? 1 : 0,
                     r.lost ? 1 : 0, r.in_pause ? 1 : 0, slot.contact_left ? 1 : 0,
                     slot.contact_right ? 1 : 0, r.missing ? 1 : 0, r.outlier ? 1 : 0,
                     r.partly_observed ? 1 : 0, r.frame_offset);
      recorded_.fetch_add(1, std::memory_order_relaxed);
    } else {
      lost_.fetch_add(1, std::memory_order_relaxed);
    }
    head_.store(head + 1, std::memory_order_release);
  }
}

void SessionRecorder::run() noexcept {
#if defined(__linux__)
  // Started from a loop thread that may run at a real-time priority (threads inherit it): file
  // work must not compete with the loop.
  sched_param param{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
#endif
  using Clock = std::chrono::steady_clock;
  auto last_checkpoint = Clock::now();
  const auto interval = std::chrono::duration<double>(options_.checkpoint_interval_s);
  auto checkpoint = [&] {
    if (!status_) return;
    Status s = user_.checkpoint();
    if (s) s = partner_.checkpoint();
    if (s && !follow_pending_.empty()) {
      if (std::fwrite(follow_pending_.data(), 1, follow_pending_.size(), follow_) !=
              follow_pending_.size() ||
          std::fflush(follow_) != 0) {
        s = make_error(follow_part_path_, 0, "cannot write: " + errno_text());
      }
      follow_pending_.clear();
    }
    if (!s) status_ = s;
  };
  try {
    for (;;) {
      drain();
      if (Clock::now() - last_checkpoint >= interval) {
        checkpoint();
        last_checkpoint = Clock::now();
      }
      std::unique_lock lock(mutex_);
      if (stop_requested_) break;
      wake_.wait_for(lock, std::chrono::milliseconds(20));
    }
    drain();
    checkpoint();
  } catch (const std::exception& e) {  // out of memory while formatting: stop recording
    if (status_) status_ = Error{std::string("recorder: ") + e.what()};
  }
}

Status SessionRecorder::finish() {
  Status status = status_;
  Status s = user_.close();
  if (status && !s) status = s;
  s = partner_.close();
  if (status && !s) status = s;
  if (follow_ != nullptr) {
    const bool ok = std::fclose(std::exchange(follow_, nullptr)) == 0;
    std::error_code ec;
    if (ok) std::filesystem::rename(follow_part_path_, follow_path_, ec);
    if (status && (!ok || ec)) {
      status = make_error(follow_path_, 0, "cannot close: " + (ec ? ec.message() : errno_text()));
    }
  }
  return status;
}

Status SessionRecorder::stop() {
  if (stopped_) return status_;
  {
    std::lock_guard lock(mutex_);
    stop_requested_ = true;
  }
  wake_.notify_one();
  if (worker_.joinable()) worker_.join();
  stopped_ = true;
  status_ = finish();
  return status_;
}

}  // namespace duet
