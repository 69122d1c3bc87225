#include "pipeline/campaign/campaign_tensor.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <sstream>

#include "base/hash.h"
#include "base/text_format.h"
#include "base/version.h"
#include "fit/physical.h"
#include "pipeline/figures/tensor_plot.h"
#include "pipeline/records/tensor_json.h"
#include "pipeline/records/total_uncertainty.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;

bool UsableAircraft(const TraceRecord& r) { return r.role == TraceRole::kAircraft && r.ok(); }

// The rig's std as the ellipse takes it (campaign.cc MakeEllipseOptions): one offset common to
// every moment.
double RigCommonStd(const CampaignConfig& config, const CampaignResult& result) {
  const double rig_std = config.rig_inertia.kind == RigInertiaSpec::Kind::kTare
                             ? result.rig_inertia_std_kg_m2
                             : config.rig_inertia.inertia_std_kg_m2;
  return std::isfinite(rig_std) ? rig_std : 0.0;
}

TensorOptions MakeTensorOptions(const CampaignConfig& config, const CampaignResult& result) {
  TensorOptions o;
  o.bootstrap_replicates = config.ellipse.bootstrap;
  o.seed = config.ellipse.seed;
  o.confidence = config.ellipse.confidence;
  o.covariance = config.ellipse.covariance;
  o.common_offset_std_kg_m2 = RigCommonStd(config, result);
  return o;
}

// The principal-axes figure under a name keyed by the fit, so an unchanged rerun reuses it.
void DrawTensorFigure(const CampaignConfig& config, const TensorResult& fit,
                      const std::string& figures_dir,
                      const std::function<void(const std::string&)>& record_figure,
                      CampaignResult* result) {
  std::ostringstream key;
  key.precision(17);
  key << ProgramVersion() << ';' << ToString(config.units) << ";tensor;";
  for (const TensorEstimate& e : fit.components) key << e.value << ',' << e.std << ';';
  for (const TensorPointResidual& p : fit.residuals) key << p.inertia_kg_m2 << ';';
  const std::string name = "tensor_" + HashToHex(Fnv1a64(key.str())) + ".png";
  record_figure(name);
  TensorPlotOptions plot;
  plot.unit_label = InertiaUnitPlotLabel(config.units);
  if (config.units == DisplayUnits::kImperial) plot.unit_scale = kSlugFt2PerKgM2;
  const fs::path path = fs::path(figures_dir) / name;
  std::error_code ec;
  std::string why;
  if (fs::exists(path, ec) || WriteTensorFigure(fit, path.string(), plot, &why)) {
    result->tensor_figure = name;
  }
}

// The orientation the fit named (fit/tensor.h, TensorResult::physical) by its roll and pitch.
void NamePhysicalAttitude(const TensorJsonContext& context, PhysicalCheck* check) {
  if (check->orientation < 0 ||
      check->orientation >= static_cast<int>(context.orientations.size())) {
    return;
  }
  const TensorJsonContext::Orientation& o = context.orientations[check->orientation];
  check->attitude = "roll " + Fmt("%g", o.roll_deg) + ", pitch " + Fmt("%g", o.pitch_deg) + " deg";
  check->message = PhysicalCheckMessage(*check);
}

}  // namespace

bool IsPlanarCampaign(const std::vector<TraceRecord>& traces) {
  for (const TraceRecord& r : traces) {
    if (UsableAircraft(r) && r.roll_nominal_deg && *r.roll_nominal_deg != 0.0) return false;
  }
  return true;
}

