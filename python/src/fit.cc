// `bifilar.fit_trace` and `time_fit_trace`: the trace processing of `bifilar fit` on a swing-rate
// series (pipeline/trace/trace_process.h).
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
#include "pendulum/model.h"
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

// ---- fit_trace ----

struct FitTraceArgs {
  std::optional<std::string> config;
  std::optional<double> length_m, separation_m, mass_kg, g;
  std::optional<std::string> model;
  py::object window;  // None, (t0, t1) or "T0:T1"
  std::optional<double> max_amplitude_deg, min_amplitude_deg;
  std::optional<double> length_std_m, separation_std_m, mass_std_kg, g_std, gyro_scale_std;
  std::optional<double> max_rms_over_noise, max_residual_autocorr, max_secondary_motion_ratio,
      min_periods;
  std::optional<int> whiteness_lags;
  std::string name = "trace";
};

// The campaign config `bifilar fit` would use, from a YAML file and/or the keyword arguments.
CampaignConfig FitTraceConfig(const FitTraceArgs& a) {
  CampaignConfig config;
  if (a.config) {
    config = LoadFitConfig(*a.config);
  } else if (!a.length_m || !a.separation_m || !a.mass_kg) {
    throw std::invalid_argument(
        "fit_trace: give length_m, separation_m and mass_kg (or config=, a YAML config)");
  }
  if (a.length_m) config.filar_length_m = *a.length_m;
  if (a.separation_m) config.filar_separation_m = *a.separation_m;
  if (a.mass_kg) {  // the whole suspended mass
    config.rig_mass_kg = *a.mass_kg;
    config.aircraft_mass_kg = 0.0;
    config.aircraft_mass_std_kg = 0.0;
  }
  if (a.g) config.gravity_mps2 = *a.g;
  if (a.model && !ParsePendulumModel(*a.model, &config.fit.model)) {
    throw std::invalid_argument("fit_trace: model '" + *a.model + "': expected " +
                                PendulumModelAllowedValues());
  }
  if (a.max_amplitude_deg) config.fit.max_amplitude_deg = *a.max_amplitude_deg;
  if (a.min_amplitude_deg) config.fit.min_amplitude_deg = *a.min_amplitude_deg;
  RigUncertainties& u = config.uncertainties;
  if (a.length_std_m) u.filar_length_std_m = *a.length_std_m;
  if (a.separation_std_m) u.filar_separation_std_m = *a.separation_std_m;
  if (a.mass_std_kg) u.mass_std_kg = *a.mass_std_kg;
  if (a.g_std) u.gravity_std_mps2 = *a.g_std;
  // Any std given replaces the assumed +-1 mm on L and D, as a rig.uncertainties section does.
  if (a.length_std_m || a.separation_std_m || a.mass_std_kg || a.g_std) u.configured = true;
  if (a.gyro_scale_std) config.imu.gyro_scale_std = *a.gyro_scale_std;
  TraceQualityOptions& q = config.fit.quality;
  if (a.max_rms_over_noise) q.max_rms_over_noise = *a.max_rms_over_noise;
  if (a.max_residual_autocorr) q.max_residual_autocorr = *a.max_residual_autocorr;
  if (a.whiteness_lags) q.whiteness_lags = *a.whiteness_lags;
  if (a.max_secondary_motion_ratio) q.max_secondary_motion_ratio = *a.max_secondary_motion_ratio;
  if (a.min_periods) q.min_periods = *a.min_periods;
  // The rate given is already the swing rate: it is the z gyro of a log whose swing axis is z.
  config.imu.swing_axis_auto = false;
  config.imu.swing_axis_in_imu = Eigen::Vector3d::UnitZ();
  config.imu.imu_to_body = Eigen::Matrix3d::Identity();
  std::string why;
  if (!config.AircraftGeometry().Check(&why)) throw std::invalid_argument("fit_trace: " + why);
  if (!config.Check(&why)) throw std::invalid_argument("fit_trace: " + why);
  return config;
}

