// The template library the follower matches against: one feature vector per template frame, the
// take boundaries and the template frame rate. Built offline (may allocate, returns errors);
// immutable afterwards and shared read-only by every tracker and context.
//
// The follow module knows vectors, not skeletons: the features arrive already standardised and
// weighted (method.md 3) from the features module.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "duet/base/result.h"

namespace duet {

class CopyPlaces;

// Row i is the feature vector phi_i of template state i. Row-major float: the per-frame emission
// streams through every row once, so rows must be contiguous and small (27k x 60 floats = 6.5 MB).
using FeatureMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// A read-only view of M x D row-major features, wherever they are stored.
using FeatureView = Eigen::Map<const FeatureMatrix>;

class TemplateModel {
 public:
  // features: M x D, one row per template frame, several takes concatenated (a library, method.md
  //   1 "beyond"). Must be non-empty and finite.
  // take_start: first state of each take, strictly increasing, starting at 0, each < M; take k
  //   covers states [take_start[k], take_start[k+1]) and the last take ends at M. Empty means one
  //   take.
  // frame_rate_hz: rate of the template frames (the HMM runs at this rate), > 0.
  // velocity_dims: how many of the last dimensions are velocities (finite differences of the
  //   input, which a glitch or a jump in the input corrupts for a while; the HMM bounds their
  //   share of the distance, FollowParams::velocity_distance_cap). In [0, D].
  static Result<TemplateModel> build(FeatureMatrix features, std::vector<int> take_start,
                                     double frame_rate_hz, int velocity_dims = 0);
  // Same, from a row-major buffer of num_frames * num_dims floats (copied).
  static Result<TemplateModel> build(std::span<const float> features_row_major, int num_frames,
                                     int num_dims, std::vector<int> take_start,
                                     double frame_rate_hz, int velocity_dims = 0);
  // Same, on features the model does not copy: `storage` keeps them alive (e.g. a memory-mapped
  // model cache, model_cache.h) as long as the model or a copy of it lives. Features not already
  // at the model's precision (features()) are copied, rounded. At a million states
  // the row-major features are 200 MB that the follower reads only a few rows of per frame (the
  // SIMD kernel reads the blocked copy), so from a mapped file they stay mostly on disk.
  static Result<TemplateModel> build_shared(std::shared_ptr<const void> storage,
                                            std::span<const float> features_row_major,
                                            int num_frames, int num_dims,
                                            std::vector<int> take_start, double frame_rate_hz,
                                            int velocity_dims = 0);

  int num_states() const { return num_states_; }  // M
  int num_dims() const { return num_dims_; }      // D
  int num_takes() const { return static_cast<int>(take_start_.size()) - 1; }
  double frame_rate_hz() const { return frame_rate_hz_; }
  // The last velocity_dims() of the D dimensions are velocities (see build).
  int velocity_dims() const { return velocity_dims_; }

  // Row i is phi_i. A cheap view: copies of the model share the features. Held at half precision
  // (IEEE binary16 values, stored as floats): build rounds every feature to the nearest (beyond
  // +-65504, to +-65504). 11 significant bits, a relative error under 5e-4, a thousandth of a
  // sensor's noise in standardised units, so the emission kernel can stream half as many bytes
  // (blocked_features) and every path still computes on the same values.
  FeatureView features() const { return {features_.get(), num_states_, num_dims_}; }
  // The same features blocked for the SIMD emission kernel, as binary16 bits: states in blocks of
  // kStateBlock, and within a block dimension-major, so one load gives dimension d of
  // kStateBlock states:
  // blocked_features()[(b * D + blocked_dim(d)) * kStateBlock + l] = phi_{b * kStateBlock + l}(d).
  // The last block is padded with zeros. Built with the model (half the size of the features)
  // and again, in the limbs' order, by set_limbs.
  static constexpr int kStateBlock = 8;
  std::span<const std::uint16_t> blocked_features() const { return blocked_features_; }
  // A feature as the model holds it (see features()).
  static float held_precision(float value);
  // First state of take k, and one past its last state.
  int take_begin(int take) const { return take_start_[static_cast<std::size_t>(take)]; }
  int take_end(int take) const { return take_start_[static_cast<std::size_t>(take) + 1]; }
  // The take that contains state (O(log takes)); state must be in [0, M).
  int take_of(int state) const;
  // True when moving from state `from` to `to` over `steps` template steps leaves the band of
  // self/next/skip moves (method.md 2): anything but 0..2*steps frames forward in the same take,
  // where a step back by up to `tolerance` frames counts as no jump (a follower's jitter). False
  // when either state is -1 (no place yet).
  bool is_jump(int from, int to, int steps, int tolerance = 0) const noexcept;
  // The furthest forward the band reaches over `steps` template steps: a skip (two frames) each.
  static constexpr int band_reach(int steps) noexcept { return 2 * steps; }

