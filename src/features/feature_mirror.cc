#include "duet/features/feature_mirror.h"

#include <string>

namespace duet {
namespace {

// The raw mirror: out[d] = sign[d] * in[source[d]].
struct RawMirror {
  std::vector<int> source;
  std::vector<float> sign;
  void add(int from, float s) {
    source.push_back(from);
    sign.push_back(s);
  }
  // A 3-vector whose x flips (a position or direction in the heading frame).
  void add_vector(int first, float s) {
    add(first, -s);
    add(first + 1, s);
    add(first + 2, s);
  }
};

Error no_mirror(const std::string& what) {
  return Error{"feature mirror: " + what + " has no mirror image in the feature spec"};
}

Result<RawMirror> full_body_mirror(const FeatureSpec& spec) {
  RawMirror m;
  const auto& segments = spec.posture_segments;
  for (const BodySegment& segment : segments) {
    const Role from = mirror_role(segment.from), to = mirror_role(segment.to);
    int found = -1;
    float sign = 1.0f;
    for (std::size_t k = 0; k < segments.size() && found < 0; ++k) {
      if (segments[k].from == from && segments[k].to == to) {
        found = static_cast<int>(k);
      } else if (segments[k].from == to && segments[k].to == from) {
        found = static_cast<int>(k);
        sign = -1.0f;  // the mirror image runs the other way along that segment
      }
    }
    if (found < 0) {
      return no_mirror("segment " + std::string(role_name(segment.from)) + " -> " +
                       std::string(role_name(segment.to)));
    }
    m.add_vector(3 * found, sign);
  }
  const int points_begin = 3 * static_cast<int>(segments.size());
  for (const Role point : spec.posture_points) {
    int found = -1;
    for (std::size_t k = 0; k < spec.posture_points.size() && found < 0; ++k) {
      if (spec.posture_points[k] == mirror_role(point)) found = static_cast<int>(k);
    }
    if (found < 0) return no_mirror("point " + std::string(role_name(point)));
    m.add_vector(points_begin + 3 * found, 1.0f);
  }
  return m;
}

RawMirror head_hands_mirror(const FeatureSpec& spec) {
  RawMirror m;
  m.add_vector(3, 1.0f);  // the left hand is the right one's mirror image
  m.add_vector(0, 1.0f);
  m.add(6, 1.0f);  // head height
  if (spec.head_tilt) m.add_vector(7, 1.0f);
  return m;
}

}  // namespace

Role mirror_role(Role role) noexcept {
  switch (role) {
    case Role::kLeftShoulder: return Role::kRightShoulder;
    case Role::kLeftElbow: return Role::kRightElbow;
    case Role::kLeftWrist: return Role::kRightWrist;
    case Role::kRightShoulder: return Role::kLeftShoulder;
    case Role::kRightElbow: return Role::kLeftElbow;
    case Role::kRightWrist: return Role::kLeftWrist;
    case Role::kLeftHip: return Role::kRightHip;
    case Role::kLeftKnee: return Role::kRightKnee;
    case Role::kLeftAnkle: return Role::kRightAnkle;
    case Role::kLeftToe: return Role::kRightToe;
    case Role::kRightHip: return Role::kLeftHip;
    case Role::kRightKnee: return Role::kLeftKnee;
    case Role::kRightAnkle: return Role::kLeftAnkle;
    case Role::kRightToe: return Role::kLeftToe;
    default: return role;
  }
}

Result<std::vector<MirroredDim>> feature_mirror(const FeatureSpec& spec,
                                                const FeatureNormalizer& normalizer) {
  const bool head_hands = spec.input_points == InputPoints::kHeadHands;
  RawMirror raw;
  if (head_hands) {
    raw = head_hands_mirror(spec);
  } else {
    Result<RawMirror> body = full_body_mirror(spec);
    if (!body) return body.error();
    raw = std::move(body).value();
  }
  // Velocities: forward, lateral (flips), vertical, yaw rate (flips), then the effector speeds
  // in pairs (left hand, right hand[, left foot, right foot]) that swap.
  const int v = spec.posture_dims();
  raw.add(v + 0, 1.0f);
  raw.add(v + 1, -1.0f);
  raw.add(v + 2, 1.0f);
  raw.add(v + 3, -1.0f);
  for (int e = 0; e < spec.effector_speed_dims(); ++e) {
    raw.add(v + FeatureSpec::kRootVelocityDims + (e ^ 1), 1.0f);
  }
  const auto dims = static_cast<std::size_t>(spec.dimension());
  if (raw.source.size() != dims || static_cast<std::size_t>(normalizer.mean().size()) != dims) {
    return Error{"feature mirror: the normaliser has " + std::to_string(normalizer.mean().size()) +
                 " dimensions, the spec " + std::to_string(dims)};
  }
  // Standardised: phi = (x - mean) * scale, so mirrored phi[d] = (sign x[s] - mean[d]) scale[d]
  // with x[s] = phi[s] / scale[s] + mean[s].
  std::vector<MirroredDim> out(dims);
  for (std::size_t d = 0; d < dims; ++d) {
    const auto i = static_cast<Eigen::Index>(d);
    const auto s = static_cast<Eigen::Index>(raw.source[d]);
    const float sign = raw.sign[d];
    out[d].source = raw.source[d];
    if (normalizer.scale()[s] == 0.0f) continue;  // a block weighted 0: 0 on both sides
    out[d].scale = sign * normalizer.scale()[i] / normalizer.scale()[s];
    out[d].offset = normalizer.scale()[i] * (sign * normalizer.mean()[s] - normalizer.mean()[i]);
  }
  return out;
}

}  // namespace duet
