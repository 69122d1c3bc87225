#include "pipeline/records/calibration_result.h"

#include <cstdio>

namespace bifilar {

GeometryCalibration RigCalibrationResult::Applied() const {
  GeometryCalibration g;
  g.applied = applied;
  g.factor = factor;
  g.factor_rel_std = factor_rel_std;
  return g;
}

std::string RigCalibrationResult::BriefReport() const {
  char buffer[400];
  std::snprintf(buffer, sizeof(buffer),
                "calibration: D^2/L factor k = %.5f +- %.5f (%.2f %%) from %d reference swing%s: "
                "effective D = %.5f m against %.5f m configured (L = %.4f m kept)",
                factor, factor_std, 100.0 * factor_rel_std, n_swings, n_swings == 1 ? "" : "s",
                effective_separation_m, nominal_separation_m, filar_length_m);
  return buffer;
}

}  // namespace bifilar
