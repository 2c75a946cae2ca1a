#pragma once
// Small string helpers used by the readers (trimming, splitting, strict number parsing).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace igi {

std::string_view Trim(std::string_view s);
std::string ToLower(std::string_view s);
bool StartsWith(std::string_view s, std::string_view prefix);
// Splits on any of `separators`, dropping empty pieces.
std::vector<std::string> SplitTokens(std::string_view s, std::string_view separators = " \t\r\n");
// Parses the whole of `s` as a finite double / integer (no trailing garbage); nullopt otherwise.
std::optional<double> ParseDouble(std::string_view s);
std::optional<long long> ParseInt(std::string_view s);
// Joins `parts` with `separator`.
std::string Join(const std::vector<std::string>& parts, std::string_view separator);

}  // namespace igi
