// The Python module's native part, `bifilar._core`: thin bindings over the same library calls the
// command line makes (pipeline/trace/trace_process.h, pipeline/campaign/campaign.h, fit/ellipse.h,
// pipeline/commands/simulate_spec.h). Records are built by the CLI's own JSON serializers
// (pipeline/records/results_json.h, pipeline/records/ellipse_json.h) and converted to Python dicts,
// so a field the CLI gains appears here with no change. The public, documented API is
// python/bifilar/__init__.py.
//
// Errors: bifilar::UserError (and std::invalid_argument) become ValueError with the message the
// CLI prints after "bifilar: error: "; nothing here aborts the interpreter. The GIL is released
// while the library works (fits, campaigns, simulation, file reading).
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

namespace py = pybind11;

namespace bifilar {
namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A C++ string as a str. Bytes that are not UTF-8 (a file name given as bytes, say) are kept
// as Python's os functions keep them (surrogateescape: os.fsencode gives the bytes back), never
// a UnicodeDecodeError after the work is done.
py::str Text(const std::string& s) {
  PyObject* text =
      PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), "surrogateescape");
  if (text == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(text);
}

py::list Texts(const std::vector<std::string>& v) {
  py::list list;
  for (const std::string& s : v) list.append(Text(s));
  return list;
}

// nlohmann::json -> dict / list / float / int / str / bool / None.
py::object ToPython(const nlohmann::json& j) {
  using Type = nlohmann::json::value_t;
  switch (j.type()) {
    case Type::null: return py::none();
    case Type::boolean: return py::bool_(j.get<bool>());
    case Type::number_integer: return py::int_(j.get<std::int64_t>());
    case Type::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case Type::number_float: return py::float_(j.get<double>());
    case Type::string: return Text(j.get_ref<const std::string&>());
    case Type::array: {
      py::list list;
      for (const nlohmann::json& item : j) list.append(ToPython(item));
      return std::move(list);
    }
    case Type::object: {
      py::dict dict;
      for (const auto& [key, value] : j.items()) dict[Text(key)] = ToPython(value);
      return std::move(dict);
    }
    default: return py::none();  // binary / discarded: never produced by the serializers
  }
}

py::array_t<double> ToNumpy(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

// N x 3 array of Eigen vectors.
py::array_t<double> ToNumpy(const std::vector<Eigen::Vector3d>& v) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  double* data = out.mutable_data();
  for (size_t i = 0; i < v.size(); ++i) {
    for (int k = 0; k < 3; ++k) data[3 * i + k] = v[i][k];
  }
  return out;
}

std::string Num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

// A one-dimensional series: `name` is the argument's name in messages.
std::vector<double> Series(const Array& array, const std::string& function,
                           const std::string& name) {
  if (array.ndim() != 1) {
    throw std::invalid_argument(function + ": " + name + " must be one-dimensional (it has " +
                                std::to_string(array.ndim()) + " dimensions)");
  }
  const double* data = array.data();
  std::vector<double> values(data, data + array.shape(0));
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument(function + ": " + name + "[" + std::to_string(i) + "] is " +
                                  Num(values[i]) + "; every value must be finite");
    }
  }
  return values;
}

void SameLength(const std::vector<double>& a, const std::vector<double>& b,
                const std::string& function, const std::string& name_a,
                const std::string& name_b) {
  if (a.size() != b.size()) {
    throw std::invalid_argument(function + ": " + name_a + " and " + name_b +
                                " have different lengths (" + std::to_string(a.size()) + " and " +
                                std::to_string(b.size()) + ")");
  }
}

void StrictlyIncreasing(const std::vector<double>& t, const std::string& function,
                        const std::string& name) {
  for (size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      throw std::invalid_argument(function + ": " + name + " must be strictly increasing; " +
                                  name + "[" + std::to_string(i) + "] = " + Num(t[i]) +
                                  " follows " + name + "[" + std::to_string(i - 1) +
                                  "] = " + Num(t[i - 1]));
    }
  }
}

