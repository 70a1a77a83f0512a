#include "duet/follow/jump_candidates.h"

#include <nanoflann.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

namespace duet {

namespace {

constexpr int kDims = JumpCandidateIndex::kProjectedDims;

// nanoflann's view of the projected points: M rows of kDims floats.
struct ProjectedPoints {
  std::vector<float> values;
  std::size_t kdtree_get_point_count() const { return values.size() / kDims; }
  float kdtree_get_pt(std::uint32_t i, std::size_t d) const {
    return values[static_cast<std::size_t>(i) * kDims + d];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*unused*/) const {
    return false;
  }
};

// nanoflann's result set for a radius search into caller-owned arrays of fixed capacity: the
// search stops (addPoint returns false) at the first point beyond the capacity.
class BoundedRadiusResult {
 public:
  BoundedRadiusResult(float radius_sq, std::size_t capacity, std::uint32_t* states, float* d2)
      : radius_sq_(radius_sq), capacity_(capacity), states_(states), d2_(d2) {}
  bool addPoint(float dist, std::uint32_t index) {
    if (dist >= radius_sq_) return true;
    if (count_ == capacity_) {
      overflow_ = true;
      return false;
    }
    states_[count_] = index;
    d2_[count_] = dist;
    ++count_;
    return true;
  }
  float worstDist() const { return radius_sq_; }
  bool full() const { return true; }
  std::size_t size() const { return count_; }
  bool overflow() const { return overflow_; }

 private:
  float radius_sq_;
  std::size_t capacity_;
  std::uint32_t* states_;
  float* d2_;
  std::size_t count_ = 0;
  bool overflow_ = false;
};

using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, ProjectedPoints>,
                                        ProjectedPoints, kDims, std::uint32_t>;

}  // namespace

struct JumpCandidateIndex::Impl {
  int posture_dims = 0;
  Eigen::VectorXf mean;                                             // posture_dims
  Eigen::Matrix<float, kDims, Eigen::Dynamic, Eigen::RowMajor> axes;  // kDims x posture_dims
  ProjectedPoints points;
  std::unique_ptr<Tree> tree;  // refers to points: Impl never moves (held by pointer)
};

JumpCandidateIndex::JumpCandidateIndex(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
JumpCandidateIndex::JumpCandidateIndex(JumpCandidateIndex&&) noexcept = default;
JumpCandidateIndex& JumpCandidateIndex::operator=(JumpCandidateIndex&&) noexcept = default;
JumpCandidateIndex::~JumpCandidateIndex() = default;

Result<JumpCandidateIndex> JumpCandidateIndex::build(const TemplateModel& model) {
  const int posture = model.num_dims() - model.velocity_dims();
  if (posture <= 0) {
    return make_error("jump candidate index", 0,
                      "the model has no posture dimensions (all " +
                          std::to_string(model.num_dims()) + " are velocities)");
  }
  auto impl = std::make_unique<Impl>();
  impl->posture_dims = posture;
  const auto features = model.features().leftCols(posture);
  const Eigen::Index rows = features.rows();
  impl->mean = features.colwise().mean().transpose();
  // Principal axes of the posture features. The covariance is summed in double over chunks of
  // rows, so that a library of 1M states needs no centred copy of its features.
  constexpr Eigen::Index kChunk = 4096;
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(posture, posture);
  Eigen::MatrixXd chunk;
  for (Eigen::Index begin = 0; begin < rows; begin += kChunk) {
    const Eigen::Index n = std::min(kChunk, rows - begin);
    chunk = (features.middleRows(begin, n).rowwise() - impl->mean.transpose()).cast<double>();
    covariance.noalias() += chunk.adjoint() * chunk;
  }
  covariance /= static_cast<double>(rows);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
  impl->axes.setZero(kDims, posture);
  for (int k = 0; k < std::min(kDims, posture); ++k) {
    // Eigenvalues ascend: the largest variance last.
    impl->axes.row(k) = solver.eigenvectors().col(posture - 1 - k).transpose().cast<float>();
  }
  impl->points.values.resize(static_cast<std::size_t>(rows) * kDims);
  Eigen::Map<Eigen::Matrix<float, Eigen::Dynamic, kDims, Eigen::RowMajor>> projected(
      impl->points.values.data(), rows, kDims);
  for (Eigen::Index begin = 0; begin < rows; begin += kChunk) {
    const Eigen::Index n = std::min(kChunk, rows - begin);
    projected.middleRows(begin, n).noalias() =
        (features.middleRows(begin, n).rowwise() - impl->mean.transpose()) *
        impl->axes.transpose();
  }
  impl->tree = std::make_unique<Tree>(kDims, impl->points,
                                      nanoflann::KDTreeSingleIndexAdaptorParams(16));
  return JumpCandidateIndex(std::move(impl));
}

std::array<float, kDims> JumpCandidateIndex::project(const float* phi) const noexcept {
  const Impl& impl = *impl_;
  // Plain loops: an Eigen product of a dynamic difference would allocate its temporary.
  std::array<float, kDims> query{};
  for (int p = 0; p < impl.posture_dims; ++p) {
    const float centred = phi[p] - impl.mean[p];
    for (int d = 0; d < kDims; ++d) query[static_cast<std::size_t>(d)] += impl.axes(d, p) * centred;
  }
  return query;
}

int JumpCandidateIndex::nearest(const float* phi, int k, std::uint32_t* states,
                                float* projected_d2, float& bound) const noexcept {
  const std::array<float, kDims> query = project(phi);
  nanoflann::KNNResultSet<float, std::uint32_t, std::size_t> result(static_cast<std::size_t>(k));
  result.init(states, projected_d2);
  impl_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams());
  const int found = static_cast<int>(result.size());
  bound = found == k ? result.worstDist() : 0.0f;
  return found;
}

int JumpCandidateIndex::within(const float* phi, float radius_sq, int capacity,
                               std::uint32_t* states, float* projected_d2) const noexcept {
  const std::array<float, kDims> query = project(phi);
  BoundedRadiusResult result(radius_sq, static_cast<std::size_t>(std::max(capacity, 0)), states,
                             projected_d2);
  impl_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.overflow() ? -1 : static_cast<int>(result.size());
}

namespace {

template <class T>
void write_array(std::ostream& out, const T* data, std::size_t count) {
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
}

template <class T>
bool read_array(std::istream& in, T* data, std::size_t count) {
  in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(count * sizeof(T)));
  return static_cast<bool>(in);
}

}  // namespace

