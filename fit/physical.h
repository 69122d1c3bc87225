// Is a fitted body one that can exist? The moments of inertia of any rigid body satisfy
//     I_a + I_b >= I_c for every permutation (the triangle inequalities: I_a + I_b - I_c =
//     2 integral c^2 dm >= 0 in the body's principal axes, and about any three orthogonal axes),
//     and the tensor is positive definite (every principal moment > 0).
// CheckPhysical tests each inequality against the components' combined std: its margin
// (e.g. I_y' + I_z' - I_x' in principal axes) has a first-order std from the covariance, and
// z = margin / std. A margin below -t std (t the one-sided quantile of `probability`, normal or
// Student's t with the fit's dof) is not physical; a negative margin above it is borderline (the
// estimate breaks the inequality within its noise, as a flat body's I_x + I_y - I_z = 2 int z^2
// dm ~ 0 may); else physical. Which checks apply follows from what the design determines:
//   - the full tensor: the three triangle inequalities of the principal moments and the smallest
//     principal moment > 0;
//   - Ixx, Iyy, Izz without the products (three-axis campaigns): the triangle inequalities of the
//     diagonal (true in any axes);
//   - I_x, I_z, I_xz only (the planar ellipse): I_x > 0, I_z > 0 and the x-z section positive
//     definite (its smaller principal moment > 0); the triangle inequalities need I_y.
// docs/method.md, "Is the body physical?".
#pragma once

#include <array>
#include <limits>
#include <string>

#include "fit/ellipse.h"
#include "fit/physical_check.h"
#include "fit/tensor_components.h"

namespace bifilar {

struct PhysicalOptions {
  // One-sided probability of a healthy body (margin >= 0) being marked not physical, at a margin
  // of exactly 0 (a flat body); bodies with a margin flag less. (0, 0.5). Default 0.001: z <= -3.09
  // with a normal std.
  double probability = 0.001;
  // Degrees of freedom of the stds (the fit's; inf: normal). > 0. Default inf.
  double dof = std::numeric_limits<double>::infinity();
};

// The checks on the six components (Ixx, Iyy, Izz, Ixy, Ixz, Iyz, products positive; NaN where
// not determined) and their covariance (kg^2 m^4). Message without an attitude.
PhysicalCheck CheckPhysical(
    const std::array<double, kTensorComponents>& components,
    const std::array<std::array<double, kTensorComponents>, kTensorComponents>& covariance,
    const PhysicalOptions& options);

// The planar ellipse's checks (I_x, I_z, I_xz and their covariance from (A, B, C)).
PhysicalCheck CheckPhysicalEllipse(const EllipseResult& fit, const PhysicalOptions& options);

// The check's message from its fields (the attitude and the likely causes when flagged);
// CheckPhysical sets it, a caller that names the attitude sets it again.
std::string PhysicalCheckMessage(const PhysicalCheck& check);

}  // namespace bifilar
