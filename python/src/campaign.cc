// `bifilar.process`: `bifilar process` (pipeline/campaign/campaign.h), results.json as a dict.
#include "python/src/common.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/bounded_read.h"
#include "base/user_error.h"
#include "base/version.h"
#include "fit/ellipse.h"
#include "fit/swing_axis.h"
#include "fit/tensor.h"
#include "fit/trace_fit.h"
#include "fit/window.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/log_inspect.h"
#include "pipeline/commands/process_command.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/records/ellipse_json.h"
#include "pipeline/records/results_json.h"
#include "pipeline/records/tensor_json.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace python {
namespace {

// ---- process ----

// Runs the campaign on a thread of its own while the calling (Python main) thread polls every
// 50 ms: Ctrl-C (PyErr_CheckSignals) sets the campaign's cancel flag, so process() raises
// KeyboardInterrupt as soon as the fits running have finished, and `progress`, a Python
// callable, is called on this thread with (done, total, line) for every fit.
py::object ProcessCore(const std::string& config_path, const std::optional<std::string>& out,
                       std::optional<int> jobs, bool force, bool figures, bool progress_bar,
                       py::object progress_callback) {
  std::atomic<bool> cancel{false};
  std::atomic<bool> finished{false};
  std::exception_ptr error;
  nlohmann::json results;
  struct Event {
    int done, total;
    std::string line;
  };
  std::mutex events_mutex;
  std::vector<Event> events;
  const bool has_callback = !progress_callback.is_none();
  std::thread worker([&] {
    try {
      ProcessCommandOptions options;  // as `bifilar process`
      options.config_path = config_path;
      options.out_dir = out;
      options.campaign.jobs = jobs.value_or(0);
      options.campaign.force = force;
      options.campaign.figures = figures;
      options.campaign.write_report = figures;
      options.campaign.progress = progress_bar ? &std::cerr : nullptr;
      options.campaign.progress_bar = progress_bar;
      options.campaign.cancel = &cancel;
      if (has_callback) {
        options.campaign.on_progress = [&](int done, int total, const std::string& line) {
          const std::lock_guard<std::mutex> lock(events_mutex);
          events.push_back({done, total, line});
        };
      }
      const ProcessCommandResult run = RunProcess(options);
      // The file just written, so that the two can never differ.
      const std::string path = (std::filesystem::path(run.out_dir) / "results.json").string();
      results = nlohmann::json::parse(ReadRegularFileOrThrow(path, OutputFileCap()));
    } catch (...) {
      error = std::current_exception();
    }
    finished = true;
  });
  std::optional<py::error_already_set> pending;  // KeyboardInterrupt, or the callback's error
  while (true) {
    const bool done = finished.load();
    {
      py::gil_scoped_release release;
      if (!done) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::vector<Event> batch;
    {
      const std::lock_guard<std::mutex> lock(events_mutex);
      batch.swap(events);
    }
    for (const Event& e : batch) {
      if (pending) break;
      try {
        progress_callback(e.done, e.total, e.line);
      } catch (py::error_already_set& callback_error) {
        pending.emplace(std::move(callback_error));
        cancel = true;
      }
    }
    if (!pending && PyErr_CheckSignals() != 0) {
      pending.emplace();  // fetches the KeyboardInterrupt PyErr_CheckSignals raised
      cancel = true;
    }
    if (done) break;
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (pending) throw *pending;
  if (error) std::rethrow_exception(error);
  return ToPython(results);
}

}  // namespace

void BindCampaign(py::module_& m) {
  m.def("process", &ProcessCore, py::arg("config"), py::arg("out"), py::arg("jobs"),
        py::arg("force"), py::arg("figures"), py::arg("progress_bar"), py::arg("callback"),
        "process(config, out, jobs, force, figures, progress_bar, callback) -> dict: runs "
        "`bifilar process` and returns the parsed results.json; Ctrl-C raises KeyboardInterrupt.");
}

}  // namespace python
}  // namespace bifilar
