// `bifilar.simulate`: `bifilar simulate` (pipeline/commands/simulate_spec.h), a campaign or one
// trace.
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

// ---- simulate ----

struct SimulateArgs {
  std::optional<std::string> spec, out, trace, truth, model;
  SimulateOverrides o;  // the keywords `bifilar simulate` has as flags (ApplySimulateOverrides)
  std::optional<double> sample_rate_hz;
  bool force = false;  // replace files that exist (as `bifilar simulate --force`)
};

// A file simulate just wrote (truth.json), read back within the result-file cap.
std::string ReadText(const std::string& path) {
  return ReadRegularFileOrThrow(path, OutputFileCap());
}

// Python's keywords for the settings, in the messages of RunSimulate.
SimulateSettingNames PythonNames() {
  SimulateSettingNames n;
  n.duration = "duration_s";
  n.sample_rate = "sample_rate_hz";
  n.inertia = "inertia_kg_m2";
  n.mass = "mass_kg";
  n.length = "length_m";
  n.separation = "separation_m";
  n.gravity = "g";
  n.amplitude = "amplitude_deg";
  n.pitch = "pitch_deg";
  n.truth = "truth=";
  n.model = "model=";
  n.trace = "trace=";
  n.out = "out=";
  return n;
}

// `bifilar simulate` through its entry point (RunSimulate: the same checks and merging, with
// the keyword names in the messages). Without trace= or out=, the trace goes to a temporary
// file that is read back and removed.
py::dict SimulateCore(const SimulateArgs& a) {
  SimulateCommandOptions options;
  options.spec_file = a.spec.value_or("");
  options.out_dir = a.out.value_or("");
  options.trace_csv = a.trace.value_or("");
  options.truth_json = a.truth.value_or("");
  options.model = a.model.value_or("");
  options.o = a.o;
  options.sample_rate = a.sample_rate_hz;
  options.force = a.force;
  options.names = PythonNames();
  if (a.out && a.out->empty()) throw std::invalid_argument("simulate: out= is empty");
  if (a.trace && a.trace->empty()) throw std::invalid_argument("simulate: trace= is empty");
  SimulateRunSummary summary;
  ImuData data;  // the single trace, read back from its file
  std::string truth_text;
  {
    py::gil_scoped_release release;
    std::filesystem::path temp;
    if (!a.out && !a.trace) {  // in memory: a temporary file, read back
      std::random_device device;
      temp = std::filesystem::temp_directory_path() /
             ("bifilar_py_" + std::to_string(device()) + "_" + std::to_string(device()));
      std::filesystem::create_directories(temp);
      options.trace_csv = (temp / "trace.csv").string();
    }
    try {
      const SimulateCommandResult run = RunSimulate(options);
      summary = run.summary;
      if (!a.out) data = ReadImuLog(options.trace_csv, run.format);
      truth_text = ReadText(summary.truth_path);
    } catch (...) {
      if (!temp.empty()) std::filesystem::remove_all(temp);
      throw;
    }
    if (!temp.empty()) {
      std::filesystem::remove_all(temp);
      summary.truth_path.clear();
    }
  }
  py::dict result;
  result["samples_written"] = summary.samples_written;
  result["samples_dropped"] = summary.samples_dropped;
  nlohmann::json truth = nlohmann::json::parse(truth_text);
  if (!a.out && !a.trace) {  // the temporary file is gone
    for (nlohmann::json& trace : truth["traces"]) trace["file"] = nullptr;
  }
  result["truth"] = ToPython(truth);
  if (a.out) {
    result["files_written"] = summary.files_written;
    result["out"] = Text(*a.out);
  } else {
    result["t_s"] = ToNumpy(data.t_s);
    result["gyro_rad_per_s"] = ToNumpy(data.gyro_in_imu);
    result["accel_mps2"] = data.has_accel() ? py::object(ToNumpy(data.accel_in_imu)) : py::none();
    if (a.trace) result["file"] = Text(*a.trace);
  }
  result["truth_path"] =
      summary.truth_path.empty() ? py::object(py::none()) : py::object(Text(summary.truth_path));
  return result;
}

}  // namespace

void BindSimulate(py::module_& m) {
  m.def(
      "simulate",
      [](py::kwargs kwargs) {
        SimulateArgs a;
        auto get = [&](const char* key, auto* target) {
          if (kwargs.contains(key) && !kwargs[key].is_none()) {
            *target = kwargs[key].cast<typename std::decay_t<decltype(*target)>::value_type>();
          }
        };
        get("spec", &a.spec);
        get("out", &a.out);
        get("trace", &a.trace);
        get("truth", &a.truth);
        get("model", &a.model);
        get("seed", &a.o.seed);
        get("inertia_kg_m2", &a.o.inertia_kg_m2);
        get("mass_kg", &a.o.mass_kg);
        get("length_m", &a.o.length_m);
        get("separation_m", &a.o.separation_m);
        get("g", &a.o.gravity_mps2);
        get("amplitude_deg", &a.o.amplitude_deg);
        get("pitch_deg", &a.o.pitch_deg);
        get("duration_s", &a.o.duration_s);
        get("sample_rate_hz", &a.sample_rate_hz);
        if (kwargs.contains("no_accel")) a.o.no_accel = kwargs["no_accel"].cast<bool>();
        if (kwargs.contains("force")) a.force = kwargs["force"].cast<bool>();
        return SimulateCore(a);
      },
      "simulate(**settings) -> dict: `bifilar simulate`, a campaign (spec, out) or one trace "
      "(written to trace= or returned as arrays).");
}

}  // namespace python
}  // namespace bifilar
