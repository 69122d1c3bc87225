// Integration of the pendulum model (pendulum/model.h), at a log's own, possibly non-uniform
// timestamps, with forward sensitivities of the state with respect to I, K_D, C, psi(t0) and
// psi'(t0), by an inlined DOP853 Runge-Kutta (default) or SUNDIALS CVODE (IntegratorMethod).
// Conventions: docs/physics.md §2 (model), docs/method.md (where the fit uses it).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pendulum/model.h"

namespace bifilar {

// The ODE solver behind PendulumIntegrator. Both integrate the same system: the state
// (psi, psi') alone, or augmented with the 2x5 variational equations of the forward
// sensitivities (12 components, analytic, all in the error test).
enum class IntegratorMethod {
  // Explicit Runge-Kutta 8(5,3) with 7th-order dense output (Dormand-Prince DOP853), inlined on
  // the 2- or 12-component system: ~15x faster than CVODE here (README, Performance).
  kRungeKutta,
  // SUNDIALS CVODE on the same 2- or 12-component system: Adams-Moulton, the fixed-point
  // nonlinear solver, CV_NORMAL output interpolated at the samples. An independent check of
  // kRungeKutta (and the simulator's truth integrator); slower per step (general N_Vector
  // machinery, ~8x more steps) and ~20x larger global error at equal tolerances, hence
  // IntegratorOptions::WithMethod. Named "cvodes" in configs for continuity with earlier
  // versions, which used the CVODES sensitivity module (2x slower at equal accuracy).
  kCvodes,
};
// "rk853", "cvodes".
const char* ToString(IntegratorMethod method);
bool ParseIntegratorMethod(const std::string& name, IntegratorMethod* method);
// The names in table order, for CLI choices: {"rk853", "cvodes"}.
const std::vector<std::string>& IntegratorMethodNames();
// The allowed values for messages and help: "rk853 or cvodes".
std::string IntegratorMethodAllowedValues();

struct IntegratorOptions {
  // Local error tolerances per step, for the state and (same values) the sensitivities. With
  // kRungeKutta the defaults give, over a 60 s swing of 20 deg, a global rate error ~2e-10
  // rad/s (3e-10 without sensitivities), sensitivities to ~1e-8 of their scale, periods to
  // 1e-11 relative and energy kept to 1.2e-9: far below any gyro noise, at ~1 ms per
  // 6000-sample trace with sensitivities (README, Performance). kCvodes at the same values is
  // ~18x less accurate globally (rate) and ~14x slower; see WithMethod.
  double rel_tol = 1e-10;    // Relative tolerance (dimensionless); in (0, 1e-2].
  double abs_tol = 1e-12;    // Absolute tolerance (rad, rad/s, and for sensitivities); > 0.
  long max_steps = 1000000;  // Internal steps allowed over the whole trace; > 0.
  IntegratorMethod method = IntegratorMethod::kRungeKutta;  // ODE solver, see above.

  bool Check(std::string* why) const;

  // A copy that integrates with `new_method`. For kCvodes the tolerances are multiplied by
  // kCvodeToleranceFactor: Adams leaves a larger global error at equal nominal tolerances, and
  // at 0.3x (defaults 1e-10/1e-12 -> 3e-11/3e-13) it matches the former CVODES sensitivity path
  // at the defaults (rate error 1.4e-9 against 1.2e-9 rad/s on the 60 s benchmark trace,
  // bench/pendulum_bench.cc) in half its time. Switching back divides again.
  IntegratorOptions WithMethod(IntegratorMethod new_method) const;
};

// Tolerance factor of IntegratorOptions::WithMethod for kCvodes (dimensionless, measured).
constexpr double kCvodeToleranceFactor = 0.3;

// Column order of the sensitivity matrices.
enum SensitivityIndex {
  kSensInertia = 0,  // d/dI
  kSensDrag = 1,     // d/dK_D
  kSensViscous = 2,  // d/dC
  kSensAngle0 = 3,   // d/dpsi(t0)
  kSensRate0 = 4,    // d/dpsi'(t0)
  kNumSensitivities = 5
};

struct Trajectory {
  std::vector<double> angle_rad;       // psi(t_k)
  std::vector<double> rate_rad_per_s;  // psi'(t_k)
  // d psi'(t_k) / d p_j and d psi(t_k) / d p_j: row k, column j in SensitivityIndex order.
  // Empty (0 rows) when sensitivities were not requested.
  Eigen::MatrixXd d_rate;
  Eigen::MatrixXd d_angle;
};

// Work done by the last Integrate call (for benchmarks and reports).
struct IntegratorStats {
  long steps = 0;           // internal steps attempted
  long rejected_steps = 0;  // of which rejected by the error test (or a non-finite stage)
  long rhs_evals = 0;       // right-hand side evaluations (state, or state + sensitivities)
};

// Reusable: keeps the CVODE memory between calls, so a fit's tens of integrations allocate
// once. Not thread-safe; use one per thread.
class PendulumIntegrator {
 public:
  PendulumIntegrator(PendulumModel model, const RigGeometry& geometry,
                     const IntegratorOptions& options = IntegratorOptions());
  ~PendulumIntegrator();
  PendulumIntegrator(const PendulumIntegrator&) = delete;
  PendulumIntegrator& operator=(const PendulumIntegrator&) = delete;

  // Integrates from t_s[0], where the state is (angle0, rate0), and fills *out at every t_s
  // (non-decreasing; repeated times allowed). Returns false with *why set when the solver
  // fails (never fills NaN).
  bool Integrate(const PendulumParams& params, double angle0_rad, double rate0_rad_per_s,
                 const std::vector<double>& t_s, bool with_sensitivities, Trajectory* out,
                 std::string* why);

  const IntegratorStats& last_stats() const;
  PendulumModel model() const;
  const RigGeometry& geometry() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bifilar
