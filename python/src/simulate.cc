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

// The same checks and merging as `bifilar simulate` (pipeline/cli/cli_simulate.cc), with the
// keyword names in the messages.
py::dict SimulateCore(const SimulateArgs& a) {
  auto positive = [](const std::optional<double>& v, const char* name) {
    if (v && !(*v > 0)) {
      throw std::invalid_argument("simulate: " + std::string(name) + " = " + Num(*v) +
                                  " is out of range; allowed > 0");
    }
  };
  const SimulateOverrides& o = a.o;
  positive(o.duration_s, "duration_s");
  positive(a.sample_rate_hz, "sample_rate_hz");
  positive(o.inertia_kg_m2, "inertia_kg_m2");
  positive(o.mass_kg, "mass_kg");
  positive(o.length_m, "length_m");
  positive(o.separation_m, "separation_m");
  positive(o.gravity_mps2, "g");
  if (a.out && a.trace) throw std::invalid_argument("simulate: give either out= or trace=, not both");
  SimulateRunSummary summary;
  ImuData data;  // the single trace, read back from its file
  std::string truth_text;
  {
    py::gil_scoped_release release;
    SimulateSpec spec = a.spec ? ReadSimulateSpec(*a.spec) : ParseSimulateSpec("{}", "<defaults>");
    if (!a.spec) spec.file.clear();
    if (a.model && !ParsePendulumModel(*a.model, &spec.options.model)) {
      throw std::invalid_argument("simulate: model '" + *a.model +
                                  "': expected full, jardin or linear");
    }
    if (a.sample_rate_hz) spec.options.sensor.sample_rate_hz = *a.sample_rate_hz;
    std::string why;
    if (a.out) {  // a campaign
      if (!a.spec) throw std::invalid_argument("simulate: out= needs a campaign spec file");
      if (o.inertia_kg_m2 || o.mass_kg || o.amplitude_deg || o.pitch_deg || a.truth) {
        throw std::invalid_argument(
            "simulate: inertia_kg_m2, mass_kg, amplitude_deg, pitch_deg and truth apply to a "
            "single trace only; a campaign takes them from the spec");
      }
      ApplySimulateOverrides(o, false, &spec);
      if (!spec.campaign.Check(&why) || !spec.options.Check(&why)) throw UserError(why);
      summary = RunSimulateCampaign(spec, *a.out, a.force);
    } else {  // one trace, into trace= or in memory (a temporary file read back)
      if (spec.has_campaign) {
        throw std::invalid_argument(*a.spec + ": has campaign sections (aircraft, rig, "
                                    "campaign); simulate it with out=DIR");
      }
      ApplySimulateOverrides(o, true, &spec);
      const TraceRequest& t = spec.trace;
      for (auto [value, name] : {std::make_pair(&t.inertia_kg_m2, "inertia_kg_m2"),
                                 std::make_pair(&t.mass_kg, "mass_kg"),
                                 std::make_pair(&t.filar_length_m, "length_m"),
                                 std::make_pair(&t.filar_separation_m, "separation_m")}) {
        if (!*value) {
          throw std::invalid_argument(std::string("simulate: give ") + name +
                                      " (or its spec key) for a single trace");
        }
      }
      if (!spec.options.Check(&why)) throw UserError(why);
      std::filesystem::path temp;
      std::string csv = a.trace.value_or("");
      if (csv.empty()) {
        std::random_device device;
        temp = std::filesystem::temp_directory_path() /
               ("bifilar_py_" + std::to_string(device()) + "_" + std::to_string(device()));
        std::filesystem::create_directories(temp);
        csv = (temp / "trace.csv").string();
      }
      try {
        summary = RunSimulateTrace(spec, csv, a.truth.value_or(""), a.force);
        data = ReadImuLog(csv, spec.format);
      } catch (...) {
        if (!temp.empty()) std::filesystem::remove_all(temp);
        throw;
      }
      truth_text = ReadText(summary.truth_path);
      if (!temp.empty()) {
        std::filesystem::remove_all(temp);
        summary.truth_path.clear();
      }
    }
    if (truth_text.empty()) truth_text = ReadText(summary.truth_path);
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
  result["truth_path"] = summary.truth_path.empty() ? py::object(py::none())
                                                    : py::object(Text(summary.truth_path));
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
            *target =
                kwargs[key].cast<typename std::decay_t<decltype(*target)>::value_type>();
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
