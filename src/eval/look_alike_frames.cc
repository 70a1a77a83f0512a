#include "duet/eval/look_alike_frames.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "duet/eval/metrics.h"
#include "duet/live/duet_library.h"
#include "duet/math/rotation.h"

namespace duet {

namespace {

// One side of every duet (the template or the response dancer) as standardised canonical
// full-body features, the takes' rows one after another.
Result<FeatureMatrix> side_features(const DuetLibrary& library, bool response) {
  const FeatureSpec spec;  // the full body, whatever the library follows
  std::vector<FeatureMatrix> per_take;
  Eigen::Index rows = 0;
  for (const DuetTake& take : library.takes()) {
    const LoadedMotion& motion = response ? take.response_motion : take.template_motion;
    Result<FeatureExtractor> extractor =
        FeatureExtractor::create(motion.clip.skeleton_ptr(), motion.roles, spec);
    if (!extractor) {
      return Error{"look-alike frames: take " + take.name + ": " + extractor.error().message};
    }
    per_take.push_back(extractor.value().extract_clip(motion.clip));
    rows += per_take.back().rows();
  }
  FeatureMatrix all(rows, spec.dimension());
  Eigen::Index row = 0;
  for (const FeatureMatrix& take : per_take) {
    all.middleRows(row, take.rows()) = take;
    row += take.rows();
  }
  FeatureNormalizer::fit(all, spec).apply(all);
  return all;
}

float distance_per_dim(const FeatureMatrix& rows, Eigen::Index a, Eigen::Index b) noexcept {
  return (rows.row(a) - rows.row(b)).squaredNorm() / static_cast<float>(rows.cols());
}

}  // namespace

Result<LookAlikeFrames> LookAlikeFrames::build(const DuetLibrary& library,
                                               const LookAlikeOptions& options) {
  if (!(options.distance_per_dim >= 0.0f) || !(options.placement_m >= 0.0) ||
      !(options.facing_rad >= 0.0) || !(options.window_ms >= 0.0)) {
    return Error{"look-alike frames: every tolerance must be a number >= 0"};
  }
  LookAlikeFrames frames;
  frames.options_ = options;
  frames.frame_rate_hz_ = library.frame_rate();
  int row = 0;
  for (const DuetTake& take : library.takes()) {
    frames.first_row_.push_back(row);
    row += take.template_motion.clip.frame_count();
    Result<SpatialAlignment> placement = SpatialAlignment::build(
        take.template_motion.clip, take.template_motion.roles, take.response_motion.clip);
    if (!placement) {
      return Error{"look-alike frames: take " + take.name + ": " + placement.error().message};
    }
    frames.placements_.push_back(std::move(placement).value());
  }
  frames.first_row_.push_back(row);
  Result<FeatureMatrix> template_rows = side_features(library, false);
  if (!template_rows) return template_rows.error();
  Result<FeatureMatrix> response_rows = side_features(library, true);
  if (!response_rows) return response_rows.error();
  frames.template_rows_ = std::move(template_rows).value();
  frames.response_rows_ = std::move(response_rows).value();
  return frames;
}

bool LookAlikeFrames::alike(int take_a, int frame_a, int take_b, int frame_b) const noexcept {
  const Eigen::Index a = first_row_[static_cast<std::size_t>(take_a)] + frame_a;
  const Eigen::Index b = first_row_[static_cast<std::size_t>(take_b)] + frame_b;
  if (distance_per_dim(template_rows_, a, b) > options_.distance_per_dim ||
      distance_per_dim(response_rows_, a, b) > options_.distance_per_dim) {
    return false;
  }
  const RootPlacement& pa = placements_[static_cast<std::size_t>(take_a)].placement(frame_a);
  const RootPlacement& pb = placements_[static_cast<std::size_t>(take_b)].placement(frame_b);
  const double apart =
      std::hypot(pa.position_hs.x() - pb.position_hs.x(), pa.position_hs.z() - pb.position_hs.z());
  const double turn = std::abs(wrap_angle(pa.relative_yaw_rad() - pb.relative_yaw_rad()));
  return apart <= options_.placement_m && turn <= options_.facing_rad;
}

bool LookAlikeFrames::shows_the_same(const TruthFrame& truth,
                                     const FrameEstimate& estimate) const noexcept {
  const int takes = static_cast<int>(placements_.size());
  if (truth.take < 0 || truth.take >= takes || estimate.take < 0 || estimate.take >= takes ||
      !std::isfinite(truth.template_frame)) {
    return false;
  }
  const auto frames_of = [&](int take) {
    return first_row_[static_cast<std::size_t>(take) + 1] -
           first_row_[static_cast<std::size_t>(take)];
  };
  if (estimate.frame_in_take < 0 || estimate.frame_in_take >= frames_of(estimate.take)) {
    return false;
  }
  const double window = options_.window_ms / 1000.0 * frame_rate_hz_;
  if (estimate.take == truth.take &&
      std::abs(estimate.frame_in_take - truth.template_frame) <= window) {
    return true;
  }
  const int first = std::max(0, static_cast<int>(std::ceil(truth.template_frame - window)));
  const int last = std::min(frames_of(truth.take) - 1,
                            static_cast<int>(std::floor(truth.template_frame + window)));
  for (int frame = first; frame <= last; ++frame) {
    if (alike(truth.take, frame, estimate.take, estimate.frame_in_take)) return true;
  }
  return false;
}

}  // namespace duet
