#include "duet/net/latency_histogram.h"

#include <gtest/gtest.h>

namespace duet::net {
namespace {

TEST(LatencyHistogram, ExactBelowOneMillisecond) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile(0.99), 0);
  for (int us = 1; us <= 1000; ++us) h.record(us);
  EXPECT_EQ(h.count(), 1000);
  EXPECT_EQ(h.percentile(0.5), 500);
  EXPECT_EQ(h.percentile(0.99), 990);
  EXPECT_EQ(h.percentile(1.0), 1000);
  EXPECT_EQ(h.max(), 1000);
}

TEST(LatencyHistogram, WithinOnePercentAbove) {
  LatencyHistogram h;
  for (int k = 0; k < 99; ++k) h.record(300);
  h.record(123456);
  EXPECT_EQ(h.percentile(0.99), 300);
  const auto p100 = h.percentile(1.0);
  EXPECT_EQ(p100, 123456);  // clamped to the max seen
  LatencyHistogram wide;
  for (std::int64_t v = 1000; v < 100'000'000; v = v * 11 / 10) {
    LatencyHistogram one;
    one.record(v);
    one.record(v + 1);  // so the bound is not clamped by max == v
    const auto p = one.percentile(0.5);
    EXPECT_GE(p, v);
    EXPECT_LE(p, v + v / 100 + 1) << v;
  }
  h.record(-5);  // clock skew: counted as 0
  EXPECT_EQ(h.percentile(0.0), 0);
}

TEST(LatencyHistogram, MergeAndClear) {
  LatencyHistogram a, b;
  for (int k = 0; k < 50; ++k) a.record(100);
  for (int k = 0; k < 50; ++k) b.record(2000);
  a.merge(b);
  EXPECT_EQ(a.count(), 100);
  EXPECT_EQ(a.percentile(0.5), 100);
  EXPECT_GE(a.percentile(0.99), 2000);
  EXPECT_EQ(a.max(), 2000);
  a.clear();
  EXPECT_EQ(a.count(), 0);
  EXPECT_EQ(a.max(), 0);
}

}  // namespace
}  // namespace duet::net
