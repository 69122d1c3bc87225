// The bifilar pendulum equations of motion: docs/physics.md §2 (see model.h).
#include "pendulum/model.h"

#include <cmath>
#include <sstream>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/units.h"

namespace bifilar {
namespace {

// Everything about the rise h(psi) that the models need, computed once:
//   s = sqrt(L^2 - (D^2/2)(1 - cos psi)),  k = D^2/4
//   h   = L - s
//   h'  = k sin psi / s
//   h'' = k [cos psi / s + k sin^2 psi / s^3]
//   h''' = -k sin psi / s + 3 k^2 sin psi cos psi / s^3 + 3 k^3 sin^3 psi / s^5
// (ds/dpsi = -k sin psi / s.) L > D guarantees s^2 >= L^2 - D^2 > 0.
struct Rise {
  double h = 0.0, d1 = 0.0, d2 = 0.0, d3 = 0.0;
};

Rise ComputeRise(const RigGeometry& g, double psi, bool want_d3) {
  const double L = g.filar_length_m;
  const double k = 0.25 * g.filar_separation_m * g.filar_separation_m;
  // One sincos of psi/2: sin psi = 2 sin cos, cos psi = 1 - 2 sin^2, and
  // 1 - cos psi = 2 sin^2(psi/2) is accurate for small psi.
  const double half = std::sin(0.5 * psi);
  const double half_c = std::cos(0.5 * psi);
  const double sn = 2.0 * half * half_c;
  const double one_minus_cos = 2.0 * half * half;
  const double cs = 1.0 - one_minus_cos;
  const double s2 = L * L - 2.0 * k * one_minus_cos;
  const double s = std::sqrt(s2);
  const double inv_s = 1.0 / s;
  const double inv_s3 = inv_s / s2;
  Rise r;
  // h = L - s = (L^2 - s^2) / (L + s), without cancellation for small angles.
  r.h = 2.0 * k * one_minus_cos / (L + s);
  r.d1 = k * sn * inv_s;
  r.d2 = k * (cs * inv_s + k * sn * sn * inv_s3);
  if (want_d3) {
    const double inv_s5 = inv_s3 / s2;
    r.d3 =
        -k * sn * inv_s + 3.0 * k * k * sn * cs * inv_s3 + 3.0 * k * k * k * sn * sn * sn * inv_s5;
  }
  return r;
}

// Linear (small-angle) stiffness per unit mass g D^2 / (4 L) (m^2/s^2 per rad).
double LinearStiffnessPerMass(const RigGeometry& g) {
  return g.gravity_mps2 * g.filar_separation_m * g.filar_separation_m / (4.0 * g.filar_length_m);
}

}  // namespace

namespace {

// The one table of pendulum models (Ceres types.h style): config `model`, --model, JSON.
constexpr EnumName<PendulumModel> kPendulumModelNames[] = {
    {PendulumModel::kFull, "full"},
    {PendulumModel::kJardin, "jardin"},
    {PendulumModel::kLinear, "linear"},
};

}  // namespace

const char* ToString(PendulumModel model) { return EnumToString(kPendulumModelNames, model); }

bool ParsePendulumModel(const std::string& name, PendulumModel* model) {
  return ParseEnum(kPendulumModelNames, name, model);
}

const std::vector<std::string>& PendulumModelNames() {
  static const std::vector<std::string> names = EnumNames(kPendulumModelNames);
  return names;
}

std::string PendulumModelAllowedValues() { return EnumAllowedValues(kPendulumModelNames); }

bool CheckSeparationBelowLength(double filar_length_m, double filar_separation_m,
                                std::string* why) {
  if (filar_separation_m < filar_length_m) return true;
  CheckFailure f;
  CheckFail(
      "filar_separation_m (D)", filar_separation_m,
      "< filar_length_m (L) = " + FormatCheckValue(filar_length_m) + " (the wires would go slack)",
      &f);
  return FailWith(f, why);
}

bool RigGeometry::Check(std::string* why) const {
  CheckFailure f;
  if (!CheckFiniteGt("filar_length_m (L)", filar_length_m, 0, &f) ||
      !CheckFiniteGt("filar_separation_m (D)", filar_separation_m, 0, &f)) {
    return FailWith(f, why);
  }
  if (!CheckSeparationBelowLength(filar_length_m, filar_separation_m, why)) return false;
  return (CheckFiniteGt("mass_kg (m)", mass_kg, 0, &f) &&
          CheckFiniteGt("gravity_mps2 (g)", gravity_mps2, 0, &f)) ||
         FailWith(f, why);
}

bool PendulumParams::Check(std::string* why) const {
  CheckFailure f;
  return (CheckFiniteGt("inertia_kg_m2 (I)", inertia_kg_m2, 0, &f) &&
          CheckFiniteGe("drag_coeff_kg_m2 (K_D)", drag_coeff_kg_m2, 0, &f) &&
          CheckFiniteGe("viscous_coeff_kg_m2_per_s (C)", viscous_coeff_kg_m2_per_s, 0, &f)) ||
         FailWith(f, why);
}

double RiseHeight(const RigGeometry& geometry, double angle_rad) {
  return ComputeRise(geometry, angle_rad, false).h;
}

double RiseSlope(const RigGeometry& geometry, double angle_rad) {
  return ComputeRise(geometry, angle_rad, false).d1;
}

double RiseCurvature(const RigGeometry& geometry, double angle_rad) {
  return ComputeRise(geometry, angle_rad, false).d2;
}

double AngularAcceleration(PendulumModel model, const RigGeometry& geometry,
                           const PendulumParams& params, double angle_rad, double rate_rad_per_s) {
  const double m = geometry.mass_kg;
  const double I = params.inertia_kg_m2;
  const double w = rate_rad_per_s;
  const double damping =
      params.drag_coeff_kg_m2 * w * std::abs(w) + params.viscous_coeff_kg_m2_per_s * w;
  switch (model) {
    case PendulumModel::kFull: {
      const Rise r = ComputeRise(geometry, angle_rad, false);
      return -(m * r.d1 * r.d2 * w * w + damping + m * geometry.gravity_mps2 * r.d1) /
             (I + m * r.d1 * r.d1);
    }
    case PendulumModel::kJardin: {
      const Rise r = ComputeRise(geometry, angle_rad, false);
      return -(damping + m * geometry.gravity_mps2 * r.d1) / I;
    }
    case PendulumModel::kLinear:
      return -(damping + m * LinearStiffnessPerMass(geometry) * angle_rad) / I;
  }
  return 0.0;
}

// With psi'' = -N / M (M the effective inertia, N the remaining terms):
//   d psi''/dx = -(dN/dx + psi'' dM/dx) / M.
// d(w|w|)/dw = 2|w|.
AccelerationPartials AngularAccelerationPartials(PendulumModel model, const RigGeometry& geometry,
                                                 const PendulumParams& params, double angle_rad,
                                                 double rate_rad_per_s) {
  const double m = geometry.mass_kg;
  const double g = geometry.gravity_mps2;
  const double I = params.inertia_kg_m2;
  const double K = params.drag_coeff_kg_m2;
  const double C = params.viscous_coeff_kg_m2_per_s;
  const double w = rate_rad_per_s;
  const double abs_w = std::abs(w);
  const double damping = K * w * abs_w + C * w;
  const double d_damping_d_w = 2.0 * K * abs_w + C;

  AccelerationPartials p;
  double M = I;
  switch (model) {
    case PendulumModel::kFull: {
      const Rise r = ComputeRise(geometry, angle_rad, true);
      M = I + m * r.d1 * r.d1;
      const double N = m * r.d1 * r.d2 * w * w + damping + m * g * r.d1;
      const double a = -N / M;
      const double dN_dpsi = m * (r.d2 * r.d2 + r.d1 * r.d3) * w * w + m * g * r.d2;
      const double dM_dpsi = 2.0 * m * r.d1 * r.d2;
      p.accel_rad_per_s2 = a;
      p.d_angle = -(dN_dpsi + a * dM_dpsi) / M;
      p.d_rate = -(2.0 * m * r.d1 * r.d2 * w + d_damping_d_w) / M;
      break;
    }
    case PendulumModel::kJardin: {
      const Rise r = ComputeRise(geometry, angle_rad, false);
      p.accel_rad_per_s2 = -(damping + m * g * r.d1) / I;
      p.d_angle = -m * g * r.d2 / I;
      p.d_rate = -d_damping_d_w / I;
      break;
    }
    case PendulumModel::kLinear: {
      const double k = m * LinearStiffnessPerMass(geometry);
      p.accel_rad_per_s2 = -(damping + k * angle_rad) / I;
      p.d_angle = -k / I;
      p.d_rate = -d_damping_d_w / I;
      break;
    }
  }
  // dM/dI = 1 and N does not depend on I: d psi''/dI = -psi''/M.
  p.d_inertia = -p.accel_rad_per_s2 / M;
  p.d_drag = -w * abs_w / M;
  p.d_viscous = -w / M;
  return p;
}

double MechanicalEnergy(PendulumModel model, const RigGeometry& geometry,
                        const PendulumParams& params, double angle_rad, double rate_rad_per_s) {
  const double m = geometry.mass_kg;
  const double I = params.inertia_kg_m2;
  const double w2 = rate_rad_per_s * rate_rad_per_s;
  switch (model) {
    case PendulumModel::kFull: {
      const Rise r = ComputeRise(geometry, angle_rad, false);
      return 0.5 * (I + m * r.d1 * r.d1) * w2 + m * geometry.gravity_mps2 * r.h;
    }
    case PendulumModel::kJardin: {
      const Rise r = ComputeRise(geometry, angle_rad, false);
      return 0.5 * I * w2 + m * geometry.gravity_mps2 * r.h;
    }
    case PendulumModel::kLinear:
      return 0.5 * I * w2 + 0.5 * m * LinearStiffnessPerMass(geometry) * angle_rad * angle_rad;
  }
  return 0.0;
}

double SmallAnglePeriod(const RigGeometry& geometry, double inertia_kg_m2) {
  const double D = geometry.filar_separation_m;
  return 2.0 * kPi *
         std::sqrt(4.0 * inertia_kg_m2 * geometry.filar_length_m /
                   (geometry.mass_kg * geometry.gravity_mps2 * D * D));
}

double InertiaFromSmallAnglePeriod(const RigGeometry& geometry, double period_s) {
  const double D = geometry.filar_separation_m;
  return geometry.mass_kg * geometry.gravity_mps2 * D * D * period_s * period_s /
         (16.0 * kPi * kPi * geometry.filar_length_m);
}

}  // namespace bifilar
