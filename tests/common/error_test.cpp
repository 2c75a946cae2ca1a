#include "tools/common/error.h"

#include <gtest/gtest.h>

namespace igi {
namespace {

TEST(ErrorTest, DescribeProblemJoinsNonEmptyParts) {
  EXPECT_EQ(DescribeProblem("scene.json", "lights.lamp.radius", "-1", "must be > 0"),
            "scene.json: lights.lamp.radius: -1: must be > 0");
  EXPECT_EQ(DescribeProblem("a.exr", "", "", "cannot read"), "a.exr: cannot read");
}

TEST(ErrorTest, InputErrorMapsToExitCodeTwoAndChainsContext) {
  try {
    try {
      throw InputError("x.json: key: 1: rule");
    } catch (Error& e) {
      throw e.AddContext("while loading the scene");
    }
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::kBadInput);
    ASSERT_EQ(e.Lines().size(), 1u);
    EXPECT_EQ(e.Lines()[0], "x.json: key: 1: rule (while loading the scene)");
    EXPECT_STREQ(e.what(), "x.json: key: 1: rule (while loading the scene)");
  }
}

TEST(ErrorTest, ProblemListThrowsAllProblems) {
  ProblemList problems;
  EXPECT_NO_THROW(problems.ThrowIfAny());
  problems.Add("f", "a", "1", "bad");
  problems.Add("f", "b", "2", "worse");
  try {
    problems.ThrowIfAny();
    FAIL() << "expected a throw";
  } catch (const InputError& e) {
    EXPECT_EQ(e.problems().size(), 2u);
    EXPECT_EQ(e.problems()[1], "f: b: 2: worse");
  }
}

TEST(ErrorTest, PartialErrorExitCodeThree) {
  EXPECT_EQ(PartialError("some failed").code(), ExitCode::kPartial);
  EXPECT_EQ(Error("boom").code(), ExitCode::kFailed);
}

}  // namespace
}  // namespace igi
