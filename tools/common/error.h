#pragma once
// Errors of igi and how executables map them to exit codes.
//
// Bad input is the user's data, not a bug: libraries throw igi::InputError naming the file, the
// key path or pixel, the value and the rule broken; the executable's main prints one line per
// problem and exits with 2. Context is chained as the error travels up ("while loading X").
//
// Exit codes (docs/ARCHITECTURE.md): 0 ok, 1 failed, 2 bad usage or bad input (nothing written),
// 3 partial (some items failed and are listed; the rest is written).

#include <stdexcept>
#include <string>
#include <vector>

namespace igi {

enum class ExitCode : int { kOk = 0, kFailed = 1, kBadInput = 2, kPartial = 3 };

// Base error: a list of problems (usually one) plus an exit code and a context chain.
class Error : public std::runtime_error {
 public:
  explicit Error(std::string message, ExitCode code = ExitCode::kFailed);
  Error(std::vector<std::string> problems, ExitCode code);

  ExitCode code() const { return code_; }
  // Each problem is one self-contained line: "file: key: value: rule".
  const std::vector<std::string>& problems() const { return problems_; }
  // Context added by callers, innermost first ("while merging bracket 3").
  const std::vector<std::string>& context() const { return context_; }
  // Adds a context line and returns *this, so `catch (Error& e) { throw e.AddContext(..); }`.
  Error& AddContext(std::string context);
  // The whole error as lines: every problem, with the context appended after " (" ... ")".
  std::vector<std::string> Lines() const;

 private:
  void Rebuild();
  std::vector<std::string> problems_;
  std::vector<std::string> context_;
  ExitCode code_;
  std::string what_;

 public:
  const char* what() const noexcept override { return what_.c_str(); }
};

// The user's data breaks a rule: exit code 2, nothing written.
class InputError : public Error {
 public:
  explicit InputError(std::string message) : Error(std::move(message), ExitCode::kBadInput) {}
  explicit InputError(std::vector<std::string> problems)
      : Error(std::move(problems), ExitCode::kBadInput) {}
};

// Some items failed and are listed; the rest was written: exit code 3.
class PartialError : public Error {
 public:
  explicit PartialError(std::string message) : Error(std::move(message), ExitCode::kPartial) {}
  explicit PartialError(std::vector<std::string> problems)
      : Error(std::move(problems), ExitCode::kPartial) {}
};

// Formats the canonical one-line description of a bad value:
//   "FILE: KEY: VALUE: RULE"   (empty parts are left out).
std::string DescribeProblem(const std::string& file, const std::string& key,
                            const std::string& value, const std::string& rule);

// Collects every problem found while validating, so that loading reports all of them, not just
// the first. ThrowIfAny() throws one InputError carrying them all.
class ProblemList {
 public:
  void Add(std::string problem) { problems_.push_back(std::move(problem)); }
  void Add(const std::string& file, const std::string& key, const std::string& value,
           const std::string& rule) {
    Add(DescribeProblem(file, key, value, rule));
  }
  void Append(const Error& error);
  bool empty() const { return problems_.empty(); }
  size_t size() const { return problems_.size(); }
  const std::vector<std::string>& problems() const { return problems_; }
  void ThrowIfAny() const;

 private:
  std::vector<std::string> problems_;
};

}  // namespace igi
