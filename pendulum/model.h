// The bifilar pendulum equations of motion: docs/physics.md §2.
//
// Conventions: psi is the yaw angle (rad) about the down vertical through the CG, rate = psi'
// (rad/s). m is the whole suspended mass (aircraft + rig + IMU), I the whole suspended inertia
// about the swing axis. Lengths in metres, masses in kilograms, SI throughout.
//
//   h(psi)  = L - sqrt(L^2 - (D^2/2)(1 - cos psi))           rise of the body as it twists
//   full:    (I + m h'^2) psi'' + m h' h'' psi'^2 + K_D psi'|psi'| + C psi' + m g h' = 0
//   jardin:   I psi'' + K_D psi'|psi'| + C psi' + m g h'(psi) = 0
//   linear:   I psi'' + K_D psi'|psi'| + C psi' + m g D^2/(4 L) psi = 0   (small-angle formula)
#pragma once

#include <string>
#include <vector>

#include "base/units.h"

namespace bifilar {

enum class PendulumModel { kFull, kJardin, kLinear };

// "full", "jardin", "linear".
const char* ToString(PendulumModel model);
// Parses the names above; returns false (and leaves *model unchanged) for anything else.
bool ParsePendulumModel(const std::string& name, PendulumModel* model);
// The names in table order, for CLI choices: {"full", "jardin", "linear"}.
const std::vector<std::string>& PendulumModelNames();
// The allowed values for messages and help: "full, jardin or linear".
std::string PendulumModelAllowedValues();

// Suspension geometry and the suspended mass.
struct RigGeometry {
  double filar_length_m = 0.0;      // L, wire length (m); > 0 and > D (wires never go slack).
  double filar_separation_m = 0.0;  // D, distance between the wires (m); > 0.
  double mass_kg = 0.0;             // m, whole suspended mass (kg); > 0.
  double gravity_mps2 = kStandardGravityMps2;  // g, local gravity (m/s^2); > 0.

  // True when every field is finite and in range; otherwise names the field and the range.
  bool Check(std::string* why) const;
};

// L > D, the one check of it and its one message (the config, the simulator and RigGeometry all
// use it): true when filar_length_m > filar_separation_m; otherwise *why (if not null) says
// "filar_separation_m (D) = .. m is not below filar_length_m (L) = .. m (the wires would go
// slack); allowed D < L". Callers prefix their file, line and key. NaN fails.
bool CheckSeparationBelowLength(double filar_length_m, double filar_separation_m, std::string* why);

// The unknowns of one swing that enter the equation of motion.
struct PendulumParams {
  double inertia_kg_m2 = 0.0;              // I, whole suspended inertia (kg m^2); > 0.
  double drag_coeff_kg_m2 = 0.0;           // K_D, quadratic (aerodynamic) damping; >= 0.
  double viscous_coeff_kg_m2_per_s = 0.0;  // C, linear (viscous) damping; >= 0.

  bool Check(std::string* why) const;
};

// h(psi), h'(psi), h''(psi) of docs/physics.md §2 (m, m/rad, m/rad^2).
double RiseHeight(const RigGeometry& geometry, double angle_rad);
double RiseSlope(const RigGeometry& geometry, double angle_rad);
double RiseCurvature(const RigGeometry& geometry, double angle_rad);

// psi'' and its partial derivatives with respect to the state and the parameters: everything
// the forward-sensitivity equations need.
struct AccelerationPartials {
  double accel_rad_per_s2 = 0.0;  // psi''
  double d_angle = 0.0;           // d psi'' / d psi
  double d_rate = 0.0;            // d psi'' / d psi'
  double d_inertia = 0.0;         // d psi'' / d I
  double d_drag = 0.0;            // d psi'' / d K_D
  double d_viscous = 0.0;         // d psi'' / d C
};

double AngularAcceleration(PendulumModel model, const RigGeometry& geometry,
                           const PendulumParams& params, double angle_rad, double rate_rad_per_s);
AccelerationPartials AngularAccelerationPartials(PendulumModel model, const RigGeometry& geometry,
                                                 const PendulumParams& params, double angle_rad,
                                                 double rate_rad_per_s);

// Total mechanical energy (J) of the model: kinetic + potential, conserved when K_D = C = 0.
double MechanicalEnergy(PendulumModel model, const RigGeometry& geometry,
                        const PendulumParams& params, double angle_rad, double rate_rad_per_s);

// Small-angle undamped period T = 2 pi sqrt(4 I L / (m g D^2)) (s), and its inverse
// I = m g D^2 T^2 / (16 pi^2 L) (kg m^2).
double SmallAnglePeriod(const RigGeometry& geometry, double inertia_kg_m2);
double InertiaFromSmallAnglePeriod(const RigGeometry& geometry, double period_s);

}  // namespace bifilar
