// igi-info on the mini scene, the shared scenes and every broken scene of the corpus:
// exit 0 with a summary, or exit 2 with exactly one stderr line naming file, key and rule.
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/e2e/run.h"
#include "tests/recon/corpus.h"

namespace igi {
namespace {

using test::Quote;
using test::RunTool;

TEST(InfoE2E, ValidScenesExitZeroWithSummary) {
  const std::string mini = std::string(IGI_SOURCE_DIR) + "/tests/data/scenes/mini/scene.json";
  auto r = RunTool("igi-info", Quote(mini));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("material box"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lighting L1"), std::string::npos) << r.out;
  for (const char* s : {"/reference/radiance_room/scene.json", "/real/diligent_ball/scene.json"}) {
    auto shared = RunTool("igi-info", Quote(std::string(IGI_SHARED_DATA_DIR) + s));
    EXPECT_EQ(shared.exit_code, 0) << s << ": " << shared.err;
  }
}

TEST(InfoE2E, UsageErrorsExitTwo) {
  EXPECT_EQ(RunTool("igi-info", "").exit_code, 2);
  EXPECT_EQ(RunTool("igi-info", "--no-such-flag x.json").exit_code, 2);
  EXPECT_EQ(RunTool("igi-info", "/nonexistent/scene.json").exit_code, 2);
  auto help = RunTool("igi-info", "--help");
  EXPECT_EQ(help.exit_code, 0);
  auto version = RunTool("igi-info", "--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("igi-info"), std::string::npos);
}

class InfoCorpusE2E : public ::testing::TestWithParam<CorpusCase> {};

TEST_P(InfoCorpusE2E, ExitsTwoWithOneLineNamingFileAndKey) {
  const CorpusCase& c = GetParam();
  auto r = RunTool("igi-info", Quote(c.path.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(c.path.filename().string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(c.key), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(c.rule), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(Corpus, InfoCorpusE2E, ::testing::ValuesIn(ReadCorpus()),
                         [](const auto& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace igi
