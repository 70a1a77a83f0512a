#include "duet/motion/skeleton_map.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace duet {
namespace {

Skeleton skeleton_with(const std::array<std::string, kRoleCount>& names) {
  Skeleton s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    s.joints.push_back({names[i], i == 0 ? -1 : 0, Vec3::Zero(), {}, false});
  }
  return s;
}

TEST(SkeletonMap, DetectsEachBuiltInConvention) {
  for (const SkeletonMap& map : builtin_skeleton_maps()) {
    JointRoles roles;
    std::string error;
    ASSERT_TRUE(detect_roles(skeleton_with(map.joint_names), roles, error)) << error;
    EXPECT_EQ(roles.convention, map.name);
    EXPECT_EQ(roles[Role::kHips], 0);
    EXPECT_EQ(roles[Role::kRightToe], kRoleCount - 1);
  }
}

TEST(SkeletonMap, UnknownSkeletonListsMissingRoles) {
  auto names = builtin_skeleton_maps()[0].joint_names;
  names[static_cast<std::size_t>(Role::kLeftWrist)] = "somethingElse";
  JointRoles roles;
  std::string error;
  EXPECT_FALSE(detect_roles(skeleton_with(names), roles, error));
  EXPECT_NE(error.find("daz: missing roles left_wrist ('lHand')"), std::string::npos) << error;
  EXPECT_NE(error.find("cmu-bvh: missing roles hips ('Hips')"), std::string::npos) << error;
}

class MapFileTest : public ::testing::Test {
 protected:
  std::string write(const std::string& text) {
    // One file per test and process: ctest runs the tests of this fixture in parallel.
    path_ = (std::filesystem::temp_directory_path() /
             ("duet_map_test_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".json"))
                .string();
    std::ofstream(path_) << text;
    return path_;
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

TEST_F(MapFileTest, LoadsAUsersMap) {
  std::string json = R"({"name": "mine", "roles": {)";
  for (int r = 0; r < kRoleCount; ++r) {
    json += (r ? "," : "") + std::string("\"") + std::string(role_name(static_cast<Role>(r))) +
            "\": \"j" + std::to_string(r) + "\"";
  }
  json += "}}";
  SkeletonMap map;
  std::string error;
  ASSERT_TRUE(load_skeleton_map(write(json), map, error)) << error;
  EXPECT_EQ(map.name, "mine");
  EXPECT_EQ(map.joint_names[static_cast<std::size_t>(Role::kHead)], "j4");
}

TEST_F(MapFileTest, RejectsBadMapsWithReasons) {
  SkeletonMap map;
  std::string error;
  EXPECT_FALSE(load_skeleton_map(write("{not json"), map, error));
  EXPECT_NE(error.find("not valid JSON"), std::string::npos);
  EXPECT_FALSE(load_skeleton_map(write(R"({"roles": {"tail": "x"}})"), map, error));
  EXPECT_NE(error.find("unknown role \"tail\""), std::string::npos);
  EXPECT_FALSE(load_skeleton_map(write(R"({"roles": {"hips": "x"}})"), map, error));
  EXPECT_NE(error.find("roles not given: spine"), std::string::npos);
  EXPECT_FALSE(load_skeleton_map("/nonexistent/map.json", map, error));
  EXPECT_NE(error.find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace duet
