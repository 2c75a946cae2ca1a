#pragma once
// The broken-scene corpus (tests/data/scenes/broken/EXPECTED.tsv), shared by the library test
// and the executables' end-to-end test.
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

namespace igi {

struct CorpusCase {
  std::string name;  // test name (file stem)
  std::filesystem::path path;
  std::string key;   // the key path the error must name
  std::string rule;  // a phrase of the rule the error must state
};

inline std::vector<CorpusCase> ReadCorpus() {
  const std::filesystem::path dir =
      std::filesystem::path(IGI_SOURCE_DIR) / "tests/data/scenes/broken";
  std::ifstream in(dir / "EXPECTED.tsv");
  std::vector<CorpusCase> cases;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t a = line.find('\t'), b = line.find('\t', a + 1);
    CorpusCase c;
    c.path = dir / line.substr(0, a);
    c.name = c.path.stem().string();
    c.key = line.substr(a + 1, b - a - 1);
    c.rule = line.substr(b + 1);
    cases.push_back(c);
  }
  return cases;
}

}  // namespace igi

namespace igi {
// Prints a case by name in test listings (instead of its bytes).
inline void PrintTo(const CorpusCase& c, std::ostream* os) { *os << c.name; }
}  // namespace igi
