#include "tools/common/json.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace igi {
namespace {

struct Parsed {
  Json doc;
  ProblemList problems;
};

TEST(JsonTest, ReadsTypedValuesWithoutProblems) {
  Json doc = ParseJson(R"({"a": 1.5, "n": 3, "s": "x", "v": [1, 2, 3], "g": 0.5, "b": true})", "t");
  ProblemList problems;
  auto root = JsonCursor::Root(doc, "t.json", &problems);
  EXPECT_TRUE(root.ExpectObject({"a", "n", "s", "v", "g", "b"}));
  EXPECT_DOUBLE_EQ(*root["a"].Number(), 1.5);
  EXPECT_EQ(*root["n"].Integer(), 3);
  EXPECT_EQ(*root["s"].String(), "x");
  EXPECT_EQ(*root["v"].Vec3(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(*root["g"].Rgb(), Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_TRUE(*root["b"].Bool());
  EXPECT_TRUE(problems.empty());
}

TEST(JsonTest, EveryProblemNamesFileKeyPathValueAndRule) {
  Json doc = ParseJson(
      R"({"lights": {"lamp": {"intensity": [1, 2, -3], "radius": "big", "colour": 1}}})", "t");
  ProblemList problems;
  auto root = JsonCursor::Root(doc, "scene.json", &problems);
  auto lamp = root["lights"]["lamp"];
  lamp.ExpectObject({"intensity", "radius"});
  lamp["intensity"].Rgb(NumberRule::NonNegative());
  lamp["radius"].Number(NumberRule::Positive());
  lamp["position"].Vec3();
  ASSERT_EQ(problems.size(), 4u);
  EXPECT_EQ(problems.problems()[0],
            "scene.json: lights.lamp.colour: 1: unknown key (allowed: intensity, radius)");
  EXPECT_EQ(problems.problems()[1], "scene.json: lights.lamp.intensity[2]: -3: must be >= 0");
  EXPECT_EQ(problems.problems()[2], "scene.json: lights.lamp.radius: \"big\": must be a number");
  EXPECT_EQ(problems.problems()[3], "scene.json: lights.lamp.position: missing required key");
}

TEST(JsonTest, RejectsNonFiniteAndOutOfRange) {
  // JSON has no NaN or infinity; an overflowing literal is a syntax-level error.
  EXPECT_THROW(ParseJson(R"({"x": 1e999})", "t"), InputError);
  Json doc = ParseJson(R"({"x": -0.5, "y": 2.0, "d": [0, 0, 0]})", "t");
  ProblemList problems;
  auto root = JsonCursor::Root(doc, "f", &problems);
  EXPECT_FALSE(root["x"].Number(NumberRule::NonNegative()).has_value());
  EXPECT_FALSE(root["y"].Number(NumberRule::Between(0, 1)).has_value());
  EXPECT_FALSE(root["d"].Direction().has_value());
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems.problems()[1].find("must be in [0, 1]"), std::string::npos);
  EXPECT_NE(problems.problems()[2].find("non-zero direction"), std::string::npos);
}

TEST(JsonTest, NullCountsAsAbsent) {
  Json doc = ParseJson(R"({"mask": null})", "t");
  ProblemList problems;
  auto root = JsonCursor::Root(doc, "f", &problems);
  EXPECT_FALSE(root["mask"].present());
  EXPECT_FALSE(root["other"].present());
  EXPECT_TRUE(problems.empty());
}

TEST(JsonTest, SyntaxErrorNamesLineAndColumn) {
  try {
    ParseJson("{\n  \"a\": 1,\n  \"b\": NaN\n}", "scene.json");
    FAIL();
  } catch (const InputError& e) {
    const std::string line = e.Lines().at(0);
    EXPECT_NE(line.find("scene.json"), std::string::npos) << line;
    EXPECT_NE(line.find("line 3"), std::string::npos) << line;
  }
}

TEST(JsonTest, KeysKeepFileOrderWhenWrittenBack) {
  auto dir = std::filesystem::temp_directory_path() / "igi_json_test";
  std::filesystem::create_directories(dir);
  Json doc = ParseJson(R"({"zeta": 1, "alpha": 2})", "t");
  WriteJsonFile(dir / "o.json", doc, -1);
  EXPECT_EQ(ReadJsonFile(dir / "o.json").dump(), R"({"zeta":1,"alpha":2})");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace igi