CampaignConfig LoadFitConfig(const std::string& path) {
  ConfigLoadOptions load;
  load.require_runs = false;  // as `bifilar fit`: geometry, masses and IMU format suffice
  return LoadCampaignConfig(path, load);
}

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
    throw std::invalid_argument("fit_trace: model '" + *a.model +
                                "': expected full, jardin or linear");
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
  QualityThresholds& q = config.fit.quality;
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

// ---- read_log ----

// Without a config the format is the one `bifilar inspect` guesses
// (pipeline/commands/log_inspect.h), and the swing axis, window search and reading limits are the
// defaults of a config that gives only the format (as the config `bifilar init --log` writes).
py::dict ReadLogCore(const std::string& path, const std::optional<std::string>& config_path) {
  CampaignConfig config;
  std::optional<nlohmann::json> guessed_format;
  if (config_path) {
    config = LoadFitConfig(*config_path);
  } else {
    InspectReport report;
    {
      py::gil_scoped_release release;
      report = InspectLog(path, nullptr);
    }
    if (!report.is_log()) {
      throw UserError(report.error.empty() ? path + ": not a log bifilar recognises"
                                           : report.error);
    }
    config.imu.format = report.format;
    guessed_format = InspectReportToJson(report)["format"];
  }
  ImuData data;
  SwingAxis axis;
  std::optional<std::array<double, 2>> window;
  {
    py::gil_scoped_release release;
    data = ReadImuLog(path, config.imu.format, config.limits.LogOptions());
    // Step 2 of ProcessTrace (pipeline/trace/trace_process.cc): the swing axis with the config's
    // settings, over the config's window for this file when it has one (matched as
    // `bifilar fit` matches it, on the path as given).
    window = ConfigWindowFor(config, path);
    const SwingAxisOptions axis_options = SwingAxisOptionsFor(config.imu);
    std::optional<std::pair<double, double>> axis_window;
    if (window) axis_window = std::make_pair((*window)[0], (*window)[1]);
    std::string why;
    if (!EstimateSwingAxis(data, axis_options, axis_window, &axis, &why)) {
      throw UserError(why.rfind(path, 0) == 0 ? why : path + ": " + why);
    }
  }
  py::dict out;
  out["file"] = Text(path);
  out["t_s"] = ToNumpy(data.t_s);
  out["rate_rad_per_s"] = ToNumpy(axis.rate_rad_per_s);
  out["gyro_rad_per_s"] = ToNumpy(data.gyro_in_imu);
  out["accel_mps2"] = data.has_accel() ? py::object(ToNumpy(data.accel_in_imu)) : py::none();
  out["axis_in_imu"] = std::vector<double>{axis.axis_in_imu[0], axis.axis_in_imu[1],
                                           axis.axis_in_imu[2]};
  out["axis_in_body"] = std::vector<double>{axis.axis_in_body[0], axis.axis_in_body[1],
                                            axis.axis_in_body[2]};
  out["axis_source"] = ToString(axis.source);
  out["pitch_measured_deg"] =
      axis.pitch_measured_deg ? py::object(py::float_(*axis.pitch_measured_deg)) : py::none();
  out["roll_measured_deg"] = axis.pitch_measured_deg && axis.roll_measured_deg
                                 ? py::object(py::float_(*axis.roll_measured_deg))
                                 : py::none();
  out["window_s"] = window ? py::object(py::make_tuple((*window)[0], (*window)[1])) : py::none();
  out["warnings"] = Texts(data.warnings);
  out["notes"] = Texts(axis.notes);
  // The format used: the guess (its "guesses" say what was guessed from what), or None when the
  // config gave it.
  out["format_guessed"] = guessed_format ? ToPython(*guessed_format) : py::object(py::none());
  return out;
}

// ---- fit_ellipse ----

