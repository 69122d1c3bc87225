#include "pipeline/commands/ellipse_command.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "base/plot_folder.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/figures/ellipse_plot.h"
#include "pipeline/records/ellipse_json.h"

namespace bifilar {
namespace {

// "value +- std" in display units, or "undefined".
std::string ValueStd(double v, double s, bool has_std, const char* format) {
  if (!std::isfinite(v)) return "undefined";
  std::string out = Fmt(format, v);
  if (has_std && std::isfinite(s)) out += " +- " + Fmt(format, s);
  return out;
}

void Row(std::ostream& out, const std::string& name, const std::string& a, const std::string& b,
         const std::string& c) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "  %-20s %-26s %-26s %-26s\n", name.c_str(), a.c_str(), b.c_str(),
                c.c_str());
  out << buf;
}

}  // namespace

void PrintEllipseReport(const EllipseResult& r, DisplayUnits units, std::ostream& out) {
  const double k = 1.0 / InertiaToSi(units);  // SI -> display
  const std::string u = InertiaUnitName(units);
  const char* f = "%.5f";
  out << "Ellipse of inertia: " << r.n_points << " points at " << r.n_angles << " angle(s), "
      << (r.weighted ? "weighted by the given std" : "unweighted") << ", covariance '"
      << EllipseCovarianceName(r.covariance_used) << "'";
  if (std::isfinite(r.dof)) out << " (" << r.dof << " dof)";
  out << "\n\nThree fits (I = A + B cos 2theta + C sin 2theta; paper Eq. 7):\n";
  Row(out, "", "linear LS (primary)", "Nelder-Mead Eq. 7", "Ceres Eq. 7");
  const EllipseSolverSummary* fits[3] = {&r.linear, &r.nelder_mead, &r.ceres};
  auto cell = [&](const EllipseSolverSummary* s, double v, double sd, double scale, bool angle) {
    if (!s->ran) return std::string("not run");
    if (angle && !r.tau_defined) return std::string("undefined");
    return ValueStd(v * scale, sd * scale, s->has_std, f);
  };
  struct Q {
    std::string name;
    double EllipseParameters::*field;
    bool angle;
  };
  const Q quantities[] = {{"I_x [" + u + "]", &EllipseParameters::ix_kg_m2, false},
                          {"I_z [" + u + "]", &EllipseParameters::iz_kg_m2, false},
                          {"I_xz [" + u + "]", &EllipseParameters::ixz_kg_m2, false},
                          {"tau [deg]", &EllipseParameters::tau_deg, true},
                          {"I_xp [" + u + "]", &EllipseParameters::ixp_kg_m2, true},
                          {"I_zp [" + u + "]", &EllipseParameters::izp_kg_m2, true}};
  for (const Q& q : quantities) {
    std::string cells[3];
    for (int i = 0; i < 3; ++i) {
      cells[i] = cell(fits[i], fits[i]->parameters.*q.field, fits[i]->std.*q.field,
                      q.angle && q.field == &EllipseParameters::tau_deg ? 1.0 : k, q.angle);
    }
    Row(out, q.name, cells[0], cells[1], cells[2]);
  }
  std::string status[3];
  for (int i = 0; i < 3; ++i) {
    status[i] = !fits[i]->ran ? "-"
                              : (fits[i]->converged ? "ok, " : "FAILED, ") +
                                    std::to_string(fits[i]->iterations) +
                                    (i == 1   ? " evals"
                                     : i == 2 ? " iters"
                                              : "");
  }
  Row(out, "status", status[0], status[1], status[2]);

  out << "\nIntervals ("
      << (r.bootstrap_replicates > 0 ? "seeded parametric bootstrap, " +
                                           std::to_string(r.bootstrap_replicates) + " replicates"
                                     : std::string("t quantiles"))
      << "):\n";
  const EllipseEstimate* est[6] = {&r.ix, &r.iz, &r.ixz, &r.tau_deg, &r.ixp, &r.izp};
  const char* names[6] = {"I_x", "I_z", "I_xz", "tau", "I_xp", "I_zp"};
  for (int i = 0; i < 6; ++i) {
    const double s = i == 3 ? 1.0 : k;
    char buf[200];
    if (!est[i]->defined) {
      std::snprintf(buf, sizeof buf, "  %-5s undefined\n", names[i]);
    } else {
      std::snprintf(buf, sizeof buf, "  %-5s %10.5f  std %8.5f  95%% [%.5f, %.5f] %s\n", names[i],
                    est[i]->value * s, est[i]->std * s, est[i]->ci_lo * s, est[i]->ci_hi * s,
                    i == 3 ? "deg" : u.c_str());
    }
    out << buf;
  }

  out << "\nTable 1 (paper): error analysis\n";
  if (r.table1.n_angles_with_trials > 0) {
    out << "  raw data sigma (mean per-angle std)   "
        << Fmt("%.4f ", r.table1.mean_angle_std_kg_m2 * k) << u << "\n";
    out << "  coefficient of variation (mean)       " << Fmt("%.4f %%", r.table1.mean_cov_percent)
        << "\n";
  } else {
    out << "  raw data sigma, CoV                   n/a (one trial per angle)\n";
  }
  out << "  regression RMSE                       " << Fmt("%.4f ", r.rmse_kg_m2 * k) << u << "\n";
  out << "\nTable 2 (paper): product of inertia\n";
  out << "  I_xz  " << Fmt("%.4f ", r.ixz.value * k) << u << "\n";
  out << "  tau   " << (r.tau_defined ? Fmt("%.4f deg", r.tau_deg.value) : "undefined") << "\n";
  out << "  I_z   " << Fmt("%.4f ", r.iz.value * k) << u << "\n";
  out << "  I_x   " << Fmt("%.4f ", r.ix.value * k) << u << "\n";

  out << "\nPer-angle moments [" << u << "]:\n";
  out << "  pitch_deg   n        mean         std     CoV %      fitted\n";
  for (const auto& a : r.angles) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "  %9.2f %3d %11.5f %11.5f %9.4f %11.5f\n", a.pitch_deg, a.n,
                  a.mean_kg_m2 * k, a.std_kg_m2 * k, a.cov_percent, a.fitted_kg_m2 * k);
    out << buf;
  }

  out << "\nNACA Report 467 three-axis estimate of I_xz (paper Eq. 1), one oblique angle each:\n";
  if (r.naca.empty()) out << "  none (no oblique angle)\n";
  for (const auto& e : r.naca) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "  pitch %7.2f deg: I_xz %9.5f +- %8.5f %s\n", e.pitch_deg,
                  e.ixz_kg_m2 * k, e.ixz_std_kg_m2 * k, u.c_str());
    out << buf;
  }
  out << "  multi-angle fit:   I_xz " << Fmt("%9.5f", r.ixz.value * k) << " +- "
      << Fmt("%8.5f", r.ixz.std * k) << " " << u << "\n";

  out << "\nOutliers (|studentized residual| > threshold): " << r.n_outliers << "\n";
  for (const auto& e : r.residuals) {
    if (!e.outlier) continue;
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "  row %d: pitch %.2f deg, inertia %.5f, fitted %.5f %s, r = %.2f\n", e.index + 1,
                  e.pitch_deg, e.inertia_kg_m2 * k, e.fitted_kg_m2 * k, u.c_str(), e.studentized);
    out << buf;
  }
  for (const auto& w : r.warnings) out << "warning: " << w << "\n";
}

