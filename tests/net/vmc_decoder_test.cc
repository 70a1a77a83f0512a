// VMC datagrams into poses: real OSC built with liblo (as performers send it), and garbage,
// truncated and hostile packets, which must be counted and never crash or make a frame.
#include "duet/net/vmc_decoder.h"

#include <gtest/gtest.h>
#include <lo/lo.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "duet/live/vmc_humanoid.h"

namespace duet::net {
namespace {

const auto kT0 = SteadyClock::time_point{} + std::chrono::seconds(100);

struct Bytes {
  std::vector<char> data;
};

Bytes serialise(lo_bundle bundle) {
  size_t size = 0;
  void* raw = lo_bundle_serialise(bundle, nullptr, &size);
  Bytes b;
  b.data.assign(static_cast<char*>(raw), static_cast<char*>(raw) + size);
  std::free(raw);
  lo_bundle_free_recursive(bundle);
  return b;
}

Bytes serialise(lo_message message, const char* path) {
  size_t size = 0;
  void* raw = lo_message_serialise(message, path, nullptr, &size);
  Bytes b;
  b.data.assign(static_cast<char*>(raw), static_cast<char*>(raw) + size);
  std::free(raw);
  lo_message_free(message);
  return b;
}

lo_message transform_message(const char* name, std::initializer_list<float> values) {
  lo_message m = lo_message_new();
  lo_message_add_string(m, name);
  for (const float v : values) lo_message_add_float(m, v);
  return m;
}

lo_message int_message(int value) {
  lo_message m = lo_message_new();
  lo_message_add_int32(m, value);
  return m;
}

void feed(Bytes bytes, VmcSource& source, SteadyClock::time_point at = kT0) {
  decode_vmc_packet(bytes.data.data(), bytes.data.size(), at, source);
}

// A frame as XR Animator sends it: root, bones (one finger among them), a blend shape, OK, T.
Bytes frame_bundle(float hips_x, float arm_qy) {
  lo_bundle b = lo_bundle_new(LO_TT_IMMEDIATE);
  lo_bundle_add_message(b, "/VMC/Ext/Root/Pos",
                        transform_message("root", {1.0f, 0.0f, 2.0f, 0.0f, 0.0f, 0.0f, 1.0f}));
  lo_bundle_add_message(b, "/VMC/Ext/Bone/Pos",
                        transform_message("Hips", {hips_x, 0.9f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f}));
  const float w = std::sqrt(1.0f - arm_qy * arm_qy);
  lo_bundle_add_message(
      b, "/VMC/Ext/Bone/Pos",
      transform_message("LeftUpperArm", {0.1f, 0.0f, 0.0f, 0.0f, arm_qy, 0.0f, w}));
  lo_bundle_add_message(
      b, "/VMC/Ext/Bone/Pos",
      transform_message("LeftIndexProximal", {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f}));
  lo_message blend = lo_message_new();
  lo_message_add_string(blend, "Joy");
  lo_message_add_float(blend, 0.5f);
  lo_bundle_add_message(b, "/VMC/Ext/Blend/Val", blend);
  lo_bundle_add_message(b, "/VMC/Ext/OK", int_message(1));
  lo_message t = lo_message_new();
  lo_message_add_float(t, 12.5f);
  lo_bundle_add_message(b, "/VMC/Ext/T", t);
  return serialise(b);
}

TEST(VmcDecoder, AFrameFromABundleInDuetAxes) {
  VmcSource source({}, "test");
  feed(frame_bundle(0.25f, 0.6f), source);
  SourceFrame frame;
  frame.resize(source.source_skeleton().joint_count());
  ASSERT_TRUE(source.poll(kT0, frame));
  EXPECT_FALSE(source.poll(kT0, frame));  // OK and T end one frame, not two
  EXPECT_EQ(source.stats().rejected, 0);
  EXPECT_EQ(source.ignored(), 2);  // the finger and the blend shape
  // The hips: root position plus the hips' local position, X mirrored (Unity is left-handed).
  EXPECT_NEAR(frame.translations_ls[0].x(), -1.25, 1e-6);
  EXPECT_NEAR(frame.translations_ls[0].y(), 0.9, 1e-6);
  EXPECT_NEAR(frame.translations_ls[0].z(), 2.0, 1e-6);
  // A Unity rotation about +Y is one about -Y in Duet's axes.
  const int arm = vmc_bone_index("LeftUpperArm");
  ASSERT_GT(arm, 0);
  EXPECT_NEAR(frame.rotations_ls[static_cast<std::size_t>(arm)].y(), -0.6, 1e-6);
  EXPECT_NEAR(frame.rotations_ls[static_cast<std::size_t>(arm)].w(), 0.8, 1e-6);
  EXPECT_DOUBLE_EQ(frame.time_s, 0.0);
  // A bone the frame does not mention keeps its rest pose.
  const int head = vmc_bone_index("Head");
  EXPECT_TRUE(frame.rotations_ls[static_cast<std::size_t>(head)].isApprox(Quat::Identity()));
  // Frame times are arrival times.
  feed(frame_bundle(0.0f, 0.0f), source, kT0 + std::chrono::milliseconds(20));
  ASSERT_TRUE(source.poll(kT0, frame));
  EXPECT_NEAR(frame.time_s, 0.020, 1e-9);
  EXPECT_EQ(source.stats().frames, 2);
}

TEST(VmcDecoder, MessagesSpreadOverDatagramsMakeOneFrame) {
  // VSeeFace splits a frame over several datagrams; the frame ends at OK.
  VmcSource source({}, "test");
  feed(serialise(transform_message("Hips", {0, 1, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Spine", {0, 0.1f, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"),
       source);
  SourceFrame frame;
  frame.resize(source.source_skeleton().joint_count());
  // No OK seen yet from this sender: each datagram with bone data would be a frame...
  EXPECT_TRUE(source.poll(kT0, frame));
  EXPECT_TRUE(source.poll(kT0, frame));
  // ...until it shows it ends frames with OK; from then on only OK does.
  feed(serialise(int_message(1), "/VMC/Ext/OK"), source);
  feed(serialise(transform_message("Hips", {0, 1, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Spine", {0, 0.1f, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"),
       source);
  EXPECT_FALSE(source.poll(kT0, frame));
  feed(serialise(int_message(1), "/VMC/Ext/OK"), source);
  EXPECT_TRUE(source.poll(kT0, frame));
  EXPECT_EQ(source.stats().rejected, 0);
}

TEST(VmcDecoder, BadMessagesAreCountedNotUsed) {
  VmcSource source({}, "test");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Wrong argument types and counts, non-finite numbers, a far position, a zero quaternion.
  lo_message ints = lo_message_new();
  lo_message_add_string(ints, "Hips");
  for (int k = 0; k < 7; ++k) lo_message_add_int32(ints, 1);
  feed(serialise(ints, "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Hips", {0, 1, 0}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Hips", {nan, 1, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Hips", {1e6f, 1, 0, 0, 0, 0, 1}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("Hips", {0, 1, 0, 0, 0, 0, 0}), "/VMC/Ext/Bone/Pos"), source);
  feed(serialise(transform_message("root", {0, 0, 0, 0, 0, 0, 1e9f}), "/VMC/Ext/Root/Pos"), source);
  // Not VMC at all.
  feed(serialise(int_message(3), "/avatar/parameters/Foo"), source);
  EXPECT_EQ(source.stats().rejected, 7);
  EXPECT_EQ(source.last_rejection(), VmcReject::kForeign);
  SourceFrame frame;
  frame.resize(source.source_skeleton().joint_count());
  feed(serialise(int_message(1), "/VMC/Ext/OK"), source);
  EXPECT_FALSE(source.poll(kT0, frame));  // nothing valid arrived: no frame
}

TEST(VmcDecoder, GarbageAndTruncatedPacketsNeverCrash) {
  VmcSource source({}, "test");
  const Bytes good = frame_bundle(0.1f, 0.2f);
  // Where the bundle's elements end: a cut there is a shorter, valid bundle.
  std::vector<std::size_t> boundaries = {16};
  for (std::size_t at = 16; at < good.data.size();) {
    const auto* u = reinterpret_cast<const unsigned char*>(good.data.data() + at);
    at += 4 + ((std::size_t{u[0]} << 24) | (std::size_t{u[1]} << 16) | (std::size_t{u[2]} << 8) |
               std::size_t{u[3]});
    boundaries.push_back(at);
  }
  long long expected_rejections = 0;
  // Every other truncation of a good bundle: the elements before the cut are used, the cut one
  // is rejected.
  for (std::size_t n = 0; n < good.data.size(); ++n) {
    Bytes cut;
    cut.data.assign(good.data.begin(), good.data.begin() + static_cast<std::ptrdiff_t>(n));
    const long long before = source.stats().rejected;
    feed(cut, source);
    if (std::find(boundaries.begin(), boundaries.end(), n) != boundaries.end()) {
      EXPECT_EQ(source.stats().rejected, before) << "a bundle cut to " << n << " bytes";
    } else {
      EXPECT_GT(source.stats().rejected, before) << "a bundle cut to " << n << " bytes";
      ++expected_rejections;
    }
  }
  // An element claiming more bytes than the bundle has; a bundle nested too deep; a message with
  // an unterminated address; random bytes.
  Bytes oversize = good;
  oversize.data[16] = 0x7f;
  feed(oversize, source);
  std::string nested;
  for (int k = 0; k < 8; ++k) nested += std::string("#bundle\0\0\0\0\0\0\0\0\1", 16);
  feed(Bytes{std::vector<char>(nested.begin(), nested.end())}, source);
  feed(Bytes{std::vector<char>{'/', 'V', 'M', 'C'}}, source);
  std::mt19937 random(7);
  for (int k = 0; k < 2000; ++k) {
    Bytes noise;
    noise.data.resize(random() % 200);
    for (char& c : noise.data) c = static_cast<char>(random());
    if (k % 2 == 0 && noise.data.size() >= 8) std::memcpy(noise.data.data(), "#bundle", 8);
    feed(noise, source);
  }
  // Near-valid packets: the good bundle with a few bytes changed (sizes, type tags, addresses,
  // string padding), where a decoder is most likely to trust what it should not.
  for (int k = 0; k < 5000; ++k) {
    Bytes mutated = good;
    for (int flips = 1 + static_cast<int>(random() % 4); flips > 0; --flips) {
      mutated.data[random() % mutated.data.size()] = static_cast<char>(random());
    }
    feed(mutated, source);
  }
  EXPECT_GT(source.stats().rejected, expected_rejections + 3);
  SourceFrame frame;
  frame.resize(source.source_skeleton().joint_count());
  while (source.poll(kT0, frame)) {
    for (const Quat& q : frame.rotations_ls) EXPECT_NEAR(q.norm(), 1.0, 1e-6);
    for (const Vec3& t : frame.translations_ls) EXPECT_TRUE(t.allFinite());
  }
  // And a good frame still decodes after all that.
  feed(good, source);
  EXPECT_TRUE(source.poll(kT0, frame));
}

TEST(VmcHumanoid, RolesAndAxes) {
  const SourceSkeleton h = vmc_humanoid();
  ASSERT_TRUE(h.skeleton);
  EXPECT_EQ(h.skeleton->validate(), "");
  EXPECT_EQ(h.skeleton->joints[static_cast<std::size_t>(h.roles[Role::kLeftWrist])].name,
            "LeftHand");
  EXPECT_EQ(h.skeleton->joints[static_cast<std::size_t>(h.roles[Role::kChest])].name, "UpperChest");
  // The left hand is at +X (facing +Z, Y up, right-handed).
  EXPECT_GT(h.skeleton->joints[static_cast<std::size_t>(vmc_bone_index("LeftUpperArm"))].offset.x(),
            0.0);
  EXPECT_EQ(vmc_bone_index("LeftIndexProximal"), -1);
  const Quat q = Quat(0.5, 0.5, 0.5, 0.5);
  EXPECT_TRUE(duet_to_unity(unity_to_duet(q)).isApprox(q));
}

}  // namespace
}  // namespace duet::net
