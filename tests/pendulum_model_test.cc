// Known answers for the pendulum equations (pendulum/model.h, docs/physics.md §2): the
// rise h and its derivatives, the analytic partials of psi'' against numeric differentiation,
// the energy balance, the small-angle period, and the input checks.
#include "pendulum/model.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/option_check.h"
#include "base/units.h"
#include "pendulum/integrator.h"

namespace bifilar {
namespace {

const PendulumModel kModels[] = {PendulumModel::kFull, PendulumModel::kJardin,
                                 PendulumModel::kLinear};

RigGeometry TestGeometry() {
  RigGeometry g;
  g.filar_length_m = 2.0;
  g.filar_separation_m = 0.8;
  g.mass_kg = 10.0;
  g.gravity_mps2 = 9.81;
  return g;
}

PendulumParams TestParams() {
  PendulumParams p;
  p.inertia_kg_m2 = 1.5;
  p.drag_coeff_kg_m2 = 0.03;
  p.viscous_coeff_kg_m2_per_s = 0.02;
  return p;
}

// Fourth-order central difference (error O(step^4)) of a smooth function.
template <typename F>
double Derivative(F f, double x, double step) {
  return (-f(x + 2 * step) + 8 * f(x + step) - 8 * f(x - step) + f(x - 2 * step)) / (12 * step);
}

TEST(PendulumModel, NamesRoundTrip) {
  for (PendulumModel m : kModels) {
    PendulumModel parsed = PendulumModel::kLinear;
    if (m == PendulumModel::kLinear) parsed = PendulumModel::kFull;
    ASSERT_TRUE(ParsePendulumModel(ToString(m), &parsed));
    EXPECT_EQ(parsed, m);
  }
  PendulumModel unchanged = PendulumModel::kJardin;
  EXPECT_FALSE(ParsePendulumModel("Full", &unchanged));
  EXPECT_FALSE(ParsePendulumModel("", &unchanged));
  EXPECT_EQ(unchanged, PendulumModel::kJardin);
}

TEST(PendulumModel, RiseMatchesClosedFormAndDerivatives) {
  const RigGeometry g = TestGeometry();
  const double L = g.filar_length_m, D = g.filar_separation_m;
  for (double deg : {-80.0, -45.0, -3.0, 0.0, 1e-3, 7.0, 30.0, 60.0, 89.0}) {
    const double psi = deg * kRadPerDeg;
    const double s = std::sqrt(L * L - 0.5 * D * D * (1 - std::cos(psi)));
    // h = L - s: the closed form loses digits to cancellation near 0, hence the absolute 1e-15.
    EXPECT_NEAR(RiseHeight(g, psi), L - s, 1e-15) << deg;
    EXPECT_NEAR(RiseSlope(g, psi), 0.25 * D * D * std::sin(psi) / s, 1e-15) << deg;
    // Numeric derivatives, 4th-order stencil with step 1e-3 rad: truncation ~1e-13, rounding
    // ~1e-16 / 1e-3 = 1e-13.
    const auto h = [&](double x) { return RiseHeight(g, x); };
    const auto h1 = [&](double x) { return RiseSlope(g, x); };
    EXPECT_NEAR(Derivative(h, psi, 1e-3), RiseSlope(g, psi), 1e-11) << deg;
    EXPECT_NEAR(Derivative(h1, psi, 1e-3), RiseCurvature(g, psi), 1e-11) << deg;
  }
  // Small angles: h ~ D^2 psi^2 / (8 L), accurate to relative O(psi^2) = 1e-12 at 1e-6 rad.
  EXPECT_NEAR(RiseHeight(g, 1e-6) / (D * D * 1e-12 / (8 * L)), 1.0, 1e-9);
  EXPECT_EQ(RiseHeight(g, 0.0), 0.0);
  EXPECT_EQ(RiseSlope(g, 0.0), 0.0);
  EXPECT_NEAR(RiseCurvature(g, 0.0), D * D / (4 * L), 1e-15);
}

TEST(PendulumModel, EquationsOfMotionAsWritten) {
  const RigGeometry g = TestGeometry();
  const PendulumParams p = TestParams();
  const double m = g.mass_kg, I = p.inertia_kg_m2, K = p.drag_coeff_kg_m2,
               C = p.viscous_coeff_kg_m2_per_s;
  const double psi = 0.4, w = -1.3;
  const double h1 = RiseSlope(g, psi), h2 = RiseCurvature(g, psi);
  const double damp = K * w * std::abs(w) + C * w;
  // Residuals of docs/physics.md §2, with psi'' from the model, vanish to rounding.
  const double a_full = AngularAcceleration(PendulumModel::kFull, g, p, psi, w);
  EXPECT_NEAR((I + m * h1 * h1) * a_full + m * h1 * h2 * w * w + damp + m * g.gravity_mps2 * h1,
              0.0, 1e-13);
  const double a_jardin = AngularAcceleration(PendulumModel::kJardin, g, p, psi, w);
  EXPECT_NEAR(I * a_jardin + damp + m * g.gravity_mps2 * h1, 0.0, 1e-13);
  const double a_linear = AngularAcceleration(PendulumModel::kLinear, g, p, psi, w);
  const double D = g.filar_separation_m, L = g.filar_length_m;
  EXPECT_NEAR(I * a_linear + damp + m * g.gravity_mps2 * D * D / (4 * L) * psi, 0.0, 1e-13);
  // Damping opposes the rate.
  PendulumParams undamped = p;
  undamped.drag_coeff_kg_m2 = 0;
  undamped.viscous_coeff_kg_m2_per_s = 0;
  for (PendulumModel model : kModels) {
    EXPECT_GT(AngularAcceleration(model, g, p, 0.0, w), 0.0);  // w < 0
    EXPECT_EQ(AngularAcceleration(model, g, undamped, 0.0, w), 0.0);
  }
}

TEST(PendulumModel, PartialsMatchNumericDifferentiation) {
  const RigGeometry g = TestGeometry();
  const PendulumParams p = TestParams();
  for (PendulumModel model : kModels) {
    for (double deg : {-70.0, -20.0, 0.0, 5.0, 45.0}) {
      for (double w : {-2.0, -0.3, 0.0, 0.7, 3.0}) {
        const double psi = deg * kRadPerDeg;
        SCOPED_TRACE(std::string(ToString(model)) + " psi_deg=" + std::to_string(deg) +
                     " w=" + std::to_string(w));
        const AccelerationPartials a = AngularAccelerationPartials(model, g, p, psi, w);
        EXPECT_EQ(a.accel_rad_per_s2, AngularAcceleration(model, g, p, psi, w));
        const auto by_angle = [&](double x) { return AngularAcceleration(model, g, p, x, w); };
        const auto by_rate = [&](double x) { return AngularAcceleration(model, g, p, psi, x); };
        const auto by_param = [&](int j) {
          return [&, j](double x) {
            PendulumParams q = p;
            if (j == 0) q.inertia_kg_m2 = x;
            if (j == 1) q.drag_coeff_kg_m2 = x;
            if (j == 2) q.viscous_coeff_kg_m2_per_s = x;
            return AngularAcceleration(model, g, q, psi, w);
          };
        };
        // 4th-order stencils with steps ~1e-3 of the scale: truncation and rounding both
        // ~1e-12 of the acceleration scale (~10 rad/s^2). At w = 0 the 4th-order stencil
        // straddles the kink of w|w| (second derivative jumps), so there a plain central
        // difference with step 1e-6 is used; for K_D w|w| it returns K_D step / I = 2e-8
        // instead of 0, hence the wider tolerance there.
        const double tol = 1e-8;
        EXPECT_NEAR(a.d_angle, Derivative(by_angle, psi, 1e-3), tol);
        if (w == 0.0) {
          EXPECT_NEAR(a.d_rate, (by_rate(1e-6) - by_rate(-1e-6)) / 2e-6, 3e-8);
        } else {
          EXPECT_NEAR(a.d_rate, Derivative(by_rate, w, 1e-4), tol);
        }
        EXPECT_NEAR(a.d_inertia, Derivative(by_param(0), p.inertia_kg_m2, 1e-3), tol);
        EXPECT_NEAR(a.d_drag, Derivative(by_param(1), p.drag_coeff_kg_m2, 1e-3), tol);
        EXPECT_NEAR(a.d_viscous, Derivative(by_param(2), p.viscous_coeff_kg_m2_per_s, 1e-3), tol);
      }
    }
  }
}

// Along the flow, dE/dt = E_psi psi' + E_rate psi'' must equal the damping power
// -(K_D psi'|psi'| + C psi') psi', which ties each model's energy to its equation of motion.
TEST(PendulumModel, EnergyBalanceMatchesDampingPower) {
  const RigGeometry g = TestGeometry();
  const PendulumParams p = TestParams();
  for (PendulumModel model : kModels) {
    for (double deg : {-50.0, 0.0, 12.0, 60.0}) {
      for (double w : {-2.5, 0.0, 0.4, 1.9}) {
        const double psi = deg * kRadPerDeg;
        const auto e_angle = [&](double x) { return MechanicalEnergy(model, g, p, x, w); };
        const auto e_rate = [&](double x) { return MechanicalEnergy(model, g, p, psi, x); };
        const double dE_dt = Derivative(e_angle, psi, 1e-3) * w +
                             Derivative(e_rate, w, 1e-3) * AngularAcceleration(model, g, p, psi, w);
        const double power =
            -(p.drag_coeff_kg_m2 * w * std::abs(w) + p.viscous_coeff_kg_m2_per_s * w) * w;
        // Stencil truncation ~1e-12 of energies ~10 J.
        EXPECT_NEAR(dE_dt, power, 1e-9) << ToString(model) << " " << deg << " " << w;
      }
    }
    // At rest at the bottom the energy is zero; it is positive anywhere else.
    EXPECT_EQ(MechanicalEnergy(model, g, p, 0.0, 0.0), 0.0);
    EXPECT_GT(MechanicalEnergy(model, g, p, 0.1, 0.0), 0.0);
    EXPECT_GT(MechanicalEnergy(model, g, p, 0.0, 0.1), 0.0);
  }
  // Values spelled out for one state (docs/physics.md energies).
  const double psi = 0.5, w = 1.2;
  const double m = g.mass_kg, I = p.inertia_kg_m2, h = RiseHeight(g, psi), h1 = RiseSlope(g, psi),
               gm = g.gravity_mps2;
  EXPECT_NEAR(MechanicalEnergy(PendulumModel::kFull, g, p, psi, w),
              0.5 * (I + m * h1 * h1) * w * w + m * gm * h, 1e-13);
  EXPECT_NEAR(MechanicalEnergy(PendulumModel::kJardin, g, p, psi, w), 0.5 * I * w * w + m * gm * h,
              1e-13);
  const double D = g.filar_separation_m, L = g.filar_length_m;
  EXPECT_NEAR(MechanicalEnergy(PendulumModel::kLinear, g, p, psi, w),
              0.5 * I * w * w + 0.5 * m * gm * D * D / (4 * L) * psi * psi, 1e-13);
}

TEST(PendulumModel, SmallAnglePeriodAndInverse) {
  const RigGeometry g = TestGeometry();
  // T = 2 pi sqrt(4 I L / (m g D^2)) = 2 pi sqrt(12 / 62.784) for I = 1.5.
  EXPECT_NEAR(SmallAnglePeriod(g, 1.5), 2 * kPi * std::sqrt(12.0 / 62.784), 1e-14);
  for (double inertia : {1e-3, 0.7, 1.5, 250.0}) {
    EXPECT_NEAR(InertiaFromSmallAnglePeriod(g, SmallAnglePeriod(g, inertia)) / inertia, 1.0, 1e-14);
  }
  // The small-angle period is the linear model's: psi'' = -(m g D^2 / (4 L I)) psi.
  PendulumParams p;
  p.inertia_kg_m2 = 1.5;
  const double omega = 2 * kPi / SmallAnglePeriod(g, 1.5);
  EXPECT_NEAR(AngularAcceleration(PendulumModel::kLinear, g, p, 0.3, 0.0), -omega * omega * 0.3,
              1e-13);
}

void ExpectRigError(const RigGeometry& g, const std::string& must_contain) {
  std::string why;
  EXPECT_FALSE(g.Check(&why)) << must_contain;
  EXPECT_NE(why.find(must_contain), std::string::npos) << "message: " << why;
}

TEST(PendulumModel, RigGeometryCheck) {
  std::string why;
  EXPECT_TRUE(TestGeometry().Check(&why)) << why;
  EXPECT_TRUE(TestGeometry().Check(nullptr));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {0.0, -1.0, nan, inf}) {
    RigGeometry g = TestGeometry();
    g.filar_length_m = bad;
    ExpectRigError(g, "filar_length_m (L) = " + FormatCheckValue(bad) + "; must be finite and > 0");
    g = TestGeometry();
    g.filar_separation_m = bad;
    ExpectRigError(
        g, "filar_separation_m (D) = " + FormatCheckValue(bad) + "; must be finite and > 0");
    g = TestGeometry();
    g.mass_kg = bad;
    ExpectRigError(g, "mass_kg (m) = " + FormatCheckValue(bad) + "; must be finite and > 0");
    g = TestGeometry();
    g.gravity_mps2 = bad;
    ExpectRigError(g, "gravity_mps2 (g) = " + FormatCheckValue(bad) + "; must be finite and > 0");
  }
  // Slack wires: L <= D.
  for (double length : {0.8, 0.5}) {
    RigGeometry g = TestGeometry();
    g.filar_length_m = length;
    ExpectRigError(g, "filar_separation_m (D) = 0.8; must be < filar_length_m (L) = " +
                          FormatCheckValue(length));
  }
  RigGeometry g = TestGeometry();
  g.filar_length_m = 0.5;
  ASSERT_FALSE(g.Check(&why));
  EXPECT_NE(why.find("filar_separation_m (D) = 0.8; must be < filar_length_m (L) = 0.5 (the wires "
                     "would go slack)"),
            std::string::npos)
      << why;
}

TEST(PendulumModel, PendulumParamsCheck) {
  std::string why;
  EXPECT_TRUE(TestParams().Check(&why)) << why;
  PendulumParams undamped;
  undamped.inertia_kg_m2 = 2.0;
  EXPECT_TRUE(undamped.Check(&why)) << why;  // K_D = C = 0 allowed
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (double bad : {0.0, -1.0, nan}) {
    PendulumParams p = TestParams();
    p.inertia_kg_m2 = bad;
    EXPECT_FALSE(p.Check(&why));
    EXPECT_NE(why.find("inertia_kg_m2 (I) = " + FormatCheckValue(bad) + "; must be finite and > 0"),
              std::string::npos)
        << why;
  }
  for (double bad : {-1e-9, nan, std::numeric_limits<double>::infinity()}) {
    PendulumParams p = TestParams();
    p.drag_coeff_kg_m2 = bad;
    EXPECT_FALSE(p.Check(&why));
    EXPECT_NE(
        why.find("drag_coeff_kg_m2 (K_D) = " + FormatCheckValue(bad) + "; must be finite and >= 0"),
        std::string::npos)
        << why;
    p = TestParams();
    p.viscous_coeff_kg_m2_per_s = bad;
    EXPECT_FALSE(p.Check(&why));
    EXPECT_NE(why.find("viscous_coeff_kg_m2_per_s (C) = " + FormatCheckValue(bad) +
                       "; must be finite and >= 0"),
              std::string::npos)
        << why;
  }
}

// One table per enumeration: every name parses back to its value, the CLI choices and the
// allowed-values text come from the same table.
TEST(EnumTables, PendulumModelAndIntegratorNamesRoundTrip) {
  EXPECT_EQ(PendulumModelNames(), (std::vector<std::string>{"full", "jardin", "linear"}));
  for (const std::string& name : PendulumModelNames()) {
    PendulumModel model = PendulumModel::kFull;
    ASSERT_TRUE(ParsePendulumModel(name, &model)) << name;
    EXPECT_EQ(ToString(model), name);
  }
  EXPECT_EQ(PendulumModelAllowedValues(), "full, jardin or linear");
  EXPECT_EQ(IntegratorMethodNames(), (std::vector<std::string>{"rk853", "cvodes"}));
  for (const std::string& name : IntegratorMethodNames()) {
    IntegratorMethod method = IntegratorMethod::kRungeKutta;
    ASSERT_TRUE(ParseIntegratorMethod(name, &method)) << name;
    EXPECT_EQ(ToString(method), name);
  }
  EXPECT_EQ(IntegratorMethodAllowedValues(), "rk853 or cvodes");
  PendulumModel model = PendulumModel::kLinear;
  EXPECT_FALSE(ParsePendulumModel("Full", &model));
  EXPECT_EQ(model, PendulumModel::kLinear);
}

// L > D: one check, one message, NaN refused.
TEST(EnumTables, SeparationBelowLengthIsOneCheck) {
  std::string why;
  EXPECT_TRUE(CheckSeparationBelowLength(2.0, 1.0, &why));
  EXPECT_FALSE(CheckSeparationBelowLength(1.0, 1.0, &why));
  EXPECT_EQ(why,
            "filar_separation_m (D) = 1; must be < filar_length_m (L) = 1 (the wires would "
            "go slack)");
  EXPECT_FALSE(CheckSeparationBelowLength(NAN, 1.0, nullptr));
}

}  // namespace
}  // namespace bifilar