std::optional<std::array<double, 2>> WindowArgument(const py::object& window) {
  if (window.is_none()) return std::nullopt;
  double t0 = 0, t1 = 0;
  std::string why;
  if (py::isinstance<py::str>(window)) {
    if (!ParseWindowSpec(window.cast<std::string>(), &t0, &t1, &why)) {
      throw std::invalid_argument("fit_trace: window: " + why);
    }
    return std::array<double, 2>{t0, t1};
  }
  std::vector<double> pair;
  try {
    pair = window.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw std::invalid_argument("fit_trace: window must be None, (t0, t1) in seconds or 'T0:T1'");
  }
  if (pair.size() != 2 || !std::isfinite(pair[0]) || !std::isfinite(pair[1]) ||
      !(pair[1] > pair[0])) {
    throw std::invalid_argument(
        "fit_trace: window must be (t0, t1) with finite t1 > t0 (seconds, the trace's own time)");
  }
  return std::array<double, 2>{pair[0], pair[1]};
}

// Returns (record dict, t, measured, fitted, residual); raises ValueError for an `error` record.
py::tuple FitTraceCore(const Array& t_array, const Array& rate_array, const FitTraceArgs& args) {
  const char* fn = "fit_trace";
  std::vector<double> t = Series(t_array, fn, "t");
  std::vector<double> rate = Series(rate_array, fn, "rate");
  SameLength(t, rate, fn, "t", "rate");
  StrictlyIncreasing(t, fn, "t");
  const CampaignConfig config = FitTraceConfig(args);
  TraceProcessOptions options;
  options.window_s = WindowArgument(args.window);
  options.display_name = args.name;

  TraceRecord record;
  TraceFitResult fit;
  ImuData data;
  data.t_s = std::move(t);
  data.gyro_in_imu.resize(rate.size());
  for (size_t i = 0; i < rate.size(); ++i) data.gyro_in_imu[i] = Eigen::Vector3d(0, 0, rate[i]);
  // The fit runs on a thread of its own while this (the caller's) thread waits, checking for
  // Ctrl-C every 20 ms: KeyboardInterrupt then stops the fit between solver iterations
  // (TraceFitOptions::interrupt) and is raised as soon as the fit has stopped.
  std::atomic<bool> interrupt{false};
  options.interrupt = &interrupt;
  std::mutex mutex;
  std::condition_variable cv;
  bool finished = false;
  std::exception_ptr error;  // ProcessTraceData never throws, but memory may run out
  std::thread worker([&] {
    try {
      record = ProcessTraceData(config, data, args.name, options, &fit);
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(mutex);
    finished = true;
    cv.notify_one();
  });
  bool interrupted = false;
  while (true) {
    bool done = false;
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(mutex);
      done = cv.wait_for(lock, std::chrono::milliseconds(20), [&] { return finished; });
    }
    if (done) break;
    if (!interrupted && PyErr_CheckSignals() != 0) {  // the exception stays set until raised
      interrupted = true;
      interrupt = true;
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  if (interrupted) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
  if (record.status == TraceStatus::kError) throw UserError(record.message);
  return py::make_tuple(ToPython(TraceRecordToJson(record, false)), ToNumpy(fit.t_s),
                        ToNumpy(fit.measured_rate_rad_per_s), ToNumpy(fit.fitted_rate_rad_per_s),
                        ToNumpy(fit.residual_rad_per_s));
}

// C++ wall time of the call fit_trace makes, repeated in C++ without Python in the loop: the
// reference for examples/bench_fit_trace.py. Returns the seconds of each repeat.
std::vector<double> TimeFitTraceCore(const Array& t_array, const Array& rate_array,
                                     const FitTraceArgs& args, int repeats) {
  const std::vector<double> t = Series(t_array, "time_fit_trace", "t");
  const std::vector<double> rate = Series(rate_array, "time_fit_trace", "rate");
  SameLength(t, rate, "time_fit_trace", "t", "rate");
  const CampaignConfig config = FitTraceConfig(args);
  TraceProcessOptions options;
  options.window_s = WindowArgument(args.window);
  options.display_name = args.name;
  std::vector<double> seconds;
  py::gil_scoped_release release;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    ImuData data;
    data.t_s = t;
    data.gyro_in_imu.resize(rate.size());
    for (size_t i = 0; i < rate.size(); ++i) data.gyro_in_imu[i] = Eigen::Vector3d(0, 0, rate[i]);
    TraceFitResult fit;
    const TraceRecord record = ProcessTraceData(config, data, args.name, options, &fit);
    const nlohmann::json json = TraceRecordToJson(record, false);
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return seconds;
}

FitTraceArgs MakeFitTraceArgs(py::kwargs kwargs) {
  FitTraceArgs a;
  auto get = [&](const char* key, auto* target) {
    if (kwargs.contains(key) && !kwargs[key].is_none()) {
      *target = kwargs[key].cast<typename std::decay_t<decltype(*target)>::value_type>();
    }
  };
  get("config", &a.config);
  get("length_m", &a.length_m);
  get("separation_m", &a.separation_m);
  get("mass_kg", &a.mass_kg);
  get("g", &a.g);
  get("model", &a.model);
  a.window = kwargs.contains("window") ? py::object(kwargs["window"]) : py::none();
  get("max_amplitude_deg", &a.max_amplitude_deg);
  get("min_amplitude_deg", &a.min_amplitude_deg);
  get("length_std_m", &a.length_std_m);
  get("separation_std_m", &a.separation_std_m);
  get("mass_std_kg", &a.mass_std_kg);
  get("g_std", &a.g_std);
  get("gyro_scale_std", &a.gyro_scale_std);
  get("max_rms_over_noise", &a.max_rms_over_noise);
  get("max_residual_autocorr", &a.max_residual_autocorr);
  get("whiteness_lags", &a.whiteness_lags);
  get("max_secondary_motion_ratio", &a.max_secondary_motion_ratio);
  get("min_periods", &a.min_periods);
  if (kwargs.contains("name") && !kwargs["name"].is_none())
    a.name = kwargs["name"].cast<std::string>();
  for (const auto& item : kwargs) {
    static const char* known[] = {"config",
                                  "length_m",
                                  "separation_m",
                                  "mass_kg",
                                  "g",
                                  "model",
                                  "window",
                                  "max_amplitude_deg",
                                  "min_amplitude_deg",
                                  "length_std_m",
                                  "separation_std_m",
                                  "mass_std_kg",
                                  "g_std",
                                  "gyro_scale_std",
                                  "max_rms_over_noise",
                                  "max_residual_autocorr",
                                  "whiteness_lags",
                                  "max_secondary_motion_ratio",
                                  "min_periods",
                                  "name"};
    const std::string key = py::str(item.first);
    if (std::find(std::begin(known), std::end(known), key) == std::end(known)) {
      throw py::type_error("fit_trace: unexpected keyword argument '" + key + "'");
    }
  }
  return a;
}

}  // namespace

void BindFit(py::module_& m) {
  m.def(
      "fit_trace",
      [](const Array& t, const Array& rate, py::kwargs kwargs) {
        return FitTraceCore(t, rate, MakeFitTraceArgs(kwargs));
      },
      py::arg("t"), py::arg("rate"),
      "fit_trace(t, rate, **settings) -> (record dict, t_s, measured, fitted, residual). "
      "Window, amplitude band and fit of `bifilar fit` on a swing-rate series; raises ValueError "
      "on bad input or an `error` record.");
  m.def(
      "time_fit_trace",
      [](const Array& t, const Array& rate, int repeats, py::kwargs kwargs) {
        return TimeFitTraceCore(t, rate, MakeFitTraceArgs(kwargs), repeats);
      },
      py::arg("t"), py::arg("rate"), py::arg("repeats"),
      "time_fit_trace(t, rate, repeats, **settings) -> [seconds]: the C++ wall time of the work "
      "fit_trace does (processing + JSON record), repeated in C++ (benchmark reference).");
}

}  // namespace python
}  // namespace bifilar
