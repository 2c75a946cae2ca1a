// The executables' jobs from Python: solve, diagnose, export, synthesize and run, each taking its
// executable's flags (parsed by the same definitions: solver/inverse/solve_flags.h and the like)
// and returning its JSON report as text; and the progress observer and cancellation that the
// pure-Python layer connects to a callback and to Ctrl-C. The GIL is released while a job runs.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "python/src/bindings.h"
#include "recon/scene.h"
#include "solver/diagnose/diagnose.h"
#include "solver/diagnose/diagnose_flags.h"
#include "solver/export/export.h"
#include "solver/export/export_flags.h"
#include "solver/inverse/solve.h"
#include "solver/inverse/solve_flags.h"
#include "solver/synth/synth_flags.h"
#include "solver/synth/synthesize.h"
#include "tools/common/cli.h"
#include "tools/common/error.h"
#include "tools/common/progress.h"
#include "tools/pipeline/run_flags.h"

namespace igi::python {
namespace {

namespace fs = std::filesystem;
using ScenePtr = std::shared_ptr<recon::Scene>;

// Every option of `app` as (flag, default as text, description): the Python layer's help.
std::vector<std::tuple<std::string, std::string, std::string>> Options(const CLI::App& app) {
  std::vector<std::tuple<std::string, std::string, std::string>> options;
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_lnames().empty()) continue;
    options.emplace_back("--" + option->get_lnames().front(), option->get_default_str(),
                         option->get_description());
  }
  return options;
}

// The exception the progress callback raised, kept until the Python layer takes it (the
// callback's error stops the job through cancellation and is raised in its place).
std::mutex g_callback_error_mutex;
std::shared_ptr<py::error_already_set> g_callback_error;

}  // namespace

