// Conversions and argument checks shared by the Python module's files (python/src/common.h).
#include "python/src/common.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

namespace bifilar {
namespace python {

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
    case Type::null:
      return py::none();
    case Type::boolean:
      return py::bool_(j.get<bool>());
    case Type::number_integer:
      return py::int_(j.get<std::int64_t>());
    case Type::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case Type::number_float:
      return py::float_(j.get<double>());
    case Type::string:
      return Text(j.get_ref<const std::string&>());
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
    default:
      return py::none();  // binary / discarded: never produced by the serializers
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
                const std::string& function, const std::string& name_a, const std::string& name_b) {
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
      throw std::invalid_argument(function + ": " + name + " must be strictly increasing; " + name +
                                  "[" + std::to_string(i) + "] = " + Num(t[i]) + " follows " +
                                  name + "[" + std::to_string(i - 1) + "] = " + Num(t[i - 1]));
    }
  }
}

CampaignConfig LoadFitConfig(const std::string& path) {
  ConfigLoadOptions load;
  load.require_runs = false;  // as `bifilar fit`: geometry, masses and IMU format suffice
  return LoadCampaignConfig(path, load);
}

}  // namespace python
}  // namespace bifilar
