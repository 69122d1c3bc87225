// `bifilar.fit_ellipse`: the `bifilar ellipse --json` document (fit/ellipse.h).
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
                          const std::optional<Array>& std_array, int bootstrap, std::uint64_t seed,
                          double confidence, const std::string& covariance) {
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
    throw std::invalid_argument("fit_ellipse: covariance '" + covariance + "': expected " +
                                EllipseCovarianceAllowedValues());
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

}  // namespace

void BindEllipse(py::module_& m) {
  m.def("fit_ellipse", &FitEllipseCore, py::arg("pitch_deg"), py::arg("inertia"), py::arg("std"),
        py::arg("bootstrap"), py::arg("seed"), py::arg("confidence"), py::arg("covariance"),
        "fit_ellipse(pitch_deg, inertia, std, bootstrap, seed, confidence, covariance) -> dict: "
        "the `bifilar ellipse --json` document.");
}

}  // namespace python
}  // namespace bifilar