void AddJobs(py::module_& m) {
  m.def(
      "_solve",
      [](const ScenePtr& scene, const std::string& out, const std::vector<std::string>& args,
         int threads) {
        CLI::App app;
        solver::SolveFlags flags;
        solver::AddSolveFlags(app, &flags);
        ParseArguments(app, "igi-solve", args);
        const solver::SolveOptions options = solver::FinishSolveFlags(flags, threads, false);
        RejectOutputInSceneFolder(out, scene->file.string());
        py::gil_scoped_release release;
        const solver::SolveSummary summary = solver::Solve(*scene, options, out);
        solver::WriteSolveOutputs(summary, options, out);
        return solver::SolveReportJson(summary, options).dump();
      },
      py::arg("scene"), py::arg("out"), py::arg("args"), py::arg("threads") = 0,
      "igi-solve: writes OUT (scene.json, albedo/, report.json, report.html); returns "
      "report.json's text.");
  m.def(
      "_diagnose",
      [](const ScenePtr& scene, const std::string& out, const std::vector<std::string>& args,
         int threads) {
        CLI::App app;
        diagnose::DiagnoseOptions parsed;
        diagnose::AddDiagnoseFlags(app, &parsed);
        ParseArguments(app, "igi-diagnose", args);
        const diagnose::DiagnoseOptions options =
            diagnose::FinishDiagnoseFlags(parsed, threads, false);
        RejectOutputInSceneFolder(out, scene->file.string());
        if (scene->photos.empty()) {
          throw InputError(DescribeProblem(scene->file.string(), "photos", "[]",
                                           "needs at least one photo to compare with"));
        }
        py::gil_scoped_release release;
        const diagnose::DiagnosisSummary summary = diagnose::Diagnose(*scene, options, out);
        diagnose::WriteDiagnosisOutputs(summary, options, out);
        return diagnose::DiagnosisJson(summary, options).dump();
      },
      py::arg("scene"), py::arg("out"), py::arg("args"), py::arg("threads") = 0,
      "igi-diagnose: writes OUT (diagnosis.json, scene.json, report.html); returns "
      "diagnosis.json's text.");
  m.def(
      "_export",
      [](const ScenePtr& scene, const std::string& out, const std::vector<std::string>& args) {
        CLI::App app;
        exporter::ExportFlags flags;
        exporter::AddExportFlags(app, &flags);
        ParseArguments(app, "igi-export", args);
        const exporter::ExportOptions options = exporter::FinishExportFlags(flags);
        exporter::CheckExportDir(out);
        exporter::CheckExportableScene(*scene);
        py::gil_scoped_release release;
        return exporter::ExportScene(*scene, out, options).ToJson().dump();
      },
      py::arg("scene"), py::arg("out"), py::arg("args"),
      "igi-export: writes OUT; returns export_report.json's text.");
  m.def(
      "_synthesize",
      [](const std::vector<std::string>& args, int threads) {
        CLI::App app;
        synth::SynthFlags flags;
        synth::AddSynthFlags(app, &flags);
        ParseArguments(app, "igi-synth", args);
        const synth::SynthOptions options = synth::FinishSynthFlags(flags, threads);
        synth::SynthSummary s;
        {
          py::gil_scoped_release release;
          s = synth::Synthesize(options);
        }
        py::dict summary;
        summary["out"] = fs::path(options.out).string();
        summary["photos"] = s.photos;
        summary["validation"] = s.validation;
        summary["saturated_pixels"] = s.saturated_pixels;
        summary["render_seconds"] = s.render_seconds;
        summary["seconds"] = s.seconds;
        return summary;
      },
      py::arg("args"), py::arg("threads") = 0,
      "igi-synth: writes the capture to --out; returns its summary.");
  m.def(
      "_run",
      [](const std::string& photos, const std::string& out, const std::vector<std::string>& args,
         int threads) {
        CLI::App app;
        pipeline::RunFlags flags;
        pipeline::AddRunFlags(app, &flags);
        ParseArguments(app, "igi-run", args);
        pipeline::RunResult r;
        {
          py::gil_scoped_release release;
          r = pipeline::RunFromFlags(flags, photos, out, threads);
        }
        Json summary = pipeline::RunSummaryJson(r.run);
        if (r.demo) summary["demo_summary"] = r.demo_summary;
        return summary.dump();
      },
      py::arg("photos"), py::arg("out"), py::arg("args"), py::arg("threads") = 0,
      "igi-run: the chain into OUT; returns its summary as JSON text.");
  m.def(
      "_options",
      [](const std::string& program) {
        CLI::App app;
        if (program == "igi-solve") {
          static solver::SolveFlags f;
          solver::AddSolveFlags(app, &f);
        } else if (program == "igi-diagnose") {
          static diagnose::DiagnoseOptions f;
          diagnose::AddDiagnoseFlags(app, &f);
        } else if (program == "igi-export") {
          static exporter::ExportFlags f;
          exporter::AddExportFlags(app, &f);
        } else if (program == "igi-synth") {
          static synth::SynthFlags f;
          synth::AddSynthFlags(app, &f);
        } else if (program == "igi-run") {
          static pipeline::RunFlags f;
          pipeline::AddRunFlags(app, &f);
        } else {
          throw InputError(DescribeProblem("", "program", program, "has no options here"));
        }
        return Options(app);
      },
      py::arg("program"), "The options of a job: (flag, default, description).");

  m.def(
      "_set_progress",
      [](const std::optional<py::function>& callback) {
        if (!callback) {
          SetProgressObserver(nullptr);
          return;
        }
        // Copies of the observer may end on a worker thread: the callback is released with the
        // GIL held.
        std::shared_ptr<py::function> held(new py::function(*callback), [](py::function* f) {
          if (!Py_IsInitialized()) return;
          py::gil_scoped_acquire gil;
          delete f;
        });
        SetProgressObserver([held](const std::string& label, int64_t done, int64_t total) {
          if (!Py_IsInitialized()) return;
          py::gil_scoped_acquire gil;
          try {
            (*held)(label, done, total);
          } catch (py::error_already_set& e) {
            std::lock_guard<std::mutex> lock(g_callback_error_mutex);
            if (!g_callback_error) g_callback_error = std::make_shared<py::error_already_set>(e);
            RequestCancel();
          }
        });
      },
      py::arg("callback"),
      "Calls callback(label, done, total) as long work advances; None removes it.");
  m.def(
      "_take_progress_error",
      []() -> py::object {
        std::lock_guard<std::mutex> lock(g_callback_error_mutex);
        if (!g_callback_error) return py::none();
        py::object value = g_callback_error->value();
        g_callback_error.reset();
        return value;
      },
      "The exception the progress callback raised (None if none), cleared.");
  m.def("_request_cancel", &RequestCancel, "Stops the running job at its next unit of work.");
  m.def("_clear_cancel", &ClearCancel, "Lets jobs run again after a cancellation.");
}

}  // namespace igi::python