void FitCampaignTensor(const CampaignConfig& config, const std::string& figures_dir,
                       const std::function<void(const std::string&)>& record_figure,
                       CampaignResult* result) {
  CampaignSummary& summary = result->summary;
  TensorJsonContext context;
  context.confidence = config.ellipse.confidence;
  context.common_offset_std_kg_m2 = RigCommonStd(config, *result);
  context.systematic_relative_std = result->systematic_relative_std;
  const bool planar = IsPlanarCampaign(result->traces);
  if (planar && result->ellipse_fit) {
    // Today's ellipse, untouched; its numbers repeated as the tensor's x-z components.
    context.mode = "planar_xz";
    for (const TraceRecord& r : result->traces) {
      if (UsableAircraft(r)) context.points.push_back({r.file, 0.0, r.pitch_used_deg});
    }
    result->tensor = PlanarTensorJson(*result->ellipse_fit, context);
    summary.tensor_fitted = true;
    return;
  }
  // One point per ok aircraft trace; orientation groups by nominal attitude.
  std::vector<TensorPoint> points;
  std::map<std::pair<double, double>, int> group_of;
  for (const TraceRecord& r : result->traces) {
    if (!UsableAircraft(r)) continue;
    TensorPoint p;
    p.direction_in_body = DownInBodyFromAttitude(r.roll_used_deg, r.pitch_used_deg);
    if (r.pitch_nominal_deg) {
      const double roll = r.roll_nominal_deg.value_or(0.0);
      p.nominal_in_body = DownInBodyFromAttitude(roll, *r.pitch_nominal_deg);
      auto [it, inserted] = group_of.emplace(std::make_pair(roll, *r.pitch_nominal_deg),
                                             static_cast<int>(group_of.size()));
      if (inserted) context.orientations.push_back({roll, *r.pitch_nominal_deg});
      p.group = it->second;
    }
    p.inertia_kg_m2 = r.inertia_kg_m2;
    p.std_kg_m2 = r.inertia_total_std_kg_m2;  // the rig's std is the common offset
    points.push_back(p);
    context.points.push_back({r.file, r.roll_used_deg, r.pitch_used_deg, p.std_kg_m2});
  }
  if (points.empty()) {
    summary.tensor_message = "tensor not fitted: no usable aircraft trace";
    return;
  }
  // Groups are by nominal attitude only when every point has one (else by direction, and the
  // orientations are then labelled by their axes alone).
  if (group_of.empty() || context.orientations.size() != group_of.size() ||
      std::any_of(points.begin(), points.end(), [](const TensorPoint& p) { return p.group < 0; })) {
    for (TensorPoint& p : points) p.group = -1;
    context.orientations.clear();
  }
  TensorResult fit;
  std::string why;
  if (!FitTensor(points, MakeTensorOptions(config, *result), &fit, &why) || !fit.IsUsable()) {
    summary.tensor_message = "tensor not fitted: " + (why.empty() ? "fit not usable" : why);
    return;
  }
  context.mode = fit.full ? "full_3d" : "partial";
  NamePhysicalAttitude(context, &fit.physical);
  result->physical = fit.physical;
  result->tensor = TensorResultToJson(fit, context);
  summary.tensor_fitted = true;
  if (!figures_dir.empty()) DrawTensorFigure(config, fit, figures_dir, record_figure, result);
  result->tensor_fit = std::move(fit);
}

}  // namespace bifilar