// The residuals of the ellipse fit as one numpy array per field of EllipseResidual (the keys of
// a residual in `bifilar ellipse --json`).
py::dict ResidualColumns(const std::vector<EllipseResidual>& residuals) {
  const auto n = static_cast<py::ssize_t>(residuals.size());
  py::array_t<std::int64_t> index(n);
  py::array_t<bool> outlier(n);
  py::array_t<double> pitch(n), inertia(n), fitted(n), residual(n), studentized(n);
  std::int64_t* index_data = index.mutable_data();
  bool* outlier_data = outlier.mutable_data();
  double* data[] = {pitch.mutable_data(), inertia.mutable_data(), fitted.mutable_data(),
                    residual.mutable_data(), studentized.mutable_data()};
  for (size_t i = 0; i < residuals.size(); ++i) {
    const EllipseResidual& e = residuals[i];
    index_data[i] = e.index;
    outlier_data[i] = e.outlier;
    data[0][i] = e.pitch_deg;
    data[1][i] = e.inertia_kg_m2;
    data[2][i] = e.fitted_kg_m2;
    data[3][i] = e.residual_kg_m2;
    data[4][i] = e.studentized;
  }
  py::dict columns;
  columns["index"] = index;
  columns["pitch_deg"] = pitch;
  columns["inertia_kg_m2"] = inertia;
  columns["fitted_kg_m2"] = fitted;
  columns["residual_kg_m2"] = residual;
  columns["studentized"] = studentized;
  columns["outlier"] = outlier;
  return columns;
}

py::object FitEllipseCore(const Array& pitch_array, const Array& inertia_array,
                          const std::optional<Array>& std_array, int bootstrap,
                          std::uint64_t seed, double confidence, const std::string& covariance) {
  const char* fn = "fit_ellipse";
  std::vector<EllipsePoint> points;
  {  // the checked copies of the arrays live only until the points are built
    const std::vector<double> pitch = Series(pitch_array, fn, "pitch_deg");
    const std::vector<double> inertia = Series(inertia_array, fn, "inertia");
    SameLength(pitch, inertia, fn, "pitch_deg", "inertia");
    std::vector<double> stds(pitch.size(), 0.0);
    if (std_array) {
      stds = Series(*std_array, fn, "std");
      SameLength(pitch, stds, fn, "pitch_deg", "std");
    }
    points.resize(pitch.size());
    for (size_t i = 0; i < points.size(); ++i) points[i] = {pitch[i], inertia[i], stds[i]};
  }
  EllipseOptions options;
  options.bootstrap_replicates = bootstrap;
  options.seed = seed;
  options.confidence = confidence;
  if (!ParseEllipseCovariance(covariance, &options.covariance)) {
    throw std::invalid_argument("fit_ellipse: covariance '" + covariance +
                                "': expected auto, points, angle_means or absolute");
  }
  EllipseResult result;
  std::string why;
  if (!options.Check(&why)) throw UserError("ellipse options: " + why);  // as `bifilar ellipse`
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = FitEllipse(points, options, &result, &why);
  }
  if (!ok) throw UserError(why);
  // The document without the per-point residuals, which come as numpy columns (~49 bytes a point)
  // instead: as JSON objects, then dicts, then Records they took ~2.7 kB a point (1e6 points:
  // 2.8 GB), where `bifilar ellipse` streams them. bifilar/__init__.py wraps the columns.
  py::dict document = ToPython(EllipseResultToJson(result, /*with_residuals=*/false));
  document["residuals"] = ResidualColumns(result.residuals);
  return std::move(document);
}

// ---- fit_tensor ----

// An (N, 3) array of axes, each finite; the function and argument named otherwise.
std::vector<std::array<double, 3>> Axes(const Array& array, const std::string& function,
                                        const std::string& name) {
  if (array.ndim() != 2 || array.shape(1) != 3) {
    throw std::invalid_argument(function + ": " + name +
                                " must have shape (N, 3): one body-axis vector per moment");
  }
  const double* data = array.data();
  std::vector<std::array<double, 3>> axes(array.shape(0));
  for (size_t i = 0; i < axes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      axes[i][k] = data[3 * i + k];
      if (!std::isfinite(axes[i][k])) {
        throw std::invalid_argument(function + ": " + name + "[" + std::to_string(i) + "] is not "
                                    "finite; every value must be finite");
      }
    }
  }
  return axes;
}

