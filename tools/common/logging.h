#pragma once
// Logging for igi: spdlog to stderr (never stdout, which belongs to the executables' output).
// Libraries log through spdlog's default logger; executables call InitLogging once.

#include <spdlog/spdlog.h>

namespace igi {

enum class LogLevel { kQuiet, kWarn, kInfo, kDebug };

// Sends the default logger to stderr with a short "[igi-name] level: message" pattern.
void InitLogging(const std::string& program, LogLevel level);

}  // namespace igi