namespace {

// The figures `ellipse --plot DIR` writes, by name.
std::vector<std::string> EllipseFigureNames() {
  return {"ellipse_moments.png", "ellipse_polar.png", "ellipse_moments.svg", "ellipse_polar.svg"};
}

}  // namespace

std::vector<std::string> WriteEllipsePlots(const EllipseResult& result, DisplayUnits units,
                                           const std::string& dir, bool force) {
  // No file bifilar did not write there is replaced without --force, no link ever
  // (base/plot_folder.h); refused before any figure is drawn.
  PlotFolder(dir, "ellipse --plot", force).Claim(EllipseFigureNames());
  EllipsePlotOptions plot;
  plot.unit_scale = 1.0 / InertiaToSi(units);
  plot.unit_label = InertiaUnitPlotLabel(units);
  std::vector<std::string> written;
  for (const char* ext : {".png", ".svg"}) {
    const std::string moments = (std::filesystem::path(dir) / "ellipse_moments").string() + ext;
    const std::string polar = (std::filesystem::path(dir) / "ellipse_polar").string() + ext;
    std::string why;
    if (!WriteEllipseMomentFigure(result, moments, plot, &why)) throw UserError(why);
    written.push_back(moments);
    if (!WriteEllipsePolarFigure(result, polar, plot, &why)) throw UserError(why);
    written.push_back(polar);
  }
  return written;
}

