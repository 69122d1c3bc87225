// The full inertia tensor from moments measured about swing axes in any body direction.
//
// Conventions: docs/physics.md §3.5 (body x forward, y right wing, z down; the swing axis is the
// down vertical, in body axes n = (-sin theta, sin phi cos theta, cos phi cos theta) for the
// aircraft's pitch theta and roll phi on the rig). Products of inertia are the paper's positive
// ones, I_xy = integral x y dm, I_xz = integral x z dm, I_yz = integral y z dm, so the tensor is
//     J = [[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]]
// and the moment about the unit axis n is linear in the six components:
//     I(n) = n^T J n = nx^2 Ixx + ny^2 Iyy + nz^2 Izz - 2 nx ny Ixy - 2 nx nz Ixz - 2 ny nz Iyz.
//
// The fit follows the axes the design spans (FitTensor): the rank of the design (the rows above,
// one per point, of the nominal directions when given) says which components, or combinations,
// the data determine. Components in the design's row space are fitted by weighted least squares
// (Ceres, over the row-space coordinates, with the closed form by QR as its parity check); the
// others are named as unobservable and reported as such, never as numbers. A full 3-D design
// (rank 6) also gives the principal moments and axes (eigen-decomposition, first-order std), the
// principal axes' Euler angles and the design's condition number. The covariance choices are the
// ellipse's (fit/ellipse.h, EllipseCovariance: points, orientation means, absolute) and the
// intervals a seeded parametric bootstrap. FitTensor runs the steps of fit/tensor_steps.h; this
// header is plain C++ and Eigen-free.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "fit/ellipse.h"  // EllipseCovariance, EllipseSolverSummary
#include "fit/physical_check.h"
#include "fit/tensor_components.h"

namespace bifilar {

// The six components: kTensorComponents, kIxx ... kIyz, TensorComponentName
// (fit/tensor_components.h).

// The swing axis (down vertical) in body axes of an aircraft hung at roll phi and pitch theta
// (deg): (-sin theta, sin phi cos theta, cos phi cos theta).
std::array<double, 3> DownInBodyFromAttitude(double roll_deg, double pitch_deg);
// The moment about the unit axis n (any length: normalised) of the six components.
double TensorMoment(const std::array<double, kTensorComponents>& components,
                    const std::array<double, 3>& n);

// One measured moment about one axis.
struct TensorPoint {
  std::array<double, 3> direction_in_body = {0, 0, 1};  // swing axis used for the fit (any length)
  // The nominal axis (as planned), which decides what the design can observe; all zero = use
  // direction_in_body. Measured directions carry small accidental tilts that would otherwise
  // make a component "observable" with an absurd std.
  std::array<double, 3> nominal_in_body = {0, 0, 0};
  double inertia_kg_m2 = 0.0;  // moment about the axis (kg m^2), > 0
  double std_kg_m2 = 0.0;      // its standard error (kg m^2); 0 or NaN = unknown
  int group = -1;  // orientation group (same nominal attitude); -1: grouped by nominal direction
};

struct TensorOptions {
  // Parametric bootstrap replicates (0: t/normal intervals), as EllipseOptions. Default 2000.
  int bootstrap_replicates = 2000;
  std::uint64_t seed = 1;    // bootstrap seed. Default 1.
  double confidence = 0.95;  // interval level, (0, 1). Default 0.95.
  // kAuto: orientation means (kAngleMeans) when the orientations' means scatter about the fit
  // beyond what their trials scatter (lack-of-fit F test at 5 %: an error shared by the trials
  // of an orientation), else points (more degrees of freedom). Default kAuto.
  EllipseCovariance covariance = EllipseCovariance::kAuto;
  // Points whose nominal axes lie within this angle (deg, sign-free) are one orientation when
  // no group is given; [0, 45). Default 0.5.
  double group_tol_deg = 0.5;
  // Standard uncertainty (kg m^2) of an offset common to every moment (the rig inertia): it
  // moves Ixx, Iyy, Izz together (n^T (c 1) n = c), not the products. >= 0. Default 0.
  double common_offset_std_kg_m2 = 0.0;
  // A singular value of the unit-direction design below this fraction of the largest is a
  // direction the data do not determine. (0, 1). Default 1e-6.
  double rank_tolerance = 1e-6;
  // Weigh each point by 1/(s_i^2 + sigma_a^2 g_i^2), g_i the moment's sensitivity to tilting its
  // axis and sigma_a the attitude scatter solved from the residuals (full designs with stds;
  // designs that are not full: 1/(s_i^2 + (sigma_r I_i)^2), a relative scatter).
  // Default true: a trace fit's std (1e-4 of I) is far below what a 0.5 deg attitude error
  // moves the moment (~1e-3), so the stated stds alone would weigh points almost at random.
  bool attitude_scatter = true;
  // |studentized residual| above this flags an outlier. Default 3.
  double outlier_threshold = 3.0;

