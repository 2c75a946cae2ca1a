// igi's log (spdlog's default logger) routed to Python's logging, logger "igi": each message is
// handed to logging.getLogger("igi").log(level, text) with the GIL held. Long calls release the
// GIL, so messages from their worker threads reach Python while they run.
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <mutex>

#include "python/src/bindings.h"

namespace igi::python {
namespace {

class PythonLoggingSink final : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    if (!Py_IsInitialized()) return;
    const int level = msg.level >= spdlog::level::critical ? 50
                      : msg.level >= spdlog::level::err    ? 40
                      : msg.level >= spdlog::level::warn   ? 30
                      : msg.level >= spdlog::level::info   ? 20
                                                           : 10;
    const std::string text(msg.payload.data(), msg.payload.size());
    py::gil_scoped_acquire gil;
    try {
      py::module_::import("logging").attr("getLogger")("igi").attr("log")(level, text);
    } catch (const py::error_already_set&) {
      // A failing handler must not take the computation down; logging reports its own errors.
    }
  }
  void flush_() override {}
};

}  // namespace

void AddLogging(py::module_& m) {
  auto logger = std::make_shared<spdlog::logger>("igi", std::make_shared<PythonLoggingSink>());
  logger->set_level(spdlog::level::info);  // igi.set_log_level changes it
  spdlog::set_default_logger(logger);
  m.def(
      "_log",
      [](int level, const std::string& text) {
        spdlog::log(level >= 40 ? spdlog::level::err
                    : level >= 30 ? spdlog::level::warn
                    : level >= 20 ? spdlog::level::info
                                  : spdlog::level::debug,
                    text);
      },
      "Logs through igi's logger (for tests of the routing).");
  m.def(
      "_set_log_level",
      [](int level) {
        spdlog::set_level(level >= 40 ? spdlog::level::err
                          : level >= 30 ? spdlog::level::warn
                          : level >= 20 ? spdlog::level::info
                                        : spdlog::level::debug);
      },
      "The least level (Python's numbers) igi hands to logging.");
}

}  // namespace igi::python