  // The posture dimensions grouped by limb (FeatureSpec::limb_dims): the emission bounds the
  // share of the farthest (FollowParams::limb_outlier_ratio). Each dimension is below
  // num_dims() - velocity_dims() and in one limb at most; empty (the default) bounds none. Set
  // once, before the model is shared.
  // At most kMaxLimbModelDims dimensions (the kernel reorders the input on its stack).
  Status set_limbs(std::vector<std::vector<int>> limbs);
  static constexpr int kMaxLimbModelDims = 256;
  const std::vector<std::vector<int>>& limbs() const { return limbs_; }
  // Where dimension d sits in a state's lane of blocked_features() (below): d itself without
  // limbs; with them the dimensions in no limb come first, then each limb's (limb k at
  // blocked_limbs()[k], [begin, end)), then the velocities, so the SIMD kernel loads every group
  // contiguously.
  int blocked_dim(int d) const {
    return blocked_position_.empty() ? d : blocked_position_[static_cast<std::size_t>(d)];
  }
  // A vector of the D features (phi) in that order: phi itself without limbs, else its values
  // written into scratch (kMaxLimbModelDims floats). No allocation.
  const float* in_blocked_order(const float* phi, float* scratch) const noexcept {
    if (blocked_position_.empty()) return phi;
    for (int d = 0; d < num_dims_; ++d) scratch[blocked_dim(d)] = phi[d];
    return scratch;
  }
  struct DimRange {
    int begin;
    int end;
  };
  const std::vector<DimRange>& blocked_limbs() const { return limb_blocks_; }

  // A library grown with copies of its takes (copy_places.h): where each state sits in the
  // captured takes, for a confidence that counts every copy of a moment. Null otherwise. Set
  // once, before the model is shared; copies of the model share it.
  const CopyPlaces* copy_places() const { return copy_places_.get(); }
  void set_copy_places(std::shared_ptr<const CopyPlaces> places) {
    copy_places_ = std::move(places);
  }

 private:
  TemplateModel() = default;

  // Validates the features and sets up everything else; features_ points at them.
  static Result<TemplateModel> finish(std::shared_ptr<const float> features, int num_frames,
                                      int num_dims, std::vector<int> take_start,
                                      double frame_rate_hz, int velocity_dims);

  std::shared_ptr<const float> features_;  // M x D row-major, owned or shared (build_shared)
  int num_states_ = 0;
  int num_dims_ = 0;
  std::vector<std::uint16_t> blocked_features_;  // see blocked_features()
  std::vector<int> take_start_;          // num_takes + 1 entries; the last one is M
  double frame_rate_hz_ = 0.0;
  int velocity_dims_ = 0;
  std::vector<std::vector<int>> limbs_;
  std::vector<int> blocked_position_;  // see blocked_dim(); empty: the identity
  std::vector<DimRange> limb_blocks_;
  std::shared_ptr<const CopyPlaces> copy_places_;
};

}  // namespace duet
