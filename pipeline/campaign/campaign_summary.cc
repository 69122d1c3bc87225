#include "pipeline/campaign/campaign_summary.h"

#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

#include "pipeline/campaign/campaign_tensor.h"
#include "pipeline/campaign/rig_inertia.h"
#include "pipeline/records/total_uncertainty.h"

namespace bifilar {

// `head` then `text` word-wrapped at 150 characters, continuation lines indented by two.
void PrintWrapped(const std::string& head, const std::string& text, std::ostream& out) {
  std::string line = head;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (line.size() + word.size() + 1 > 150 && line.size() > 2) {
      out << line << "\n";
      line = "  ";
    }
    line += (line.empty() || line.back() == ' ' ? "" : " ") + word;
    start = end + 1;
  }
  out << line << "\n";
}

void PrintPhysicalCheck(const CampaignResult& result, std::ostream& out) {
  if (!result.physical) return;
  const PhysicalCheck& p = *result.physical;
  if (p.status == PhysicalStatus::kNotPhysical) PrintWrapped("Error: ", p.message, out);
  if (p.status == PhysicalStatus::kBorderline) PrintWrapped("Warning: ", p.message, out);
}

void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out) {
  const DisplayUnits units = config.units;
  const char* unit = InertiaUnitName(units);
  auto inertia = [&](double kg_m2) { return InertiaToDisplay(kg_m2, units); };
  char line[256];
  const CampaignSummary& s = result.summary;
  // The one cause that fails every aircraft trace comes first, once.
  if (!result.rig_problem.empty()) out << "Error: " << result.rig_problem << "\n";
  PrintPhysicalCheck(result, out);  // a body that cannot exist: said before its numbers
  // Attitudes whose logs look like two set-ups: the most important warning, before the numbers.
  for (const std::string& w : result.setup_warnings) PrintWrapped("Warning: ", w, out);
  if (result.ellipse_fit) {
    const EllipseResult& e = *result.ellipse_fit;
    // Each moment: its std (stat: the trials' scatter, the rig offset) and the total, which adds
    // the common-mode scale terms (pipeline/records/total_uncertainty.h).
    const double rel = result.common_mode_relative_std;
    out << "Table 2 (" << unit << ", +- 1 std: stat, then total with the common-mode terms):\n";
    auto row = [&](const char* name, const EllipseEstimate& est) {
      if (!est.defined) {
        std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", name);
      } else {
        std::snprintf(line, sizeof(line), "  %-5s  %#10.5g +- %#.2g (stat) +- %#.2g (total)\n",
                      name, inertia(est.value), inertia(est.std),
                      inertia(WithCommonModeScale(est.value, est.std, rel)));
      }
      out << line;
    };
    row("I_x", e.ix);
    row("I_z", e.iz);
    row("I_xz", e.ixz);
    if (e.tau_deg.defined) {
      std::snprintf(line, sizeof(line),
                    "  %-5s  %10.4f +- %.4f deg (stat = total: a scale leaves tau)\n", "tau",
                    e.tau_deg.value, e.tau_deg.std);
    } else {
      std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", "tau");
    }
    out << line;
    if (std::isfinite(rel)) {
      std::snprintf(line, sizeof(line),
                    "  (total: stat and +- %.2f %% common to all moments in quadrature, from the "
                    "uncertainties of %s, the masses and the gyro scale)\n",
                    100.0 * rel,
                    result.calibration           ? "the rig calibration"
                    : result.common_mode_assumed ? "L, D (assumed +-1 mm), g"
                                                 : "L, D, g");
      out << line;
    }
    for (const std::string& w : e.warnings) {
      if (!e.physical && w.rfind("non-physical", 0) == 0) out << "Warning: " << w << "\n";
    }
    std::snprintf(line, sizeof(line),
                  "Table 1: raw sigma %#.5g %s, CV %.4f %%, regression RMSE %#.5g %s\n",
                  inertia(result.raw_sigma_kg_m2), unit, result.cv_percent,
                  inertia(result.regression_rmse_kg_m2), unit);
    out << line;
  } else if (IsPlanarCampaign(result.traces)) {
    out << s.ellipse_message << "\n";
  }
  // The inertia tensor when it was fitted as one (rolls, or too few pitch angles for the ellipse).
  if (result.tensor_fit) {
    PrintTensorSummary(config, result, out);
  } else if (!IsPlanarCampaign(result.traces)) {
    out << s.tensor_message << "\n";
  }
  if (std::isfinite(result.rig_inertia_kg_m2)) {
    std::snprintf(line, sizeof(line), "Rig inertia %#.5g +- %.2g %s",
                  inertia(result.rig_inertia_kg_m2), inertia(result.rig_inertia_std_kg_m2), unit);
    out << line;
    if (config.rig_inertia.kind == RigInertiaSpec::Kind::kTare) {
      out << " (mean of " << result.rig_tare_n << " tare logs)";
    }
    out << "\n";
  }
  if (result.calibration) {  // rig.calibration: the geometry every fit used
    const RigCalibrationResult& c = *result.calibration;
    std::snprintf(line, sizeof(line),
                  "Calibration: D^2/L x %.5f +- %.5f (+- %.2f %%, common to all moments): "
                  "D %.5f m effective against %.5f m configured, L %.4f m; %d reference swing%s\n",
                  c.factor, c.factor_std, 100.0 * c.factor_rel_std, c.effective_separation_m,
                  c.nominal_separation_m, c.filar_length_m, c.n_swings, c.n_swings == 1 ? "" : "s");
    out << line;
  }
  int shown = 0, rig_unknown = 0;
  for (const TraceRecord& r : result.traces) {
    if (r.ok()) continue;
    // Traces failed only by the unknown rig inertia: counted in one line, the cause is above.
    if (!result.rig_problem.empty() && r.role == TraceRole::kAircraft &&
        r.message.find(kNoUsableTareLog) != std::string::npos) {
      ++rig_unknown;
      continue;
    }
    if (shown++ == 10) {
      out << "  ...\n";
      break;
    }
    out << "  " << ToString(r.status) << ": " << r.message << "\n";
  }
  if (!result.assumed_inputs_note.empty()) out << result.assumed_inputs_note << "\n";
  if (rig_unknown > 0) {
    out << "  error: " << rig_unknown << " aircraft trace" << (rig_unknown == 1 ? "" : "s")
        << ": rig inertia unknown (no usable tare log, see the first line)\n";
  }
  std::snprintf(line, sizeof(line),
                "Traces: %d ok, %d rejected, %d error (of %d); fits run %d, reused from cache %d; "
                "wall time %.2f s\n",
                s.n_ok, s.n_rejected, s.n_error, s.n_traces, s.n_fitted, s.n_reused, s.wall_s);
  out << line;
  if (s.n_cache_refused > 0) {
    out << "Warning: " << s.n_cache_refused << " cache entr"
        << (s.n_cache_refused == 1 ? "y was" : "ies were")
        << " damaged or not theirs and refitted (see the warnings above)\n";
  }
}

}  // namespace bifilar
