// `bifilar.fit_tensor`: the `tensor` section of results.json (fit/tensor.h).
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
        throw std::invalid_argument(function + ": " + name + "[" + std::to_string(i) +
                                    "] is not "
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
    throw std::invalid_argument(std::string(fn) +
                                ": directions and inertias have different "
                                "lengths (" +
                                std::to_string(directions.size()) + " and " +
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
      throw std::invalid_argument(std::string(fn) +
                                  ": nominal and inertias have different lengths");
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
    throw std::invalid_argument("fit_tensor: covariance '" + covariance + "': expected " +
                                EllipseCovarianceAllowedValues());
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

}  // namespace

void BindTensor(py::module_& m) {
  m.def("fit_tensor", &FitTensorCore, py::arg("directions"), py::arg("inertias"), py::arg("stds"),
        py::arg("nominal"), py::arg("groups"), py::arg("bootstrap"), py::arg("seed"),
        py::arg("confidence"), py::arg("covariance"), py::arg("common_offset_std"),
        py::arg("attitude_scatter"),
        "fit_tensor(directions, inertias, stds, nominal, groups, bootstrap, seed, confidence, "
        "covariance, common_offset_std, attitude_scatter) -> dict: the `tensor` section of "
        "results.json for these moments.");
}

}  // namespace python
}  // namespace bifilar