py::object FitTensorCore(const Array& direction_array, const Array& inertia_array,
                         const std::optional<Array>& std_array,
                         const std::optional<Array>& nominal_array,
                         const std::optional<std::vector<int>>& groups, int bootstrap,
                         std::uint64_t seed, double confidence, const std::string& covariance,
                         double common_offset_std, bool attitude_scatter) {
  const char* fn = "fit_tensor";
  const std::vector<std::array<double, 3>> directions = Axes(direction_array, fn, "directions");
  const std::vector<double> inertia = Series(inertia_array, fn, "inertias");
  if (directions.size() != inertia.size()) {
    throw std::invalid_argument(std::string(fn) + ": directions and inertias have different "
                                "lengths (" + std::to_string(directions.size()) + " and " +
                                std::to_string(inertia.size()) + ")");
  }
  std::vector<double> stds(inertia.size(), 0.0);
  if (std_array) {
    stds = Series(*std_array, fn, "stds");
    SameLength(inertia, stds, fn, "inertias", "stds");
  }
  std::vector<std::array<double, 3>> nominal;
  if (nominal_array) {
    nominal = Axes(*nominal_array, fn, "nominal");
    if (nominal.size() != inertia.size()) {
      throw std::invalid_argument(std::string(fn) + ": nominal and inertias have different lengths");
    }
  }
  if (groups && groups->size() != inertia.size()) {
    throw std::invalid_argument(std::string(fn) + ": groups and inertias have different lengths");
  }
  std::vector<TensorPoint> points(inertia.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].direction_in_body = directions[i];
    if (!nominal.empty()) points[i].nominal_in_body = nominal[i];
    points[i].inertia_kg_m2 = inertia[i];
    points[i].std_kg_m2 = stds[i];
    if (groups) points[i].group = (*groups)[i];
  }
  TensorOptions options;
  options.bootstrap_replicates = bootstrap;
  options.seed = seed;
  options.confidence = confidence;
  options.common_offset_std_kg_m2 = common_offset_std;
  options.attitude_scatter = attitude_scatter;
  if (!ParseEllipseCovariance(covariance, &options.covariance)) {
    throw std::invalid_argument("fit_tensor: covariance '" + covariance +
                                "': expected auto, points, angle_means or absolute");
  }
  std::string why;
  if (!options.Check(&why)) throw UserError("tensor options: " + why);
  TensorResult result;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = FitTensor(points, options, &result, &why);
  }
  if (!ok) throw UserError(why);
  TensorJsonContext context;
  context.mode = result.full ? "full_3d" : "partial";
  context.confidence = confidence;
  context.common_offset_std_kg_m2 = common_offset_std;
  return ToPython(TensorResultToJson(result, context));
}

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
      const CampaignConfig config = LoadCampaignConfig(config_path);
      CampaignOptions options;  // as `bifilar process`
      options.out_dir =
          out ? *out : (std::filesystem::path(config.folder) / "out").string();
      options.jobs = jobs.value_or(0);
      options.force = force;
      options.figures = figures;
      options.write_report = figures;
      options.progress = progress_bar ? &std::cerr : nullptr;
      options.progress_bar = progress_bar;
      options.cancel = &cancel;
      if (has_callback) {
        options.on_progress = [&](int done, int total, const std::string& line) {
          const std::lock_guard<std::mutex> lock(events_mutex);
          events.push_back({done, total, line});
        };
      }
      RunCampaign(config, options);
      // The file just written, so that the two can never differ.
      const std::string path = (std::filesystem::path(options.out_dir) / "results.json").string();
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

// ---- simulate ----

