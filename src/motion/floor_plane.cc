#include "duet/motion/floor_plane.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "duet/math/median.h"
#include "duet/math/rotation.h"

namespace duet {
namespace {

// The least spread a fit assumes (toes rest on a floor within about a centimetre).
constexpr double kLeastHeightSpreadM = 0.01;
// Samples of a dance closer than this are not independent evidence of the floor.
constexpr double kIndependentAfterS = 0.5;
constexpr int kPasses = 6;
constexpr double kTrimSpreads = 3.0;

}  // namespace

FloorFit fit_floor(std::span<const Vec3> points, const Vec3& prior_up, double span_s,
                   double prior_sigma_deg, PlaneOutliers outliers) {
  FloorFit fit;
  const Vec3 prior =
      prior_up.allFinite() && prior_up.y() > 0.0 ? prior_up.normalized() : Vec3::UnitY();
  fit.up = prior;
  std::vector<Vec3> finite;
  for (const Vec3& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  if (finite.size() < 3) return fit;

  // The plane y = a x + b z + c, its slope (a, b) drawn towards the prior's, fitted in a frame
  // turned so that the last estimate is its Y: the points' scatter is along the floor's normal,
  // not the world's Y, and a least-squares slope in a tilted frame would be biased by it.
  const double prior_weight = 1.0 / std::pow(std::tan(deg_to_rad(prior_sigma_deg)), 2);
  const double independent =
      std::clamp(span_s / kIndependentAfterS, 1.0, static_cast<double>(finite.size()));
  std::vector<char> inlier(finite.size(), 1);
  std::vector<Vec3> local(finite.size());
  std::vector<double> residuals(finite.size());
  Vec3 up = prior;
  double spread = 0.02;
  double tilt_sigma_rad = 0.0;
  bool solved = false;
  for (int pass = 0; pass < kPasses; ++pass) {
    const Quat to_local = Quat::FromTwoVectors(up, Vec3::UnitY());
    for (std::size_t i = 0; i < finite.size(); ++i) local[i] = to_local * finite[i];
    const Vec3 local_prior = to_local * prior;
    const Eigen::Vector2d prior_slope(-local_prior.x() / local_prior.y(),
                                      -local_prior.z() / local_prior.y());
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    int used = 0;
    for (std::size_t i = 0; i < local.size(); ++i) {
      if (!inlier[i]) continue;
      const Eigen::Vector3d row(local[i].x(), local[i].z(), 1.0);
      normal += row * row.transpose();
      rhs += row * local[i].y();
      ++used;
    }
    if (used < 3) break;
    // Each sample weighs 1 / spread^2, scaled down to the independent samples' count.
    const double weight =
        std::min(1.0, independent / used) / std::pow(std::max(spread, kLeastHeightSpreadM), 2);
    normal *= weight;
    rhs *= weight;
    normal.topLeftCorner<2, 2>() += prior_weight * Eigen::Matrix2d::Identity();
    rhs.head<2>() += prior_weight * prior_slope;
    const Eigen::Vector3d plane = normal.ldlt().solve(rhs);
    if (!plane.allFinite()) break;
    // The slope's covariance is the inverse of the weighted normal matrix; its larger axis.
    const Eigen::Matrix2d slope_covariance = normal.inverse().topLeftCorner<2, 2>();
    const double largest_variance =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(slope_covariance).eigenvalues().maxCoeff();
    tilt_sigma_rad = std::atan(std::sqrt(std::max(0.0, largest_variance)));
    solved = true;
    for (std::size_t i = 0; i < local.size(); ++i) {
      // Signed: a toe above the floor (a foot in the air) is positive.
      residuals[i] =
          local[i].y() - (plane.x() * local[i].x() + plane.y() * local[i].z() + plane.z());
    }
    std::vector<double> magnitudes;
    magnitudes.reserve(residuals.size());
    for (std::size_t i = 0; i < residuals.size(); ++i) {
      if (inlier[i]) magnitudes.push_back(std::abs(residuals[i]));
    }
    spread = 1.4826 * upper_median(std::move(magnitudes));
    // Points far out on the outliers' side are set aside (feet in the air above the toes' floor,
    // a head's dips below its path), and points far out on the other side are doubted too.
    const double limit = kTrimSpreads * std::max(spread, kLeastHeightSpreadM);
    const double side = outliers == PlaneOutliers::kAbove ? 1.0 : -1.0;
    for (std::size_t i = 0; i < local.size(); ++i) {
      inlier[i] = side * residuals[i] <= limit && side * residuals[i] >= -2.0 * limit;
    }
    up = (to_local.conjugate() * Vec3(-plane.x(), 1.0, -plane.y())).normalized();
  }
  if (!solved) return fit;
  fit.up = up;
  fit.height_spread_m = spread;
  fit.tilt_sigma_deg = rad_to_deg(tilt_sigma_rad);
  return fit;
}

}  // namespace duet
