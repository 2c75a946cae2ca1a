// report.html of igi-solve (TEMPORARY plain version until tools/common/html_report lands).
#include <fmt/format.h>

#include "solver/solve.h"
#include "tools/common/atomic_file.h"

namespace igi {

void WriteSolveReportHtml(const SolveSummary& s, const Json& report,
                          const std::filesystem::path& path) {
  std::string html = "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>igi-solve report</title></head><body>";
  html += "<h1>igi-solve report</h1><pre>" + report.dump(1) + "</pre>";
  html += fmt::format("<p>{} regions</p></body></html>", s.regions.size());
  WriteFileAtomic(path, html);
}

}  // namespace igi
