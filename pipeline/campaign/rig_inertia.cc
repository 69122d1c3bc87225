#include "pipeline/campaign/rig_inertia.h"

#include <cmath>
#include <cstdio>
#include <iterator>

namespace bifilar {

bool RigInertiaAt(const CampaignConfig& config, double tare_mean_kg_m2, double tare_std_kg_m2,
                  double pitch_deg, double* inertia_kg_m2, double* std_kg_m2, std::string* why) {
  const RigInertiaSpec& spec = config.rig_inertia;
  switch (spec.kind) {
    case RigInertiaSpec::Kind::kValue:
      *inertia_kg_m2 = spec.inertia_kg_m2;
      *std_kg_m2 = spec.inertia_std_kg_m2;
      return true;
    case RigInertiaSpec::Kind::kTare:
      if (!std::isfinite(tare_mean_kg_m2)) {
        *why = std::string(kNoUsableTareLog) + ": the rig inertia is unknown";
        return false;
      }
      *inertia_kg_m2 = tare_mean_kg_m2;
      *std_kg_m2 = std::isfinite(tare_std_kg_m2) ? tare_std_kg_m2 : 0.0;
      return true;
    case RigInertiaSpec::Kind::kTable: {
      const auto& table = spec.table_kg_m2;
      if (!std::isfinite(pitch_deg)) {
        *why = "pitch unknown: cannot look up the rig inertia table";
        return false;
      }
      auto hi = table.lower_bound(pitch_deg - 1e-9);
      if (hi != table.end() && std::abs(hi->first - pitch_deg) <= 1e-9) {
        *inertia_kg_m2 = hi->second;
      } else if (hi == table.begin() || hi == table.end()) {
        char buffer[160];
        std::snprintf(buffer, sizeof(buffer),
                      "pitch %.3g deg is outside the rig inertia table [%.3g, %.3g] deg", pitch_deg,
                      table.begin()->first, table.rbegin()->first);
        *why = buffer;
        return false;
      } else {
        auto lo = std::prev(hi);
        const double f = (pitch_deg - lo->first) / (hi->first - lo->first);
        *inertia_kg_m2 = lo->second + f * (hi->second - lo->second);
      }
      *std_kg_m2 = spec.inertia_std_kg_m2;
      return true;
    }
  }
  return false;
}

}  // namespace bifilar
