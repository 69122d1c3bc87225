// `bifilar.read_log`: a log in SI units and its swing rate, as `bifilar fit` reads it.
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
    data = ReadImuLog(path, config.imu.format, config.LogOptions());
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
  out["axis_in_imu"] =
      std::vector<double>{axis.axis_in_imu[0], axis.axis_in_imu[1], axis.axis_in_imu[2]};
  out["axis_in_body"] =
      std::vector<double>{axis.axis_in_body[0], axis.axis_in_body[1], axis.axis_in_body[2]};
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

}  // namespace

void BindLogs(py::module_& m) {
  m.def("read_log", &ReadLogCore, py::arg("path"), py::arg("config"),
        "read_log(path, config) -> dict: the log in SI units and its swing rate, as `bifilar fit` "
        "reads it with the YAML config (None: the format `bifilar inspect` guesses).");
}

}  // namespace python
}  // namespace bifilar
