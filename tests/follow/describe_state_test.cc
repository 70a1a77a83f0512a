// describe_state: what the follower reports of the state it chose, from the posterior around it.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "follow/forward_common.h"
#include "follow/synthetic.h"

namespace duet {
namespace {

FollowResult described(const TemplateModel& model, const std::vector<float>& posterior,
                       int state) {
  FollowResult r;
  follow_detail::describe_state(model, posterior.data(), 1.0f, state, 6, r);
  return r;
}

TEST(DescribeState, TheFrameOffsetIsThePosteriorsMeanAroundTheState) {
  const TemplateModel model = test::two_ramp_takes();
  std::vector<float> p(201, 0.0f);
  // Half the mass on 50, half on 51: the dancer is half-way between them.
  p[50] = 0.5f;
  p[51] = 0.5f;
  FollowResult r = described(model, p, 50);
  EXPECT_EQ(r.frame_in_take, 50);
  EXPECT_FLOAT_EQ(r.frame_offset, 0.5f);
  EXPECT_FLOAT_EQ(r.window_mass, 1.0f);
  // Mass spread evenly either side: on the state itself.
  std::fill(p.begin(), p.end(), 0.0f);
  p[49] = 0.25f;
  p[50] = 0.5f;
  p[51] = 0.25f;
  EXPECT_NEAR(described(model, p, 50).frame_offset, 0.0f, 1e-6f);
  // Mass outside the window (here, 30 frames behind) counts for neither the confidence nor the
  // offset.
  std::fill(p.begin(), p.end(), 0.0f);
  p[20] = 0.4f;
  p[50] = 0.3f;
  p[52] = 0.3f;
  r = described(model, p, 50);
  EXPECT_FLOAT_EQ(r.window_mass, 0.6f);
  EXPECT_FLOAT_EQ(r.frame_offset, 1.0f);
}

TEST(DescribeState, TheOffsetStaysInTheStatesTake) {
  const TemplateModel model = test::two_ramp_takes();
  std::vector<float> p(201, 0.0f);
  p[99] = 0.5f;  // the last frame of take 0
  p[100] = 0.3f;
  p[101] = 0.2f;
  const FollowResult r = described(model, p, 100);  // the first frame of take 1
  EXPECT_EQ(r.take, 1);
  EXPECT_EQ(r.frame_in_take, 0);
  EXPECT_NEAR(r.frame_offset, 0.2f / 0.5f, 1e-6f);
  // No mass around the state at all: no offset (and no NaN).
  std::vector<float> none(201, 0.0f);
  none[10] = 1.0f;
  EXPECT_EQ(described(model, none, 150).frame_offset, 0.0f);
}

}  // namespace
}  // namespace duet
