// The corpus of broken scene files (tests/data/scenes/broken): each must fail to load with
// exactly one problem line that names the file, the key path and the rule (EXPECTED.tsv).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "recon/scene.h"
#include "tests/recon/corpus.h"

namespace igi::recon {
namespace {

class BrokenSceneTest : public ::testing::TestWithParam<CorpusCase> {};

TEST_P(BrokenSceneTest, LoadReportsOneLineNamingFileKeyAndRule) {
  const CorpusCase& c = GetParam();
  try {
    LoadScene(c.path);
    FAIL() << c.path << " loaded without error";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u) << e.what();
    const std::string& line = e.problems()[0];
    EXPECT_NE(line.find(c.path.filename().string()), std::string::npos) << line;
    EXPECT_NE(line.find(c.key), std::string::npos) << line;
    EXPECT_NE(line.find(c.rule), std::string::npos) << line;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BrokenSceneTest, ::testing::ValuesIn(ReadCorpus()),
                         [](const auto& param_info) { return param_info.param.name; });

TEST(BrokenSceneCorpus, HasAtLeast25Cases) { EXPECT_GE(ReadCorpus().size(), 25u); }

}  // namespace
}  // namespace igi::recon