  bool Check(std::string* why) const;
};

// One quantity: value, std, interval; observable == false: not determined by the design (no
// number must be printed).
struct TensorEstimate {
  double value = 0.0;
  double std = 0.0;
  double ci_lo = 0.0;
  double ci_hi = 0.0;
  bool observable = true;
  // Degrees of freedom of the interval (inf: normal). Per component: a component fed by an
  // orientation whose logs scatter has that orientation's few, the others keep theirs.
  double dof = std::numeric_limits<double>::infinity();
};

struct TensorPointResidual {
  int index = 0;        // into the input points
  int orientation = 0;  // into TensorResult::orientations
  double inertia_kg_m2 = 0.0;
  double fitted_kg_m2 = 0.0;
  double residual_kg_m2 = 0.0;  // measured - fitted
  double studentized = 0.0;     // internally studentized
  bool outlier = false;
};

// Residual of one orientation: the (weighted) mean of its points against the fit.
struct TensorOrientation {
  std::array<double, 3> nominal_in_body = {0, 0, 1};  // the group's first nominal axis (unit)
  std::vector<int> members;                           // point indices
  double mean_kg_m2 = 0.0;                            // weighted mean of the measured moments
  double fitted_kg_m2 = 0.0;                          // weighted mean of the fitted moments
  double residual_kg_m2 = 0.0;                        // mean - fitted
  double residual_std_kg_m2 = 0.0;  // sqrt(variance factor / weight sum): its expected scatter
  double z = 0.0;                   // residual / residual_std (0 when the std is 0)
  double scatter_kg_m2 = 0.0;       // sample std of the members (0 for one point)
};

struct TensorResult {
  int n_points = 0;
  int n_orientations = 0;
  int rank = 0;           // of the design (6: full 3-D)
  bool weighted = false;  // every point had a std
  // The attitude scatter found in the residuals (deg, TensorOptions::attitude_scatter), 0 when
  // the stated stds explain the scatter or the design is not full.
  double attitude_scatter_deg = 0.0;
  // A design that is not full: the relative scatter of the moments beyond their stds instead
  // (fraction, e.g. 0.002), 0 when the stds explain it.
  double relative_scatter = 0.0;
  // Per orientation (same order as `orientations`), a design that is not full: the relative
  // scatter its points were weighed with. An orientation whose logs scatter beyond the others'
  // (F test, p < 0.01) has its own; the others share relative_scatter. Empty when not used.
  std::vector<double> orientation_relative_scatter;
  bool full = false;              // rank == 6: principal moments and axes below are defined
  double condition_number = 0.0;  // largest / smallest non-zero singular value of the design
  std::array<double, kTensorComponents> design_singular_values = {};  // descending
  EllipseCovariance covariance_used = EllipseCovariance::kPointResiduals;
  double variance_factor = 1.0;
  double dof = 0.0;           // of the intervals (inf for absolute)
  double reduced_chi2 = 0.0;  // chi^2 / (n - rank) of the points
  double rmse_kg_m2 = 0.0;

  // Ixx, Iyy, Izz, Ixy, Ixz, Iyz (products positive convention), kg m^2.
  std::array<TensorEstimate, kTensorComponents> components;
  // Their covariance (kg^2 m^4), rows/columns of unobservable components NaN.
  std::array<std::array<double, kTensorComponents>, kTensorComponents> covariance = {};
  std::vector<std::string> unobservable;  // component names, in order
  // Combinations the design determines although none of their components alone is, e.g.
  // "0.5 Ixx + 0.5 Iyy - Ixy" (empty when every determined direction is a component).
  std::vector<std::string> observable_combinations;

  // Principal moments ascending with std and interval, axes as unit vectors in body axes (row k
  // is the axis of moment k, sign: largest component positive), each axis' direction std (deg,
  // the rms angle it may turn). Only when `full`.
  std::array<TensorEstimate, 3> principal_moments;
  std::array<std::array<double, 3>, 3> principal_axes = {};
  std::array<double, 3> principal_axes_std_deg = {};
  // Euler angles (deg, aerospace Z-Y-X: yaw, then pitch, then roll) of the rotation from body to
  // principal axes, with each principal axis matched to the nearest body axis (x', y', z') and
  // signed along it; body_from_principal = Rz(yaw) Ry(pitch) Rx(roll). In the planar case pitch
  // = -tau. Std by first-order propagation.
  std::array<TensorEstimate, 3> euler_deg;                     // roll, pitch, yaw
  std::array<double, 3> principal_moments_matched_kg_m2 = {};  // about x', y', z'

  std::vector<TensorPointResidual> residuals;
  std::vector<TensorOrientation> orientations;
  int n_outliers = 0;

  // Can a body have these moments (fit/physical.h): the triangle inequalities and positive
  // definiteness against the combined std, at the fit's dof. When flagged or borderline,
  // `physical.orientation` is the orientation whose removal restores the inequality most (a
  // refit without each in turn) or, when no refit determines the same components, the one nearest
  // the axis of the largest moment of the broken inequality; `physical.attitude` names its axis
  // (a campaign names the roll and pitch instead).
  PhysicalCheck physical;

  EllipseSolverSummary ceres;                        // the primary fit ("ceres")
  double closed_form_max_relative_difference = 0.0;  // Ceres vs closed form (QR), parity
  int bootstrap_replicates = 0;
  std::vector<std::string> warnings;
  double time_s = 0.0;

  bool IsUsable() const;            // at least one component with a finite std
  std::string BriefReport() const;  // the tensor with stds, unobservable components, warnings
};

// Fits the tensor. False with *why on bad input (no points, a zero direction, non-finite or
// non-positive inertia, negative std, bad options), when no component at all is observable
// (*why names them), or when nothing is left to estimate the scatter (n = rank without stds).
bool FitTensor(const std::vector<TensorPoint>& points, const TensorOptions& options,
               TensorResult* result, std::string* why);

}  // namespace bifilar
