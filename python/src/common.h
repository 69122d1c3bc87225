// Shared by the files of the Python module `bifilar._core` (python/src/): conversions between
// C++ values and Python objects, argument checks, and the Bind... function of each file, which
// module.cc calls. Everything here is a thin layer over the library calls the CLI makes.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pipeline/config/config.h"

namespace py = pybind11;

namespace bifilar {
namespace python {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A C++ string as a str. Bytes that are not UTF-8 (a file name given as bytes, say) are kept
// as Python's os functions keep them (surrogateescape: os.fsencode gives the bytes back), never
// a UnicodeDecodeError after the work is done.
py::str Text(const std::string& s);
py::list Texts(const std::vector<std::string>& v);
// nlohmann::json -> dict / list / float / int / str / bool / None.
py::object ToPython(const nlohmann::json& j);
py::array_t<double> ToNumpy(const std::vector<double>& v);
// N x 3 array of Eigen vectors.
py::array_t<double> ToNumpy(const std::vector<Eigen::Vector3d>& v);
std::string Num(double value);
// A one-dimensional series: `name` is the argument's name in messages.
std::vector<double> Series(const Array& array, const std::string& function,
                           const std::string& name);
void SameLength(const std::vector<double>& a, const std::vector<double>& b,
                const std::string& function, const std::string& name_a, const std::string& name_b);
void StrictlyIncreasing(const std::vector<double>& t, const std::string& function,
                        const std::string& name);
// A config as `bifilar fit` loads it: geometry, masses and IMU format suffice.
CampaignConfig LoadFitConfig(const std::string& path);

// The functions of each file (python/src/<file>.cc), added to the module.
void BindFit(py::module_& m);       // fit_trace, time_fit_trace
void BindLogs(py::module_& m);      // read_log
void BindEllipse(py::module_& m);   // fit_ellipse
void BindTensor(py::module_& m);    // fit_tensor
void BindCampaign(py::module_& m);  // process
void BindSimulate(py::module_& m);  // simulate
void BindWatch(py::module_& m);     // watch (python/src/watch.cc)

}  // namespace python
}  // namespace bifilar
