#include "pipeline/records/ellipse_json.h"

#include <cmath>

#include "base/json_number.h"

namespace bifilar {
namespace {

using nlohmann::json;

void PutEstimate(json* j, const std::string& key, const EllipseEstimate& e) {
  const bool ok = e.defined;
  (*j)[key] = ok ? JsonNumber(e.value) : json(nullptr);
  (*j)[key + "_std"] = ok ? JsonNumber(e.std) : json(nullptr);
  (*j)[key + "_ci95"] =
      ok ? json::array({JsonNumber(e.ci_lo), JsonNumber(e.ci_hi)}) : json(nullptr);
}

json ParametersToJson(const EllipseParameters& p, bool tau_defined) {
  json j;
  j["Ix_kg_m2"] = JsonNumber(p.ix_kg_m2);
  j["Iz_kg_m2"] = JsonNumber(p.iz_kg_m2);
  j["Ixz_kg_m2"] = JsonNumber(p.ixz_kg_m2);
  j["tau_deg"] = tau_defined ? JsonNumber(p.tau_deg) : json(nullptr);
  j["Ixp_kg_m2"] = tau_defined ? JsonNumber(p.ixp_kg_m2) : json(nullptr);
  j["Izp_kg_m2"] = tau_defined ? JsonNumber(p.izp_kg_m2) : json(nullptr);
  return j;
}

json SolverToJson(const EllipseSolverSummary& s, bool tau_defined) {
  json j;
  j["method"] = s.method;
  j["ran"] = s.ran;
  if (!s.ran) return j;
  j["converged"] = s.converged;
  j["message"] = s.message;
  j["iterations"] = s.iterations;
  j["restarts"] = s.restarts;
  j["initial_cost"] = JsonNumber(s.initial_cost);
  j["final_cost"] = JsonNumber(s.final_cost);
  j["time_s"] = JsonNumber(s.time_s);
  j["parameters"] = ParametersToJson(s.parameters, tau_defined);
  j["std"] = s.has_std ? ParametersToJson(s.std, tau_defined) : json(nullptr);
  return j;
}

json ResidualToJson(const EllipseResidual& e) {
  return {{"index", e.index},
          {"pitch_deg", JsonNumber(e.pitch_deg)},
          {"inertia_kg_m2", JsonNumber(e.inertia_kg_m2)},
          {"fitted_kg_m2", JsonNumber(e.fitted_kg_m2)},
          {"residual_kg_m2", JsonNumber(e.residual_kg_m2)},
          {"studentized", JsonNumber(e.studentized)},
          {"outlier", e.outlier}};
}

constexpr const char* kResidualsPlaceholder = "@@bifilar residuals@@";

}  // namespace

void WriteEllipseResultJson(const EllipseResult& result, const json& extra, std::ostream& out) {
  json j = EllipseResultToJson(result, false);
  for (const auto& [key, value] : extra.items()) j[key] = value;
  j["residuals"] = kResidualsPlaceholder;
  const std::string text = j.dump(2, ' ', false, json::error_handler_t::replace);
  const std::string quoted = std::string("\"") + kResidualsPlaceholder + "\"";
  const size_t at = text.find(quoted);
  out << text.substr(0, at) << "[";
  for (size_t i = 0; i < result.residuals.size(); ++i) {
    out << (i ? ",\n    " : "\n    ") << ResidualToJson(result.residuals[i]).dump();
  }
  out << (result.residuals.empty() ? "]" : "\n  ]") << text.substr(at + quoted.size()) << "\n";
}

json EllipseResultToJson(const EllipseResult& r, bool with_residuals) {
  json j;
  PutEstimate(&j, "Ix_kg_m2", r.ix);
  PutEstimate(&j, "Iz_kg_m2", r.iz);
  PutEstimate(&j, "Ixz_kg_m2", r.ixz);
  PutEstimate(&j, "tau_deg", r.tau_deg);
  PutEstimate(&j, "Ixp_kg_m2", r.ixp);
  PutEstimate(&j, "Izp_kg_m2", r.izp);
  j["rmse_kg_m2"] = JsonNumber(r.rmse_kg_m2);
  j["n_points"] = r.n_points;
  j["n_angles"] = r.n_angles;
  j["weighted"] = r.weighted;
  j["tau_defined"] = r.tau_defined;
  j["circle_chi2"] = JsonNumber(r.circle_chi2);
  j["covariance"] = EllipseCovarianceName(r.covariance_used);
  j["variance_factor"] = JsonNumber(r.variance_factor);
  j["dof"] = JsonNumber(r.dof);  // null when the std were trusted as absolute (normal quantiles)
  j["reduced_chi2"] = JsonNumber(r.reduced_chi2);
  j["confidence_interval_method"] =
      r.bootstrap_replicates > 0 ? "parametric_bootstrap_percentile" : "t_quantile";
  j["bootstrap_replicates"] = r.bootstrap_replicates;
  j["coefficients_kg_m2"] = {
      {"A", JsonNumber(r.a_kg_m2)}, {"B", JsonNumber(r.b_kg_m2)}, {"C", JsonNumber(r.c_kg_m2)}};
  json cov = json::array();
  for (const auto& row : r.cov_abc)
    cov.push_back({JsonNumber(row[0]), JsonNumber(row[1]), JsonNumber(row[2])});
  j["cov_abc_kg2_m4"] = cov;
  j["fits"] = {{"linear_ls", SolverToJson(r.linear, r.tau_defined)},
               {"nelder_mead", SolverToJson(r.nelder_mead, r.tau_defined)},
               {"ceres", SolverToJson(r.ceres, r.tau_defined)}};
  j["table1"] = {{"mean_angle_std_kg_m2", JsonNumber(r.table1.mean_angle_std_kg_m2)},
                 {"mean_cov_percent", JsonNumber(r.table1.mean_cov_percent)},
                 {"rmse_kg_m2", JsonNumber(r.table1.rmse_kg_m2)},
                 {"n_angles_with_trials", r.table1.n_angles_with_trials}};
  if (r.table1.n_angles_with_trials == 0) {
    j["table1"]["mean_angle_std_kg_m2"] = nullptr;
    j["table1"]["mean_cov_percent"] = nullptr;
  }
  j["table2"] = {{"Ixz_kg_m2", JsonNumber(r.ixz.value)},
                 {"tau_deg", r.tau_defined ? JsonNumber(r.tau_deg.value) : json(nullptr)},
                 {"Iz_kg_m2", JsonNumber(r.iz.value)},
                 {"Ix_kg_m2", JsonNumber(r.ix.value)}};
  json angles = json::array();
  for (const auto& a : r.angles) {
    angles.push_back({{"pitch_deg", JsonNumber(a.pitch_deg)},
                      {"n", a.n},
                      {"mean_kg_m2", JsonNumber(a.mean_kg_m2)},
                      {"std_kg_m2", a.n > 1 ? JsonNumber(a.std_kg_m2) : json(nullptr)},
                      {"cov_percent", a.n > 1 ? JsonNumber(a.cov_percent) : json(nullptr)},
                      {"fitted_kg_m2", JsonNumber(a.fitted_kg_m2)}});
  }
  j["angles"] = angles;
  json residuals = json::array();
  json outliers = json::array();
  for (const auto& e : r.residuals) {
    if (e.outlier) outliers.push_back(ResidualToJson(e));
    if (with_residuals) residuals.push_back(ResidualToJson(e));
  }
  j["residuals"] = residuals;
  j["outliers"] = outliers;
  json naca = json::array();
  for (const auto& e : r.naca) {
    naca.push_back({{"pitch_deg", JsonNumber(e.pitch_deg)},
                    {"phi_deg", JsonNumber(e.phi_deg)},
                    {"I_phi_kg_m2", JsonNumber(e.i_phi_kg_m2)},
                    {"Ixz_kg_m2", JsonNumber(e.ixz_kg_m2)},
                    {"Ixz_std_kg_m2", JsonNumber(e.ixz_std_kg_m2)}});
  }
  j["naca"] = naca;
  j["warnings"] = r.warnings;
  j["time_s"] = JsonNumber(r.time_s);
  return j;
}

json EllipsePlanToJson(const EllipsePlan& p) {
  json j;
  j["n_points"] = p.n_points;
  j["tau_defined"] = p.tau_defined;
  j["assumed"] = ParametersToJson(p.truth, p.tau_defined);
  const json s = ParametersToJson(p.std, p.tau_defined);
  for (auto it = s.begin(); it != s.end(); ++it) j[it.key() + std::string("_std")] = it.value();
  return j;
}

}  // namespace bifilar
