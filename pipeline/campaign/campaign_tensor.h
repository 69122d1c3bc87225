// The campaign's inertia tensor (issue 17): which axes the campaign spans decides the fit.
//   - No log has a non-zero nominal roll (a pitch-only rig): the ellipse of inertia as always
//     (campaign.cc, bit for bit unchanged); the tensor section repeats its I_x, I_z, I_xz as
//     Ixx, Izz, Ixz and names Iyy, Ixy, Iyz unobservable. When the ellipse could not be fitted
//     (too few angles), the tensor fit gives what the angles do determine.
//   - Otherwise: the tensor fit (fit/tensor.h) of every ok aircraft trace about its swing axis
//     n = (-sin pitch, sin roll cos pitch, cos roll cos pitch) (docs/physics.md §3.5), with the
//     attitude used (nominal or measured, runs.pitch_source) for n and the nominal one for what
//     the design can observe; the rig's std as a common offset, the ellipse's covariance,
//     bootstrap and seed settings.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/config/config.h"
#include "pipeline/records/campaign_result.h"

namespace bifilar {

// True when no ok aircraft trace has a non-zero nominal roll.
bool IsPlanarCampaign(const std::vector<TraceRecord>& traces);

// Fills result->tensor (the results.json section), tensor_fit, tensor_figure and the summary's
// tensor_fitted/tensor_message; runs after the ellipse step. `figures_dir` empty: no figure;
// `record_figure` is called with the figure's name inside figures_dir before it is written.
void FitCampaignTensor(const CampaignConfig& config, const std::string& figures_dir,
                       const std::function<void(const std::string&)>& record_figure,
                       CampaignResult* result);

// The console's tensor table (campaign_summary.cc): the components with their std (names of the
// unobservable ones), principal moments, axes and Euler angles when full, and one row per
// orientation with its logs, total and aircraft moments and residual.
void PrintTensorSummary(const CampaignConfig& config, const CampaignResult& result,
                        std::ostream& out);

}  // namespace bifilar
