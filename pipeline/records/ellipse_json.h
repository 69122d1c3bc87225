// JSON form of an ellipse-of-inertia result (SI, tau in deg), shared by `bifilar ellipse --json`
// and the campaign's results.json. Quantities that are undefined (tau, I_xp, I_zp when I_x ~ I_z)
// or not finite are null, with the reason in "warnings"; never NaN.
#pragma once

#include <ostream>

#include <nlohmann/json.hpp>

#include "fit/ellipse.h"

namespace bifilar {

// Keys: Ix_kg_m2, Iz_kg_m2, Ixz_kg_m2, tau_deg, Ixp_kg_m2, Izp_kg_m2, each also with _std and
// _ci95 ([lo, hi] at the fit's confidence) appended; rmse_kg_m2, n_points, n_angles, tau_defined,
// covariance, dof, variance_factor, confidence_interval_method; fits (linear_ls, nelder_mead,
// ceres summaries), table1, table2, angles (per-angle stats), residuals, outliers, naca,
// warnings, time_s.
// The result as JSON; with_residuals false leaves "residuals" empty (one row per point: a
// million-point table would hold a DOM of a gigabyte).
nlohmann::json EllipseResultToJson(const EllipseResult& result, bool with_residuals = true);

// Writes EllipseResultToJson(result) plus the keys of `extra` to `out`, the residuals streamed
// row by row: memory stays proportional to the points, not to a JSON tree of them.
void WriteEllipseResultJson(const EllipseResult& result, const nlohmann::json& extra,
                            std::ostream& out);

// The plan: n_points and the predicted *_std of the six quantities.
nlohmann::json EllipsePlanToJson(const EllipsePlan& plan);

}  // namespace bifilar
