// The floor a dancer stands on, read from where the feet touch it: for levelling a world whose
// floor is tilted (motion/up_axis.h). Over a dance the lower foot's toe is on the floor on most
// frames, at places spread over the room, so the plane through those points is the floor. Unlike
// the body's mean feet-to-head direction it does not lean with the dancer, nor with a suit's
// calibration error in the trunk: over the 28 salsa takes it is within 1.3 degrees of the level.
#pragma once

#include <span>

#include "duet/math/types.h"

namespace duet {

// Which side of the plane the points' outliers lie on: a foot in the air is above the floor, a
// head that dips is below the plane its path keeps to.
enum class PlaneOutliers { kAbove, kBelow };

struct FloorFit {
  Vec3 up = Vec3::UnitY();       // the floor's normal (unit, +Y side)
  double height_spread_m = 0.0;  // robust spread of the points about the plane
  // The standard error of the plane's tilt, degrees, along its least determined direction (from
  // the last pass's weights: samples half a second apart counted independent, the prior included).
  double tilt_sigma_deg = 0.0;
};

// The floor through `points` (world, nearly Y-up: one lower-toe position per sampled frame,
// spread over `span_s` seconds of motion). Where the points do not spread over the floor (a
// dancer dancing on the spot, or walking along one line) the plane is ill-determined in that
// direction, so its slope is drawn towards `prior_up` (the body's mean up) with a prior of
// prior_sigma_deg; samples closer than half a second count as one. Points far off the plane (a
// foot in the air on every frame of a jump) are set aside (3 robust spreads). Non-finite points
// are skipped; with fewer than 3 points, `prior_up` normalised.
FloorFit fit_floor(std::span<const Vec3> points, const Vec3& prior_up, double span_s,
                   double prior_sigma_deg = 3.0, PlaneOutliers outliers = PlaneOutliers::kAbove);

}  // namespace duet