void JumpCandidateIndex::save(std::ostream& out) const {
  const Impl& impl = *impl_;
  const std::int32_t header[2] = {impl.posture_dims,
                                  static_cast<std::int32_t>(impl.points.kdtree_get_point_count())};
  write_array(out, header, 2);
  write_array(out, impl.mean.data(), static_cast<std::size_t>(impl.mean.size()));
  write_array(out, impl.axes.data(), static_cast<std::size_t>(impl.axes.size()));
  write_array(out, impl.points.values.data(), impl.points.values.size());
  impl.tree->saveIndex(out);
}

Result<JumpCandidateIndex> JumpCandidateIndex::load(std::istream& in, int num_states,
                                                    int posture_dims) {
  auto fail = [](const std::string& what) {
    return make_error("jump candidate index", 0, what);
  };
  std::int32_t header[2] = {0, 0};
  if (!read_array(in, header, 2)) return fail("truncated before its sizes");
  if (header[0] != posture_dims || header[1] != num_states) {
    return fail("built for " + std::to_string(header[1]) + " states x " +
                std::to_string(header[0]) + " posture dimensions, the model has " +
                std::to_string(num_states) + " x " + std::to_string(posture_dims));
  }
  auto impl = std::make_unique<Impl>();
  impl->posture_dims = posture_dims;
  impl->mean.resize(posture_dims);
  impl->axes.resize(kDims, posture_dims);
  impl->points.values.resize(static_cast<std::size_t>(num_states) * kDims);
  if (!read_array(in, impl->mean.data(), static_cast<std::size_t>(posture_dims)) ||
      !read_array(in, impl->axes.data(), static_cast<std::size_t>(impl->axes.size())) ||
      !read_array(in, impl->points.values.data(), impl->points.values.size())) {
    return fail("truncated in its projection");
  }
  impl->tree = std::make_unique<Tree>(
      kDims, impl->points,
      nanoflann::KDTreeSingleIndexAdaptorParams(
          16, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
  impl->tree->loadIndex(in);
  if (!in || impl->tree->vAcc.size() != static_cast<std::size_t>(num_states)) {
    return fail("truncated or damaged in its tree");
  }
  return JumpCandidateIndex(std::move(impl));
}

int JumpCandidateIndex::num_states() const noexcept {
  return static_cast<int>(impl_->points.kdtree_get_point_count());
}

std::size_t JumpCandidateIndex::memory_bytes() const noexcept {
  // The projected points and the tree's permutation; the tree's nodes are a few per leaf.
  return impl_->points.values.size() * sizeof(float) +
         impl_->points.kdtree_get_point_count() * (sizeof(std::uint32_t) + 16);
}

}  // namespace duet