struct SimulateArgs {
  std::optional<std::string> spec, out, trace, truth, model;
  std::optional<std::uint64_t> seed;
  std::optional<double> inertia_kg_m2, mass_kg, length_m, separation_m, g, amplitude_deg,
      pitch_deg, duration_s, sample_rate_hz;
  bool no_accel = false;
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
  positive(a.duration_s, "duration_s");
  positive(a.sample_rate_hz, "sample_rate_hz");
  positive(a.inertia_kg_m2, "inertia_kg_m2");
  positive(a.mass_kg, "mass_kg");
  positive(a.length_m, "length_m");
  positive(a.separation_m, "separation_m");
  positive(a.g, "g");
  if (a.out && a.trace) throw std::invalid_argument("simulate: give either out= or trace=, not both");
  SimulateRunSummary summary;
  ImuData data;  // the single trace, read back from its file
  std::string truth_text;
  {
    py::gil_scoped_release release;
    SimulateSpec spec = a.spec ? ReadSimulateSpec(*a.spec) : ParseSimulateSpec("{}", "<defaults>");
    if (!a.spec) spec.file.clear();
    if (a.seed) spec.seed = *a.seed;
    if (a.model && !ParsePendulumModel(*a.model, &spec.options.model)) {
      throw std::invalid_argument("simulate: model '" + *a.model +
                                  "': expected full, jardin or linear");
    }
    if (a.sample_rate_hz) spec.options.sensor.sample_rate_hz = *a.sample_rate_hz;
    if (a.no_accel) spec.options.sensor.accelerometer = false;
    if (a.duration_s) spec.options.timeline.free_s = {*a.duration_s, *a.duration_s};
    std::string why;
    if (a.out) {  // a campaign
      if (!a.spec) throw std::invalid_argument("simulate: out= needs a campaign spec file");
      if (a.inertia_kg_m2 || a.mass_kg || a.amplitude_deg || a.pitch_deg || a.truth) {
        throw std::invalid_argument(
            "simulate: inertia_kg_m2, mass_kg, amplitude_deg, pitch_deg and truth apply to a "
            "single trace only; a campaign takes them from the spec");
      }
      if (a.length_m) spec.campaign.filar_length_m = *a.length_m;
      if (a.separation_m) spec.campaign.filar_separation_m = *a.separation_m;
      if (a.g) spec.campaign.gravity_mps2 = *a.g;
      if (!spec.campaign.Check(&why) || !spec.options.Check(&why)) throw UserError(why);
      summary = RunSimulateCampaign(spec, *a.out, a.force);
    } else {  // one trace, into trace= or in memory (a temporary file read back)
      if (spec.has_campaign) {
        throw std::invalid_argument(*a.spec + ": has campaign sections (aircraft, rig, "
                                    "campaign); simulate it with out=DIR");
      }
      TraceRequest& t = spec.trace;
      if (a.inertia_kg_m2) t.inertia_kg_m2 = *a.inertia_kg_m2;
      if (a.mass_kg) t.mass_kg = *a.mass_kg;
      if (a.length_m) t.filar_length_m = *a.length_m;
      if (a.separation_m) t.filar_separation_m = *a.separation_m;
      if (a.g) t.gravity_mps2 = *a.g;
      if (a.amplitude_deg) t.amplitude_deg = *a.amplitude_deg;
      if (a.pitch_deg) t.pitch_deg = *a.pitch_deg;
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
  if (kwargs.contains("name") && !kwargs["name"].is_none()) a.name = kwargs["name"].cast<std::string>();
  for (const auto& item : kwargs) {
    static const char* known[] = {"config", "length_m", "separation_m", "mass_kg", "g", "model",
                                  "window", "max_amplitude_deg", "min_amplitude_deg",
                                  "length_std_m", "separation_std_m", "mass_std_kg", "g_std",
                                  "gyro_scale_std", "max_rms_over_noise",
                                  "max_residual_autocorr", "whiteness_lags",
                                  "max_secondary_motion_ratio", "min_periods", "name"};
    const std::string key = py::str(item.first);
    if (std::find(std::begin(known), std::end(known), key) == std::end(known)) {
      throw py::type_error("fit_trace: unexpected keyword argument '" + key + "'");
    }
  }
  return a;
}

}  // namespace
}  // namespace bifilar

