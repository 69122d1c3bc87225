#include <cmath>
#include <cstdio>
#include <ostream>

#include "pipeline/campaign.h"
#include "pipeline/campaign_tensor.h"

namespace bifilar {

void PrintCampaignSummary(const CampaignConfig& config, const CampaignResult& result,
                          std::ostream& out) {
  const DisplayUnits units = config.units;
  const char* unit = InertiaUnitName(units);
  auto inertia = [&](double kg_m2) { return InertiaToDisplay(kg_m2, units); };
  char line[256];
  const CampaignSummary& s = result.summary;
  if (result.ellipse_fit) {
    const EllipseResult& e = *result.ellipse_fit;
    out << "Table 2 (" << unit << ", +- 1 std):\n";
    auto row = [&](const char* name, const EllipseEstimate& est) {
      if (!est.defined) {
        std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", name);
      } else {
        std::snprintf(line, sizeof(line), "  %-5s  %#10.5g +- %.2g\n", name, inertia(est.value),
                      inertia(est.std));
      }
      out << line;
    };
    row("I_x", e.ix);
    row("I_z", e.iz);
    row("I_xz", e.ixz);
    if (e.tau_deg.defined) {
      std::snprintf(line, sizeof(line), "  %-5s  %10.4f +- %.4f deg\n", "tau", e.tau_deg.value,
                    e.tau_deg.std);
    } else {
      std::snprintf(line, sizeof(line), "  %-5s  ill-defined (I_x ~ I_z)\n", "tau");
    }
    out << line;
    if (std::isfinite(result.systematic_relative_std) && result.systematic_relative_std > 0) {
      std::snprintf(
          line, sizeof(line),
          "  (+- %.2f %% systematic, common to all moments, from the configured uncertainties)\n",
          100.0 * result.systematic_relative_std);
      out << line;
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
  int shown = 0;
  for (const TraceRecord& r : result.traces) {
    if (r.ok()) continue;
    if (shown++ == 10) {
      out << "  ...\n";
      break;
    }
    out << "  " << ToString(r.status) << ": " << r.message << "\n";
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
