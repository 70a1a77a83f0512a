// Where a jump may land: the template states whose posture is nearest the input frame, found by a
// k-d tree (nanoflann) over a low-dimensional projection of the posture features. The beam
// follower (beam_follower.h) gives these states the mass resuming from the pause state, so a jump
// is followed without computing every emission.
//
// The projection onto the first principal axes of the posture features is orthonormal, so the
// projected squared distance never exceeds the posture distance, which never exceeds the
// emission distance (the velocity part only adds). Hence every state that is not returned is at
// least `bound` away from the input: the follower can bound the mass it leaves out.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <memory>

#include "duet/base/result.h"
#include "duet/follow/template_model.h"

namespace duet {

class JumpCandidateIndex {
 public:
  static constexpr int kProjectedDims = 8;

  // Projects the model's posture features (the dimensions before its velocities) and builds the
  // tree. Allocates (O(M)); the model must outlive the index.
  static Result<JumpCandidateIndex> build(const TemplateModel& model);

  JumpCandidateIndex(JumpCandidateIndex&&) noexcept;
  JumpCandidateIndex& operator=(JumpCandidateIndex&&) noexcept;
  ~JumpCandidateIndex();

  // The k states nearest phi (model.num_dims() finite values) in the projection: writes their
  // indices to states[0..n) and returns n = min(k, M). Every other state's emission distance is
  // >= the returned bound (0 when n < k). Allocates nothing.
  int nearest(const float* phi, int k, std::uint32_t* states, float* projected_d2,
              float& bound) const noexcept;

  // Every state whose projected squared distance to phi is below radius_sq, up to `capacity` of
  // them: writes their indices to states[0..n) (in no particular order) and returns n, or -1
  // when more than `capacity` states lie within (the search stops there). Every other state's
  // emission distance is >= radius_sq. Allocates nothing.
  int within(const float* phi, float radius_sq, int capacity, std::uint32_t* states,
             float* projected_d2) const noexcept;

  std::size_t memory_bytes() const noexcept;
  int num_states() const noexcept;

  // The index as bytes (projection, projected points and tree), for the model cache
  // (model_cache.h). The stream is native-endian and only for this build's readers.
  void save(std::ostream& out) const;
  // An index saved by save() for a model of num_states states with posture_dims posture
  // dimensions; an error when the bytes do not describe one.
  static Result<JumpCandidateIndex> load(std::istream& in, int num_states, int posture_dims);

 private:
  struct Impl;
  // phi's posture on the index's principal axes.
  std::array<float, kProjectedDims> project(const float* phi) const noexcept;
  explicit JumpCandidateIndex(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace duet
