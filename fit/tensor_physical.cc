// The physical check of a tensor fit (fit/physical.h) and the orientation that drives a break:
// the one whose removal restores the inequality most (a refit without it), or, when no refit
// determines the same components (a three-axis campaign: each axis alone measures its moment),
// the one nearest the axis of the largest moment of the broken inequality, whose swings an
// inflated moment most likely comes from (a rig error scales a moment: the largest needs the
// smallest relative change to restore I_a + I_b >= I_c).
#include <cmath>

#include "base/text_format.h"
#include "fit/physical.h"
#include "fit/tensor_steps.h"

namespace bifilar {
namespace tensor {
namespace {

PhysicalCheck CheckOf(const TensorResult& r) {
  std::array<double, kTensorComponents> c;
  for (int k = 0; k < kTensorComponents; ++k) c[k] = r.components[k].value;
  PhysicalOptions o;
  if (std::isfinite(r.dof) && r.dof > 0) o.dof = r.dof;
  return CheckPhysical(c, r.covariance, o);
}

std::string AxisText(const std::array<double, 3>& n) {
  return "the axis (" + Fmt("%+.3f", n[0]) + ", " + Fmt("%+.3f", n[1]) + ", " + Fmt("%+.3f", n[2]) +
         ")";
}

}  // namespace

void CheckTensorPhysical(const std::vector<TensorPoint>& points, const TensorOptions& options,
                         TensorResult* result) {
  TensorResult& r = *result;
  r.physical = CheckOf(r);
  PhysicalCheck& check = r.physical;
  if (check.status != PhysicalStatus::kNotPhysical && check.status != PhysicalStatus::kBorderline) {
    return;
  }
  if (r.orientations.size() < 2) return;
  TensorOptions quick = options;
  quick.bootstrap_replicates = 0;
  int best = -1;
  double best_z = -std::numeric_limits<double>::infinity();
  for (size_t g = 0; g < r.orientations.size(); ++g) {
    std::vector<TensorPoint> rest;
    std::vector<bool> drop(points.size(), false);
    for (int i : r.orientations[g].members) drop[i] = true;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!drop[i]) rest.push_back(points[i]);
    }
    TensorResult refit;
    std::string why;
    if (rest.empty() || !FitTensorOnce(rest, quick, &refit, &why)) continue;
    const PhysicalCheck without = CheckOf(refit);
    if (without.checked != check.checked || without.Worst() == nullptr) continue;
    if (without.Worst()->z > best_z) {
      best_z = without.Worst()->z;
      best = static_cast<int>(g);
    }
  }
  if (best >= 0) {
    check.z_without_attitude = best_z;
  } else {
    // No refit sees the same components: the orientation nearest the subtracted moment's axis.
    const std::array<double, 3>& a = check.Worst()->against_axis;
    double best_dot = -1.0;
    for (size_t g = 0; g < r.orientations.size(); ++g) {
      const std::array<double, 3>& n = r.orientations[g].nominal_in_body;
      const double dot = std::fabs(a[0] * n[0] + a[1] * n[1] + a[2] * n[2]);
      if (dot > best_dot) {
        best_dot = dot;
        best = static_cast<int>(g);
      }
    }
  }
  check.orientation = best;
  if (best >= 0) check.attitude = AxisText(r.orientations[best].nominal_in_body);
  check.message = PhysicalCheckMessage(check);
}

}  // namespace tensor
}  // namespace bifilar