EllipseCommandResult RunEllipse(const EllipseCommandOptions& options) {
  std::string why;
  if (!options.fit.Check(&why)) throw UserError("ellipse options: " + why);
  if (!options.plot_dir.empty()) {  // refused before the fit, as when the figures are written
    PlotFolder(options.plot_dir, "ellipse --plot", options.force).Claim(EllipseFigureNames());
  }
  const std::vector<EllipsePoint> points = ReadEllipseTable(options.table_path, options.units);
  EllipseCommandResult result;
  if (!FitEllipse(points, options.fit, &result.fit, &why)) {
    throw UserError(options.table_path + ": " + why);
  }
  if (!options.plot_dir.empty()) {
    result.figures = WriteEllipsePlots(result.fit, options.units, options.plot_dir, options.force);
  }
  return result;
}

void PrintEllipseCommand(const EllipseCommandOptions& options, const EllipseCommandResult& result,
                         std::ostream& out) {
  if (options.json) {
    WriteEllipseResultJson(result.fit, {{"table", options.table_path}, {"figures", result.figures}},
                           out);
    return;
  }
  out << options.table_path << "\n";
  PrintEllipseReport(result.fit, options.units, out);
  for (const auto& p : result.figures) out << "wrote " << p << "\n";
}

int EllipseExitCode(const EllipseCommandResult& result) {
  return result.fit.physical ? 0 : 1;  // a non-physical tensor is printed with its warning
}

EllipsePlan RunPlan(const PlanCommandOptions& options) {
  const double to_si = InertiaToSi(options.units);
  EllipsePlanOptions plan_options;
  plan_options.pitch_deg = options.pitch_deg;
  plan_options.trials_per_angle = options.trials_per_angle;
  plan_options.sigma_kg_m2 = options.sigma * to_si;
  if (options.guesses_given) {
    plan_options.ix_kg_m2 = options.ix * to_si;
    plan_options.iz_kg_m2 = options.iz * to_si;
    plan_options.ixz_kg_m2 = options.ixz * to_si;
  } else {
    plan_options.ix_kg_m2 = 2.3596 * kKgM2PerSlugFt2;
    plan_options.iz_kg_m2 = 2.8477 * kKgM2PerSlugFt2;
    plan_options.ixz_kg_m2 = 0.0178 * kKgM2PerSlugFt2;
  }
  EllipsePlan plan;
  std::string why;
  if (!PlanEllipse(plan_options, &plan, &why)) throw UserError("plan: " + why);
  return plan;
}

void PrintPlan(const PlanCommandOptions& options, const EllipsePlan& plan, std::ostream& out) {
  if (options.json) {
    out << EllipsePlanToJson(plan).dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
        << "\n";
    return;
  }
  const double k = 1.0 / InertiaToSi(options.units);
  const std::string u = InertiaUnitName(options.units);
  out << "Planned design: " << options.pitch_deg.size() << " angle(s) x "
      << options.trials_per_angle << " trial(s) = " << plan.n_points << " points, per-trial sigma "
      << Fmt("%.5g ", options.sigma) << u << "\n";
  out << "Assumed aircraft" << (options.guesses_given ? "" : " (default: the paper's PRANDTL-D)")
      << ": I_x " << Fmt("%.5g", plan.truth.ix_kg_m2 * k) << ", I_z "
      << Fmt("%.5g", plan.truth.iz_kg_m2 * k) << ", I_xz " << Fmt("%.5g ", plan.truth.ixz_kg_m2 * k)
      << u << "\n";
  out << "Predicted standard errors (independent trial noise only):\n";
  out << "  I_xz  " << Fmt("%.5g ", plan.std.ixz_kg_m2 * k) << u << "\n";
  if (plan.tau_defined) {
    out << "  tau   " << Fmt("%.4g deg", plan.std.tau_deg)
        << " (tau = " << Fmt("%.4g deg", plan.truth.tau_deg) << ")\n";
  } else {
    out << "  tau   undefined for I_x = I_z and I_xz = 0\n";
  }
  out << "  I_x   " << Fmt("%.5g ", plan.std.ix_kg_m2 * k) << u << "\n";
  out << "  I_z   " << Fmt("%.5g ", plan.std.iz_kg_m2 * k) << u << "\n";
}

}  // namespace bifilar
