#include "pipeline/records/tensor_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/json_number.h"
#include "fit/physical.h"

namespace bifilar {
namespace {

using nlohmann::json;

json Vector3(const std::array<double, 3>& v) {
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return nullptr;
  return json::array({v[0], v[1], v[2]});
}

void PutEstimate(json* j, const std::string& key, const TensorEstimate& e) {
  const bool ok = e.observable && std::isfinite(e.value);
  (*j)[key] = ok ? JsonNumber(e.value) : json(nullptr);
  (*j)[key + "_std"] = ok ? JsonNumber(e.std) : json(nullptr);
  (*j)[key + "_ci95"] =
      ok ? json::array({JsonNumber(e.ci_lo), JsonNumber(e.ci_hi)}) : json(nullptr);
}

json ComponentsOrder() {
  json order = json::array();
  for (int k = 0; k < kTensorComponents; ++k) order.push_back(TensorComponentName(k));
  return order;
}

const char* kConvention =
    "body axes x forward, y right wing, z down; products positive (Ixy = integral x y dm, Ixz = "
    "integral x z dm, Iyz = integral y z dm); tensor_kg_m2 = [[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, "
    "-Iyz], [-Ixz, -Iyz, Izz]]; swing axis n = (-sin pitch, sin roll cos pitch, cos roll cos "
    "pitch), I(n) = n^T tensor n (docs/physics.md 3.5)";

void PutCommon(const TensorJsonContext& c, json* j) {
  (*j)["mode"] = c.mode;
  (*j)["convention"] = kConvention;
  (*j)["components_order"] = ComponentsOrder();
  (*j)["confidence"] = c.confidence;
  (*j)["rig_common_offset_std_kg_m2"] = JsonNumber(c.common_offset_std_kg_m2);
  (*j)["systematic_relative_std"] = JsonNumber(c.systematic_relative_std);
}

// The components, which are observable, and their covariance.
void PutComponents(const TensorResult& r, json* j) {
  for (int k = 0; k < kTensorComponents; ++k) {
    PutEstimate(j, std::string(TensorComponentName(k)) + "_kg_m2", r.components[k]);
  }
  json observable = json::object();
  for (int k = 0; k < kTensorComponents; ++k) {
    observable[TensorComponentName(k)] = r.components[k].observable;
  }
  (*j)["observable"] = observable;
  (*j)["unobservable"] = r.unobservable;
  (*j)["observable_combinations"] = r.observable_combinations;
  json cov = json::array();
  for (int k = 0; k < kTensorComponents; ++k) {
    json row = json::array();
    for (int l = 0; l < kTensorComponents; ++l) row.push_back(JsonNumber(r.covariance[k][l]));
    cov.push_back(row);
  }
  (*j)["covariance_kg2_m4"] = cov;
}

// The tensor matrix, principal moments, axes and angles; null when the fit is not full.
void PutPrincipal(const TensorResult& r, json* j) {
  if (r.full) {
    const auto& v = r.components;
    (*j)["tensor_kg_m2"] =
        json::array({json::array({v[kIxx].value, -v[kIxy].value, -v[kIxz].value}),
                     json::array({-v[kIxy].value, v[kIyy].value, -v[kIyz].value}),
                     json::array({-v[kIxz].value, -v[kIyz].value, v[kIzz].value})});
    json moments = json::array(), stds = json::array(), cis = json::array(), axes = json::array(),
         axes_std = json::array();
    for (int k = 0; k < 3; ++k) {
      moments.push_back(JsonNumber(r.principal_moments[k].value));
      stds.push_back(JsonNumber(r.principal_moments[k].std));
      cis.push_back(json::array(
          {JsonNumber(r.principal_moments[k].ci_lo), JsonNumber(r.principal_moments[k].ci_hi)}));
      axes.push_back(Vector3(r.principal_axes[k]));
      axes_std.push_back(JsonNumber(r.principal_axes_std_deg[k]));
    }
    (*j)["principal_moments_kg_m2"] = moments;
    (*j)["principal_moments_kg_m2_std"] = stds;
    (*j)["principal_moments_kg_m2_ci95"] = cis;
    (*j)["principal_axes"] = axes;
    (*j)["principal_axes_std_deg"] = axes_std;
    (*j)["principal_euler_deg"] = {{"roll", JsonNumber(r.euler_deg[0].value)},
                                   {"pitch", JsonNumber(r.euler_deg[1].value)},
                                   {"yaw", JsonNumber(r.euler_deg[2].value)},
                                   {"roll_std", JsonNumber(r.euler_deg[0].std)},
                                   {"pitch_std", JsonNumber(r.euler_deg[1].std)},
                                   {"yaw_std", JsonNumber(r.euler_deg[2].std)},
                                   {"convention",
                                    "body_from_principal = Rz(yaw) Ry(pitch) Rx(roll), each "
                                    "principal axis matched to the nearest body axis"}};
    const auto& matched = r.principal_moments_matched_kg_m2;
    (*j)["principal_moments_matched_kg_m2"] = {{"x", JsonNumber(matched[0])},
                                               {"y", JsonNumber(matched[1])},
                                               {"z", JsonNumber(matched[2])}};
  } else {
    (*j)["tensor_kg_m2"] = nullptr;
    (*j)["principal_moments_kg_m2"] = nullptr;
    (*j)["principal_moments_kg_m2_std"] = nullptr;
    (*j)["principal_moments_kg_m2_ci95"] = nullptr;
    (*j)["principal_axes"] = nullptr;
    (*j)["principal_axes_std_deg"] = nullptr;
    (*j)["principal_euler_deg"] = nullptr;
    (*j)["principal_moments_matched_kg_m2"] = nullptr;
  }
}

// The design (rank, condition, singular values, counts) and the scatter model of the fit.
void PutDesignAndScatter(const TensorResult& r, json* j) {
  (*j)["rank"] = r.rank;
  (*j)["condition_number"] = JsonNumber(r.condition_number);
  json sv = json::array();
  for (double s : r.design_singular_values) sv.push_back(JsonNumber(s));
  (*j)["design_singular_values"] = sv;
  (*j)["n_points"] = r.n_points;
  (*j)["n_orientations"] = r.n_orientations;
  (*j)["weighted"] = r.weighted;
  (*j)["attitude_scatter_deg"] = JsonNumber(r.attitude_scatter_deg);
  (*j)["relative_scatter"] = JsonNumber(r.relative_scatter);
  (*j)["covariance"] = EllipseCovarianceName(r.covariance_used);
  (*j)["variance_factor"] = JsonNumber(r.variance_factor);
  (*j)["dof"] = JsonNumber(r.dof);
  (*j)["reduced_chi2"] = JsonNumber(r.reduced_chi2);
  (*j)["rmse_kg_m2"] = JsonNumber(r.rmse_kg_m2);
  (*j)["bootstrap_replicates"] = r.bootstrap_replicates;
}

// One entry per point: measured, fitted, residual, with its file and attitude when known.
json ResidualsJson(const TensorResult& r, const TensorJsonContext& c) {
  json residuals = json::array();
  for (const TensorPointResidual& p : r.residuals) {
    json e = {{"index", p.index},
              {"orientation", p.orientation},
              {"inertia_kg_m2", JsonNumber(p.inertia_kg_m2)},
              {"fitted_kg_m2", JsonNumber(p.fitted_kg_m2)},
              {"residual_kg_m2", JsonNumber(p.residual_kg_m2)},
              {"studentized", JsonNumber(p.studentized)},
              {"outlier", p.outlier}};
    if (p.index < static_cast<int>(c.points.size())) {
      const TensorJsonContext::Point& q = c.points[p.index];
      e["file"] = q.file;
      e["roll_deg"] = JsonNumber(q.roll_deg);
      e["pitch_deg"] = JsonNumber(q.pitch_deg);
    }
    residuals.push_back(e);
  }
  return residuals;
}

// One entry per orientation group: axis, mean, fit, residual, with its attitude when known.
json OrientationsJson(const TensorResult& r, const TensorJsonContext& c) {
  json orientations = json::array();
  for (size_t g = 0; g < r.orientations.size(); ++g) {
    const TensorOrientation& o = r.orientations[g];
    json e = {{"axis_in_body", Vector3(o.nominal_in_body)},
              {"n", static_cast<int>(o.members.size())},
              {"mean_kg_m2", JsonNumber(o.mean_kg_m2)},
              {"fitted_kg_m2", JsonNumber(o.fitted_kg_m2)},
              {"residual_kg_m2", JsonNumber(o.residual_kg_m2)},
              {"residual_std_kg_m2", JsonNumber(o.residual_std_kg_m2)},
              {"z", JsonNumber(o.z)},
              {"scatter_kg_m2", JsonNumber(o.scatter_kg_m2)}};
    if (g < r.orientation_relative_scatter.size()) {
      e["relative_scatter"] = JsonNumber(r.orientation_relative_scatter[g]);
    }
    if (g < c.orientations.size()) {
      e["roll_deg"] = JsonNumber(c.orientations[g].roll_deg);
      e["pitch_deg"] = JsonNumber(c.orientations[g].pitch_deg);
    }
    orientations.push_back(e);
  }
  return orientations;
}

json SolverJson(const TensorResult& r) {
  return {{"method", r.ceres.method},
          {"converged", r.ceres.converged},
          {"message", r.ceres.message},
          {"iterations", r.ceres.iterations},
          {"initial_cost", JsonNumber(r.ceres.initial_cost)},
          {"final_cost", JsonNumber(r.ceres.final_cost)},
          {"time_s", JsonNumber(r.ceres.time_s)}};
}

}  // namespace

json TensorScatterLogs(const TensorResult& r, const TensorJsonContext& c) {
  json out = json::array();
  if (!(r.relative_scatter > 0) && !(r.attitude_scatter_deg > 0)) return out;
  // A log is behind the scatter when its residual is beyond 2 of its own stds.
  constexpr double kBeyondStds = 2.0;
  std::vector<std::pair<double, std::string>> logs;
  for (const TensorPointResidual& p : r.residuals) {
    if (p.index >= static_cast<int>(c.points.size())) continue;
    const TensorJsonContext::Point& q = c.points[p.index];
    const double ratio = p.residual_kg_m2 / q.std_kg_m2;
    if (std::isfinite(ratio) && std::fabs(ratio) > kBeyondStds) logs.emplace_back(ratio, q.file);
  }
  std::stable_sort(logs.begin(), logs.end(), [](const auto& a, const auto& b) {
    return std::fabs(a.first) > std::fabs(b.first);
  });
  for (const auto& [ratio, file] : logs)
    out.push_back({{"file", file}, {"residual_over_std", ratio}});
  return out;
}

std::string ScatterLogsText(const std::vector<std::pair<std::string, double>>& logs) {
  if (logs.empty()) return "";
  constexpr size_t kNamed = 4;
  std::string out = "the logs behind the scatter, residual over their own std: ";
  char ratio[32];
  for (size_t i = 0; i < logs.size() && i < kNamed; ++i) {
    std::snprintf(ratio, sizeof(ratio), " %+.1f", logs[i].second);
    out += (i ? ", " : "") + logs[i].first + ratio;
  }
  if (logs.size() > kNamed) out += ", and " + std::to_string(logs.size() - kNamed) + " more";
  return out;
}

json PhysicalCheckToJson(const PhysicalCheck& check) {
  const auto one = [](const PhysicalInequality& q) {
    return json{{"inequality", q.name},
                {"margin_kg_m2", JsonNumber(q.margin_kg_m2)},
                {"std_kg_m2", JsonNumber(q.std_kg_m2)},
                {"z", std::isfinite(q.z) ? JsonNumber(q.z) : json(nullptr)}};
  };
  json j;
  j["status"] = PhysicalStatusName(check.status);
  j["checked"] = check.checked;
  j["worst"] = check.Worst() ? one(*check.Worst()) : json(nullptr);
  j["threshold_z"] =
      std::isfinite(check.threshold_z) ? JsonNumber(check.threshold_z) : json(nullptr);
  j["attitude"] = check.attitude;
  j["z_without_attitude"] = std::isfinite(check.z_without_attitude)
                                ? JsonNumber(check.z_without_attitude)
                                : json(nullptr);
  j["message"] = check.message;
  json all = json::array();
  for (const PhysicalInequality& q : check.inequalities) all.push_back(one(q));
  j["inequalities"] = all;
  return j;
}

json TensorResultToJson(const TensorResult& r, const TensorJsonContext& c) {
  json j;
  PutCommon(c, &j);
  j["source"] = "tensor_fit";
  PutComponents(r, &j);
  PutPrincipal(r, &j);
  PutDesignAndScatter(r, &j);
  j["residuals"] = ResidualsJson(r, c);
  j["n_outliers"] = r.n_outliers;
  j["orientations"] = OrientationsJson(r, c);
  j["solver"] = SolverJson(r);
  j["closed_form_max_relative_difference"] = JsonNumber(r.closed_form_max_relative_difference);
  j["warnings"] = r.warnings;
  j["scatter_logs"] = TensorScatterLogs(r, c);
  j["physical"] = PhysicalCheckToJson(r.physical);
  j["time_s"] = JsonNumber(r.time_s);
  return j;
}

json PlanarTensorJson(const EllipseResult& e, const TensorJsonContext& c) {
  json j;
  PutCommon(c, &j);
  j["source"] = "ellipse";
  const auto put = [&](const char* key, const EllipseEstimate& est) {
    TensorEstimate t{est.value, est.std, est.ci_lo, est.ci_hi, true};
    PutEstimate(&j, key, t);
  };
  put("Ixx_kg_m2", e.ix);
  PutEstimate(&j, "Iyy_kg_m2", TensorEstimate{0, 0, 0, 0, false});
  put("Izz_kg_m2", e.iz);
  PutEstimate(&j, "Ixy_kg_m2", TensorEstimate{0, 0, 0, 0, false});
  put("Ixz_kg_m2", e.ixz);
  PutEstimate(&j, "Iyz_kg_m2", TensorEstimate{0, 0, 0, 0, false});
  j["observable"] = {{"Ixx", true},  {"Iyy", false}, {"Izz", true},
                     {"Ixy", false}, {"Ixz", true},  {"Iyz", false}};
  j["unobservable"] = json::array({"Iyy", "Ixy", "Iyz"});
  j["observable_combinations"] = json::array();
  // Ix = A - B, Iz = A + B, Ixz = C: their covariance from that of (A, B, C).
  const double m[3][3] = {{1, -1, 0}, {1, 1, 0}, {0, 0, 1}};
  const int index[3] = {kIxx, kIzz, kIxz};
  json cov = json::array();
  for (int k = 0; k < kTensorComponents; ++k) {
    json row = json::array();
    for (int l = 0; l < kTensorComponents; ++l) row.push_back(nullptr);
    cov.push_back(row);
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double v = 0.0;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) v += m[a][p] * e.cov_abc[p][q] * m[b][q];
      cov[index[a]][index[b]] = JsonNumber(v);
    }
  }
  j["covariance_kg2_m4"] = cov;
  j["tensor_kg_m2"] = nullptr;
  j["principal_moments_kg_m2"] = nullptr;
  j["principal_axes"] = nullptr;
  j["principal_in_plane"] = {
      {"tau_deg", e.tau_defined ? JsonNumber(e.tau_deg.value) : json(nullptr)},
      {"Ixp_kg_m2", e.tau_defined ? JsonNumber(e.ixp.value) : json(nullptr)},
      {"Izp_kg_m2", e.tau_defined ? JsonNumber(e.izp.value) : json(nullptr)},
      {"note", "principal axes of the x-z plane, see the ellipse section"}};
  j["rank"] = 3;
  j["n_points"] = e.n_points;
  j["n_orientations"] = e.n_angles;
  j["covariance"] = EllipseCovarianceName(e.covariance_used);
  j["variance_factor"] = JsonNumber(e.variance_factor);
  j["dof"] = JsonNumber(e.dof);
  j["rmse_kg_m2"] = JsonNumber(e.rmse_kg_m2);
  j["bootstrap_replicates"] = e.bootstrap_replicates;
  json residuals = json::array();
  for (const EllipseResidual& p : e.residuals) {
    json r = {{"index", p.index},
              {"inertia_kg_m2", JsonNumber(p.inertia_kg_m2)},
              {"fitted_kg_m2", JsonNumber(p.fitted_kg_m2)},
              {"residual_kg_m2", JsonNumber(p.residual_kg_m2)},
              {"studentized", JsonNumber(p.studentized)},
              {"outlier", p.outlier},
              {"roll_deg", 0.0},
              {"pitch_deg", JsonNumber(p.pitch_deg)}};
    if (p.index < static_cast<int>(c.points.size())) r["file"] = c.points[p.index].file;
    residuals.push_back(r);
  }
  j["residuals"] = residuals;
  json orientations = json::array();
  for (const EllipseAngleStats& a : e.angles) {
    const std::array<double, 3> n = DownInBodyFromAttitude(0.0, a.pitch_deg);
    orientations.push_back({{"roll_deg", 0.0},
                            {"pitch_deg", JsonNumber(a.pitch_deg)},
                            {"axis_in_body", Vector3(n)},
                            {"n", a.n},
                            {"mean_kg_m2", JsonNumber(a.mean_kg_m2)},
                            {"fitted_kg_m2", JsonNumber(a.fitted_kg_m2)},
                            {"residual_kg_m2", JsonNumber(a.mean_kg_m2 - a.fitted_kg_m2)},
                            {"scatter_kg_m2", JsonNumber(a.std_kg_m2)}});
  }
  j["orientations"] = orientations;
  j["warnings"] = json::array(
      {"a planar x-z campaign (pitch only): Ixx, Izz and Ixz are the ellipse's I_x, I_z and "
       "I_xz; Iyy, Ixy and Iyz are not observable without swings about axes outside that plane "
       "(roll_deg)"});
  return j;
}

}  // namespace bifilar
