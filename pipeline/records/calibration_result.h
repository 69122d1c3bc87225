// What rig.calibration found (pipeline/campaign/calibration.h runs it): a record of its own, so
// that the campaign result and results.json need not include the calibration itself.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "pipeline/config/config.h"

namespace bifilar {

// What the calibration found. All inertias are of the final iteration (the calibrated geometry).
struct RigCalibrationResult {
  bool applied = false;
  double factor = 1.0;                  // k = effective D^2/L over the configured D^2/L
  double factor_std = 0.0;              // std of k
  double factor_rel_std = 0.0;          // std(k) / k, from the three parts below in quadrature
  double rel_std_reference = 0.0;       // from reference_inertia_std_kg_m2
  double rel_std_swings = 0.0;          // from the reference swings' scatter (or their fits' std)
  double rel_std_rig = 0.0;             // from the rig inertia's std (tare mean or configured std)
  double filar_length_m = 0.0;          // L, as configured (kept)
  double nominal_separation_m = 0.0;    // D as configured
  double effective_separation_m = 0.0;  // D sqrt(k)
  double nominal_d2_over_l_m = 0.0, effective_d2_over_l_m = 0.0;
  double reference_inertia_kg_m2 = 0.0, reference_inertia_std_kg_m2 = 0.0;
  double reference_mass_kg = 0.0;
  int n_swings = 0;                     // reference swings (every one must fit)
  double swings_total_kg_m2 = NAN;      // mean fitted rig + reference inertia
  double swings_total_std_kg_m2 = NAN;  // its standard error (MeanAndStandardError)
  double swings_scatter_kg_m2 = NAN;    // sample std between the swings (n >= 2)
  std::string rig_inertia_source;       // "value", "table" or "tare"
  double rig_inertia_kg_m2 = NAN, rig_inertia_std_kg_m2 = NAN;  // as used
  int iterations = 0;                                           // fitting rounds
  std::vector<std::string> logs;  // the reference swings as shown to the user
  std::vector<std::string> warnings;
  std::vector<std::string> cache_keys;  // every fit of every round (the campaign keeps them)

  GeometryCalibration Applied() const;  // what the fits use: {applied, factor, factor_rel_std}
  std::string BriefReport() const;      // one line: factor +- std, effective against nominal D
};

}  // namespace bifilar
