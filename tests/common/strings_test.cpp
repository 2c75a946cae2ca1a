#include "tools/common/strings.h"

#include <gtest/gtest.h>

namespace igi {
namespace {

TEST(StringsTest, ParsesStrictly) {
  EXPECT_EQ(ParseDouble(" 1.5 "), 1.5);
  EXPECT_EQ(ParseDouble("+2e3"), 2000.0);
  EXPECT_FALSE(ParseDouble("1.5x").has_value());
  EXPECT_FALSE(ParseDouble("").has_value());
  EXPECT_FALSE(ParseDouble("nan").has_value());
  EXPECT_EQ(ParseInt("-12"), -12);
  EXPECT_FALSE(ParseInt("1.0").has_value());
}

TEST(StringsTest, SplitsTrimsJoins) {
  EXPECT_EQ(SplitTokens("  a b\t\tc\r\n"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(SplitTokens("1,2,,3", ","), (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_EQ(Trim("  x "), "x");
  EXPECT_EQ(ToLower("AbC"), "abc");
  EXPECT_TRUE(StartsWith("TILT=NONE", "TILT="));
  EXPECT_EQ(Join({"a", "b"}, ", "), "a, b");
}

}  // namespace
}  // namespace igi