PYBIND11_MODULE(_core, m) {
  using namespace bifilar;
  m.doc() = "Native part of the bifilar Python module; use the functions of `bifilar` instead.";

  // Bad input from a user: ValueError with the CLI's message.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const UserError& e) {  // (a message naming a non-UTF-8 file name: surrogates)
      PyErr_SetObject(PyExc_ValueError, Text(e.what()).ptr());
    } catch (const std::invalid_argument& e) {
      PyErr_SetObject(PyExc_ValueError, Text(e.what()).ptr());
    }
  });

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
  m.def("read_log", &ReadLogCore, py::arg("path"), py::arg("config"),
        "read_log(path, config) -> dict: the log in SI units and its swing rate, as `bifilar fit` "
        "reads it with the YAML config (None: the format `bifilar inspect` guesses).");
  m.def("fit_ellipse", &FitEllipseCore, py::arg("pitch_deg"), py::arg("inertia"),
        py::arg("std"), py::arg("bootstrap"), py::arg("seed"), py::arg("confidence"),
        py::arg("covariance"),
        "fit_ellipse(pitch_deg, inertia, std, bootstrap, seed, confidence, covariance) -> dict: "
        "the `bifilar ellipse --json` document.");
  m.def("fit_tensor", &FitTensorCore, py::arg("directions"), py::arg("inertias"),
        py::arg("stds"), py::arg("nominal"), py::arg("groups"), py::arg("bootstrap"),
        py::arg("seed"), py::arg("confidence"), py::arg("covariance"),
        py::arg("common_offset_std"), py::arg("attitude_scatter"),
        "fit_tensor(directions, inertias, stds, nominal, groups, bootstrap, seed, confidence, "
        "covariance, common_offset_std, attitude_scatter) -> dict: the `tensor` section of "
        "results.json for these moments.");
  m.def("process", &ProcessCore, py::arg("config"), py::arg("out"), py::arg("jobs"),
        py::arg("force"), py::arg("figures"), py::arg("progress_bar"), py::arg("callback"),
        "process(config, out, jobs, force, figures, progress_bar, callback) -> dict: runs "
        "`bifilar process` and returns the parsed results.json; Ctrl-C raises KeyboardInterrupt.");
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
        get("seed", &a.seed);
        get("inertia_kg_m2", &a.inertia_kg_m2);
        get("mass_kg", &a.mass_kg);
        get("length_m", &a.length_m);
        get("separation_m", &a.separation_m);
        get("g", &a.g);
        get("amplitude_deg", &a.amplitude_deg);
        get("pitch_deg", &a.pitch_deg);
        get("duration_s", &a.duration_s);
        get("sample_rate_hz", &a.sample_rate_hz);
        if (kwargs.contains("no_accel")) a.no_accel = kwargs["no_accel"].cast<bool>();
        if (kwargs.contains("force")) a.force = kwargs["force"].cast<bool>();
        return SimulateCore(a);
      },
      "simulate(**settings) -> dict: `bifilar simulate`, a campaign (spec, out) or one trace "
      "(written to trace= or returned as arrays).");
  m.attr("version") = ProgramVersion();
  // The ranges of the whole-number arguments, from the constants the C++ checks use:
  // bifilar/__init__.py refuses a value outside them by name, before a cast to int could fail
  // ("Unable to cast Python instance of type <class 'int'> to C++ type").
  py::dict int_ranges;
  int_ranges["whiteness_lags"] = py::make_tuple(1, kMaxWhitenessLags);
  int_ranges["bootstrap"] = py::make_tuple(0, kMaxBootstrapReplicates);
  int_ranges["jobs"] = py::make_tuple(0, kMaxJobs);
  m.attr("int_ranges") = int_ranges;
}