namespace bifilar {

namespace {

// Attitudes whose logs scatter beyond the others': their own scatter widens their axes only.
void PrintOwnScatter(const TensorResult& t, const CampaignResult& result, std::ostream& out) {
  char line[256];
  for (size_t g = 0; g < t.orientation_relative_scatter.size(); ++g) {
    const double own = t.orientation_relative_scatter[g];
    if (!(own > t.relative_scatter) || g >= result.tensor["orientations"].size()) continue;
    const nlohmann::json& o = result.tensor["orientations"][g];
    std::snprintf(line, sizeof(line),
                  "  (the logs at roll %g, pitch %g deg scatter by %.2f %% beyond their stds: "
                  "weighed by that, that axis alone; docs/method.md)\n",
                  o.value("roll_deg", NAN), o.value("pitch_deg", NAN), 100.0 * own);
    out << line;
  }
}

// Per orientation: logs, the total (rig + aircraft) and aircraft moments with the mean's std
// (stat, then total), the fit's residual.
void PrintPerAxis(const CampaignConfig& config, const CampaignResult& result, std::ostream& out) {
  const TensorResult& t = *result.tensor_fit;
  const DisplayUnits units = config.units;
  const char* unit = InertiaUnitName(units);
  auto inertia = [&](double kg_m2) { return InertiaToDisplay(kg_m2, units); };
  char line[320];
  const bool rig = config.rig_inertia_given;
  out << "Per axis (" << unit
      << "; mean of its logs, its std: stat, then total; the fit, the "
         "residual over its expected scatter):\n";
  std::snprintf(line, sizeof(line), "  %7s %7s %4s %11s %11s %9s %9s %11s %8s\n", "roll", "pitch",
                "logs", rig ? "I_total" : "I", rig ? "I_aircraft" : "", "sd(stat)", "sd(total)",
                "fitted", "resid/sd");
  out << line;
  std::vector<const TraceRecord*> usable;
  for (const TraceRecord& r : result.traces) {
    if (UsableAircraft(r)) usable.push_back(&r);
  }
  for (size_t g = 0; g < t.orientations.size(); ++g) {
    const TensorOrientation& o = t.orientations[g];
    double roll = NAN, pitch = NAN, rig_kg_m2 = 0.0;
    if (g < result.tensor["orientations"].size()) {
      const nlohmann::json& j = result.tensor["orientations"][g];
      if (j.contains("roll_deg") && j["roll_deg"].is_number()) roll = j["roll_deg"];
      if (j.contains("pitch_deg") && j["pitch_deg"].is_number()) pitch = j["pitch_deg"];
    }
    // Points are the usable aircraft traces in order: the orientation's mean rig inertia.
    double rig_sum = 0.0;
    for (const int i : o.members) {
      const double v = usable[i]->rig_inertia_kg_m2;
      rig_sum += std::isfinite(v) ? v : 0.0;
    }
    rig_kg_m2 = o.members.empty() ? 0.0 : rig_sum / o.members.size();
    const int members = static_cast<int>(o.members.size());
    char total[32] = "", aircraft[32] = "";
    std::snprintf(total, sizeof(total), "%#11.5g", inertia(o.mean_kg_m2 + rig_kg_m2));
    if (rig) std::snprintf(aircraft, sizeof(aircraft), "%#11.5g", inertia(o.mean_kg_m2));
    std::snprintf(line, sizeof(line), "  %7.1f %7.1f %4d %s %11s %#9.2g %#9.2g %#11.5g %+8.2f\n",
                  roll, pitch, members, total, aircraft, inertia(o.residual_std_kg_m2),
                  inertia(WithCommonModeScale(o.mean_kg_m2, o.residual_std_kg_m2,
                                              result.common_mode_relative_std)),
                  inertia(o.fitted_kg_m2), o.z);
    out << line;
  }
  if (!rig) {
    out << "  (no rig.inertia and no aircraft section: the moments are of everything that "
           "hangs, rig.mass_kg)\n";
  }
}

}  // namespace

void PrintTensorSummary(const CampaignConfig& config, const CampaignResult& result,
                        std::ostream& out) {
  const TensorResult& t = *result.tensor_fit;
  const DisplayUnits units = config.units;
  const char* unit = InertiaUnitName(units);
  auto inertia = [&](double kg_m2) { return InertiaToDisplay(kg_m2, units); };
  char line[320];
  std::snprintf(line, sizeof(line),
                "Inertia tensor (%s, +- 1 std: stat, then total; %d moments about %d axes, "
                "rank %d of 6, design condition number %.3g, covariance %s):\n",
                unit, t.n_points, t.n_orientations, t.rank, t.condition_number,
                EllipseCovarianceName(t.covariance_used));
  out << line;
  static const char* const kLabels[] = {"I_xx", "I_yy", "I_zz", "I_xy", "I_xz", "I_yz"};
  // The total: the stat std and the common-mode scale terms in quadrature, as Table 2's
  // (pipeline/records/total_uncertainty.h).
  const double common = result.common_mode_relative_std;
  auto total = [&](double value, double std) { return WithCommonModeScale(value, std, common); };
  for (int k = 0; k < kTensorComponents; ++k) {
    const TensorEstimate& e = t.components[k];
    if (e.observable) {
      std::snprintf(line, sizeof(line),
                    "  %-5s %#11.5g +- %#.2g (stat) +- %#.2g (total)  (%.3g %% stat)\n", kLabels[k],
                    inertia(e.value), inertia(e.std), inertia(total(e.value, e.std)),
                    e.value != 0 ? 100.0 * e.std / std::fabs(e.value) : 0.0);
    } else {
      std::snprintf(line, sizeof(line), "  %-5s not observable from these swing axes\n",
                    kLabels[k]);
    }
    out << line;
  }
  out << "  (products positive: I_xy = integral x y dm; the tensor holds -I_xy; "
         "docs/physics.md 3.5)\n";
  if (std::isfinite(common) && common > 0) {
    std::snprintf(line, sizeof(line),
                  "  (total: stat and +- %.2f %% common to all moments in quadrature, from the "
                  "configured uncertainties)\n",
                  100.0 * common);
    out << line;
  }
  if (t.attitude_scatter_deg > 0) {
    std::snprintf(line, sizeof(line),
                  "  (the moments scatter as if each axis were off by %.2f deg: weighed by that, "
                  "docs/method.md)\n",
                  t.attitude_scatter_deg);
    out << line;
  }
  if (t.relative_scatter > 0) {
    std::snprintf(line, sizeof(line),
                  "  (the moments scatter by %.2f %% beyond their logs' stds: weighed by that, "
                  "docs/method.md)\n",
                  100.0 * t.relative_scatter);
    out << line;
  }
  PrintOwnScatter(t, result, out);
  std::vector<std::pair<std::string, double>> logs;
  if (result.tensor.is_object() && result.tensor.contains("scatter_logs")) {
    for (const nlohmann::json& l : result.tensor["scatter_logs"]) {
      logs.emplace_back(l.value("file", std::string("?")), l.value("residual_over_std", 0.0));
    }
  }
  const std::string scatter_logs = ScatterLogsText(logs);
  if (!scatter_logs.empty()) out << "  (" << scatter_logs << ")\n";
  if (t.full) {
    out << "Principal moments (ascending) and axes in body axes (x, y, z):\n";
    for (int k = 0; k < 3; ++k) {
      const TensorEstimate& m = t.principal_moments[k];
      std::snprintf(line, sizeof(line),
                    "  %d: %#11.5g +- %#.2g (stat) +- %#.2g (total)  axis (%+.4f, %+.4f, %+.4f) +- "
                    "%.2g deg\n",
                    k + 1, inertia(m.value), inertia(m.std), inertia(total(m.value, m.std)),
                    t.principal_axes[k][0], t.principal_axes[k][1], t.principal_axes[k][2],
                    t.principal_axes_std_deg[k]);
      out << line;
    }
    std::snprintf(line, sizeof(line),
                  "  principal axes from body axes (Z-Y-X): roll %.3f +- %.3f, pitch %.3f +- "
                  "%.3f, yaw %.3f +- %.3f deg\n",
                  t.euler_deg[0].value, t.euler_deg[0].std, t.euler_deg[1].value,
                  t.euler_deg[1].std, t.euler_deg[2].value, t.euler_deg[2].std);
    out << line;
  }
  PrintPerAxis(config, result, out);
  for (const std::string& w : t.warnings) out << "  warning: " << w << "\n";
}

}  // namespace bifilar
