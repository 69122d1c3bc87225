// The result of checking fitted moments against what a rigid body can have (fit/physical.h,
// CheckPhysical): each inequality's margin with its std and z, the worst one, and a status.
// Plain C++ (no Eigen), so records/, report/, export and Python can read it.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace bifilar {

// physical: every inequality holds or is broken by less than nothing (z >= 0);
// borderline: the fitted moments break one, but within the noise (0 > z > threshold);
// not_physical: broken beyond the noise (z <= threshold, PhysicalOptions);
// not_checked: the components the checks need are not all determined.
enum class PhysicalStatus { kNotChecked, kPhysical, kBorderline, kNotPhysical };
const char* PhysicalStatusName(PhysicalStatus status);  // "physical", "borderline", ...

// One inequality of a body, written margin >= 0 (e.g. "I_y' + I_z' - I_x'", primes: principal
// axes named by the body axis nearest each).
struct PhysicalInequality {
  std::string name;
  double margin_kg_m2 = NAN;
  double std_kg_m2 = NAN;  // first-order, from the components' covariance
  double z = NAN;          // margin / std (+-inf when the std is 0)
  // The axis (body axes, unit) of the moment the inequality subtracts (I_c of I_a + I_b - I_c;
  // the moment itself for a positivity check): the one whose swings a break most likely comes
  // from when no refit can tell.
  std::array<double, 3> against_axis = {0, 0, 0};
};

struct PhysicalCheck {
  PhysicalStatus status = PhysicalStatus::kNotChecked;
  // What was checked: "principal moments" (a full tensor), "diagonal moments" (Ixx, Iyy, Izz
  // without the products: the triangle inequalities hold in any axes), "x-z ellipse" (a planar
  // campaign: I_x, I_z, I_xz only), "" when not checked.
  std::string checked;
  std::vector<PhysicalInequality> inequalities;
  int worst = -1;            // index of the smallest z, -1 when none
  double threshold_z = NAN;  // z at or below which the result is not physical
  // The attitude whose logs drive a break (filled by the caller, which knows the attitudes:
  // the one whose removal restores the inequality, or, when no refit is possible, the one that
  // measures the largest moment of the broken inequality). Empty when none is named.
  std::string attitude;
  int orientation = -1;             // the tensor fit's orientation of that attitude, -1: none
  double z_without_attitude = NAN;  // the worst z of the refit without it (NaN: no refit)
  std::string message;              // one paragraph for the console, the report and results.json

  bool Flagged() const { return status == PhysicalStatus::kNotPhysical; }
  const PhysicalInequality* Worst() const {
    return worst >= 0 && worst < static_cast<int>(inequalities.size()) ? &inequalities[worst]
                                                                       : nullptr;
  }
};

}  // namespace bifilar
