#include "calib/response_curve.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "tools/common/error.h"

namespace igi::calib {
namespace {

TEST(ResponseCurve, LinearAndInterpolation) {
  const ResponseCurve linear = LinearResponse(256, 3);
  EXPECT_EQ(linear.channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_NEAR(linear.LnExposure(1, 1.0), 0.0, 1e-12);
  EXPECT_NEAR(linear.LnExposure(0, 128.0 / 255), std::log(128.0 / 255), 1e-12);
  // Halfway between levels 10 and 11: the mean of their g.
  EXPECT_NEAR(linear.LnExposure(2, 10.5 / 255), 0.5 * (std::log(10.0 / 255) + std::log(11.0 / 255)),
              1e-12);
}

TEST(ResponseCurve, JsonRoundTripKeepsTheContractKeys) {
  ResponseCurve curve = LinearResponse(16, 1);
  curve.method = "debevec";
  const auto path = std::filesystem::temp_directory_path() / "igi_response_test.json";
  Json info;
  info["lambda"] = 10;
  WriteResponseJson(path, curve, info);
  const Json doc = ReadJsonFile(path);
  EXPECT_EQ(doc["format"], "igi-response");
  EXPECT_EQ(doc["version"], 1);
  EXPECT_EQ(doc["levels"], 16);
  EXPECT_EQ(doc["g"].size(), 1u);
  const ResponseCurve back = ReadResponseJson(path);
  EXPECT_EQ(back.method, "debevec");
  ASSERT_EQ(back.g.size(), 1u);
  for (int z = 0; z < 16; ++z) EXPECT_NEAR(back.g[0][size_t(z)], curve.g[0][size_t(z)], 1e-6);
  std::filesystem::remove(path);
}

std::string ErrorOf(const std::string& text) {
  try {
    ResponseFromJson(ParseJson(text, "r.json"), "r.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ResponseCurve, StrictReader) {
  const std::string head =
      R"({"format":"igi-response","version":1,"method":"debevec","levels":3,"channels":["Y"],)";
  EXPECT_EQ(ErrorOf(head + R"("g":[[-1,0,1]]})"), "");
  EXPECT_NE(ErrorOf(head + R"("g":[[-1,0]]})").find("g[0]"), std::string::npos);
  EXPECT_NE(ErrorOf(head + R"("g":[[0,-1,1]]})").find("must not decrease"), std::string::npos);
  EXPECT_NE(ErrorOf(head + R"("g":[[-1,0,1]],"extra":1})").find("extra"), std::string::npos);
  EXPECT_NE(ErrorOf(head + R"("g":[[-1,0,1],[0,1,2]]})").find("one curve per channel"),
            std::string::npos);
}

}  // namespace
}  // namespace igi::calib
