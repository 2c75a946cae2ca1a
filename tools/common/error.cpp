#include "tools/common/error.h"

#include <utility>

namespace igi {

Error::Error(std::string message, ExitCode code)
    : std::runtime_error(message), problems_{std::move(message)}, code_(code) {
  Rebuild();
}

Error::Error(std::vector<std::string> problems, ExitCode code)
    : std::runtime_error(problems.empty() ? std::string("error") : problems.front()),
      problems_(std::move(problems)),
      code_(code) {
  if (problems_.empty()) problems_.push_back("unspecified error");
  Rebuild();
}

Error& Error::AddContext(std::string context) {
  context_.push_back(std::move(context));
  Rebuild();
  return *this;
}

std::vector<std::string> Error::Lines() const {
  std::string suffix;
  for (const std::string& c : context_) suffix += " (" + c + ")";
  std::vector<std::string> lines;
  lines.reserve(problems_.size());
  for (const std::string& p : problems_) lines.push_back(p + suffix);
  return lines;
}

void Error::Rebuild() {
  what_.clear();
  for (const std::string& line : Lines()) {
    if (!what_.empty()) what_ += '\n';
    what_ += line;
  }
}

std::string DescribeProblem(const std::string& file, const std::string& key,
                            const std::string& value, const std::string& rule) {
  std::string out;
  auto append = [&out](const std::string& part) {
    if (part.empty()) return;
    if (!out.empty()) out += ": ";
    out += part;
  };
  append(file);
  append(key);
  append(value);
  append(rule);
  return out;
}

void ProblemList::Append(const Error& error) {
  for (const std::string& line : error.Lines()) problems_.push_back(line);
}

void ProblemList::ThrowIfAny() const {
  if (!problems_.empty()) throw InputError(problems_);
}

}  // namespace igi
