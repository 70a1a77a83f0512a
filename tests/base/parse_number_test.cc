// parse_number: the whole text or nothing, the same rules for every reader.
#include "duet/base/parse_number.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace duet {
namespace {

TEST(ParseNumber, TakesTheWholeTextOrNothing) {
  EXPECT_EQ(parse_number<int>("42"), 42);
  EXPECT_EQ(parse_number<int>("-7"), -7);
  EXPECT_EQ(parse_number<double>("0.25"), 0.25);
  EXPECT_EQ(parse_number<double>("1e3"), 1000.0);
  for (const char* bad : {"", " 1", "1 ", "1x", "0x10", "+1", "--1", "1.5.2"}) {
    EXPECT_FALSE(parse_number<double>(bad)) << '"' << bad << '"';
    EXPECT_FALSE(parse_number<int>(bad)) << '"' << bad << '"';
  }
  EXPECT_FALSE(parse_number<int>("1.5"));
}

TEST(ParseNumber, RefusesWhatTheTypeCannotHold) {
  EXPECT_FALSE(parse_number<unsigned>("-1"));
  EXPECT_FALSE(parse_number<std::uint16_t>("65536"));
  EXPECT_EQ(parse_number<std::uint16_t>("65535"), 65535);
  EXPECT_FALSE(parse_number<int>("99999999999"));
  for (const char* not_finite : {"inf", "-inf", "nan", "1e400"}) {
    EXPECT_FALSE(parse_number<double>(not_finite)) << not_finite;
  }
}

TEST(ParseNumber, APlusSignOnlyWhenAllowed) {
  EXPECT_FALSE(parse_number<double>("+0.5"));
  EXPECT_EQ(parse_number<double>("+0.5", PlusSign::kAllowed), 0.5);
  EXPECT_EQ(parse_number<double>("-0.5", PlusSign::kAllowed), -0.5);
  EXPECT_FALSE(parse_number<double>("+-0.5", PlusSign::kAllowed));
  EXPECT_FALSE(parse_number<double>("+", PlusSign::kAllowed));
  EXPECT_EQ(parse_number<long long>("+12", PlusSign::kAllowed), 12);
}

}  // namespace
}  // namespace duet
