// Integration of the pendulum model (see integrator.h).
//
// Both methods integrate y = (psi, psi') together with the forward sensitivities
// s_j = dy/dp_j for p = (I, K_D, C, psi(t0), psi'(t0)):
//   s_j' = J s_j + df/dp_j,   J = [[0, 1], [d psi''/d psi, d psi''/d psi']],
//   df/dp_j = (0, d psi''/dp_j) for I, K_D, C and 0 for the initial conditions,
// from the analytic partials (model.h AngularAccelerationPartials): no finite differences.
// They start from s_j(t0) = 0 for the parameters and unit vectors for the initial state, and
// take part in the error test, so that they are accurate enough for a fit's Jacobian. Outputs
// are the methods' interpolants at each requested time, so steps never land on samples.
//
// kRungeKutta: DOP853 (dop853.h) on the 2- or 12-component system, all inlined.
// kCvodes: plain SUNDIALS CVODE on the same 2- or 12-component system (the variational
// equations are just more components, so no sensitivity module is needed). The system is not
// stiff: Adams-Moulton with the fixed-point nonlinear solver (no Jacobian, no linear solve),
// CV_NORMAL output interpolated at each sample. One CVODE memory per system size, created on
// first use and re-initialised (CVodeReInit) for each call. This replaced the CVODES forward-
// sensitivity path (CVodeSensInit, simultaneous corrector), which was 2x slower at equal
// accuracy: one 12-vector per step instead of 6 two-vectors and their per-vector overhead.
#include "pendulum/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "base/enum_names.h"
#include "base/option_check.h"
#include "pendulum/dop853.h"

namespace bifilar {
namespace {

bool Fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

// Right-hand side of the 2-state system (Sens = false) or of the 12-component system state +
// 5 sensitivities (Sens = true, layout y[0..1] state, y[2 + 2j], y[3 + 2j] sensitivity j).
// Returns false for a non-finite state or derivative, which makes the stepper retry smaller.
template <bool Sens>
struct AugmentedRhs {
  PendulumModel model;
  const RigGeometry* geometry;
  const PendulumParams* params;

  bool operator()(const double* y, double* dy) const {
    if (!std::isfinite(y[0]) || !std::isfinite(y[1])) return false;
    dy[0] = y[1];
    if (!Sens) {
      dy[1] = AngularAcceleration(model, *geometry, *params, y[0], y[1]);
      return std::isfinite(dy[1]);
    } else {
      const AccelerationPartials p =
          AngularAccelerationPartials(model, *geometry, *params, y[0], y[1]);
      dy[1] = p.accel_rad_per_s2;
      const double forcing[kNumSensitivities] = {p.d_inertia, p.d_drag, p.d_viscous, 0.0, 0.0};
      bool finite = std::isfinite(dy[1]);
      for (int j = 0; j < kNumSensitivities; ++j) {
        const double* s = y + 2 + 2 * j;
        double* ds = dy + 2 + 2 * j;
        ds[0] = s[1];
        ds[1] = p.d_angle * s[0] + p.d_rate * s[1] + forcing[j];
        finite = finite && std::isfinite(ds[1]);
      }
      return finite;
    }
  }
};

}  // namespace

namespace {

// The one table of integrators (Ceres types.h style): config `integrator`, --integrator, JSON.
constexpr EnumName<IntegratorMethod> kIntegratorMethodNames[] = {
    {IntegratorMethod::kRungeKutta, "rk853"},
    {IntegratorMethod::kCvodes, "cvodes"},
};

}  // namespace

const char* ToString(IntegratorMethod method) {
  return EnumToString(kIntegratorMethodNames, method);
}

bool ParseIntegratorMethod(const std::string& name, IntegratorMethod* method) {
  return ParseEnum(kIntegratorMethodNames, name, method);
}

const std::vector<std::string>& IntegratorMethodNames() {
  static const std::vector<std::string> names = EnumNames(kIntegratorMethodNames);
  return names;
}

std::string IntegratorMethodAllowedValues() { return EnumAllowedValues(kIntegratorMethodNames); }

bool IntegratorOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok =
      CheckIn("rel_tol", rel_tol, 0, 1e-2, Ends::kOpenClosed, &f) &&
      CheckFiniteGt("abs_tol", abs_tol, 0, &f) && CheckGt("max_steps", max_steps, 0, &f) &&
      ((method == IntegratorMethod::kRungeKutta || method == IntegratorMethod::kCvodes) ||
       CheckFail("method", static_cast<double>(method), "kRungeKutta or kCvodes", &f));
  return ok || FailWith(f, why);
}

// One CVODE instance on the 2-component state (Sens = false) or the 12-component augmented
// system (Sens = true): Adams-Moulton, fixed-point nonlinear solver (the system is not stiff:
// no Jacobian, no linear solve), created on first use and re-initialised (CVodeReInit) for
// each call.
struct CvodeSystem {
  void* mem = nullptr;
  N_Vector y = nullptr;
  SUNNonlinearSolver nls = nullptr;

  ~CvodeSystem() {
    if (mem != nullptr) CVodeFree(&mem);
    if (nls != nullptr) SUNNonlinSolFree(nls);
    if (y != nullptr) N_VDestroy(y);
  }
};

IntegratorOptions IntegratorOptions::WithMethod(IntegratorMethod new_method) const {
  IntegratorOptions out = *this;
  if (new_method == method) return out;
  out.method = new_method;
  if (new_method == IntegratorMethod::kCvodes) {
    out.rel_tol *= kCvodeToleranceFactor;
    out.abs_tol *= kCvodeToleranceFactor;
  } else if (method == IntegratorMethod::kCvodes) {
    out.rel_tol /= kCvodeToleranceFactor;
    out.abs_tol /= kCvodeToleranceFactor;
  }
  return out;
}

struct PendulumIntegrator::Impl {
  PendulumModel model;
  RigGeometry geometry;
  IntegratorOptions options;
  std::string setup_error;  // non-empty when construction failed; Integrate reports it

  // Declared before the CVODE systems, so destroyed after them.
  struct Context {
    SUNContext ctx = nullptr;
    ~Context() {
      if (ctx != nullptr) SUNContext_Free(&ctx);
    }
  } context;
  CvodeSystem cvode_state;      // 2 components
  CvodeSystem cvode_augmented;  // 12 components

  PendulumParams params;         // of the current Integrate call, read by the RHS
  IntegratorStats stats;         // of the last Integrate call
  std::string last_cvode_error;  // filled by the CVODE error handler

  template <bool Sens>
  static int CvodeRhs(realtype /*t*/, N_Vector y, N_Vector ydot, void* user_data) {
    const Impl* self = static_cast<const Impl*>(user_data);
    const AugmentedRhs<Sens> rhs{self->model, &self->geometry, &self->params};
    // A non-finite state or derivative is recoverable: CVODE retries with a smaller step.
    return rhs(N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)) ? 0 : 1;
  }

  static void ErrHandler(int /*error_code*/, const char* module, const char* function, char* msg,
                         void* eh_data) {
    Impl* self = static_cast<Impl*>(eh_data);
    self->last_cvode_error = std::string(module) + "/" + function + ": " + msg;
  }

  bool Setup() {
    std::string why;
    if (!geometry.Check(&why)) {
      setup_error = "invalid rig geometry: " + why;
      return false;
    }
    if (!options.Check(&why)) {
      setup_error = "invalid integrator options: " + why;
      return false;
    }
    return true;
  }

  // Creates the CVODE memory of *sys for a system of n components on first use.
  template <bool Sens>
  bool SetupCvode(CvodeSystem* sys, std::string* why) {
    constexpr int kN = Sens ? 2 + 2 * kNumSensitivities : 2;
    SUNContext& ctx = context.ctx;
    if (ctx == nullptr && SUNContext_Create(nullptr, &ctx) != 0) {
      return Fail(why, "SUNContext_Create failed");
    }
    sys->y = N_VNew_Serial(kN, ctx);
    sys->mem = CVodeCreate(CV_ADAMS, ctx);
    if (sys->y == nullptr || sys->mem == nullptr) return Fail(why, "CVODE allocation failed");
    N_VConst(0.0, sys->y);
    if (CVodeSetErrHandlerFn(sys->mem, &Impl::ErrHandler, this) != CV_SUCCESS ||
        CVodeInit(sys->mem, &Impl::CvodeRhs<Sens>, 0.0, sys->y) != CV_SUCCESS ||
        CVodeSStolerances(sys->mem, options.rel_tol, options.abs_tol) != CV_SUCCESS ||
        CVodeSetUserData(sys->mem, this) != CV_SUCCESS ||
        CVodeSetMaxNumSteps(sys->mem, options.max_steps) != CV_SUCCESS) {
      return Fail(why, "CVODE set-up failed: " + last_cvode_error);
    }
    sys->nls = SUNNonlinSol_FixedPoint(sys->y, 0, ctx);
    if (sys->nls == nullptr || CVodeSetNonlinearSolver(sys->mem, sys->nls) != CV_SUCCESS) {
      return Fail(why, "CVODE fixed-point solver set-up failed: " + last_cvode_error);
    }
    return true;
  }

  template <bool Sens>
  bool IntegrateRk(double angle0_rad, double rate0_rad_per_s, const std::vector<double>& t_s,
                   size_t first, Trajectory* out, std::string* why);
  template <bool Sens>
  bool IntegrateCvode(double angle0_rad, double rate0_rad_per_s, const std::vector<double>& t_s,
                      size_t first, Trajectory* out, std::string* why);
};

PendulumIntegrator::PendulumIntegrator(PendulumModel model, const RigGeometry& geometry,
                                       const IntegratorOptions& options)
    : impl_(new Impl) {
  impl_->model = model;
  impl_->geometry = geometry;
  impl_->options = options;
  impl_->Setup();
}

PendulumIntegrator::~PendulumIntegrator() = default;

const IntegratorStats& PendulumIntegrator::last_stats() const { return impl_->stats; }
PendulumModel PendulumIntegrator::model() const { return impl_->model; }
const RigGeometry& PendulumIntegrator::geometry() const { return impl_->geometry; }

bool PendulumIntegrator::Integrate(const PendulumParams& params, double angle0_rad,
                                   double rate0_rad_per_s, const std::vector<double>& t_s,
                                   bool with_sensitivities, Trajectory* out, std::string* why) {
  Impl& im = *impl_;
  im.stats = IntegratorStats();
  if (!im.setup_error.empty()) return Fail(why, im.setup_error);
  std::string reason;
  if (!params.Check(&reason)) return Fail(why, "invalid pendulum parameters: " + reason);
  if (!std::isfinite(angle0_rad) || !std::isfinite(rate0_rad_per_s)) {
    return Fail(why, "initial angle and rate must be finite");
  }
  const size_t n = t_s.size();
  for (size_t k = 0; k < n; ++k) {
    if (!std::isfinite(t_s[k])) {
      std::ostringstream os;
      os << "t_s[" << k << "] is not finite";
      return Fail(why, os.str());
    }
    if (k > 0 && t_s[k] < t_s[k - 1]) {
      std::ostringstream os;
      os.precision(17);
      os << "t_s must be non-decreasing, but t_s[" << k << "] = " << t_s[k] << " < t_s[" << k - 1
         << "] = " << t_s[k - 1];
      return Fail(why, os.str());
    }
  }

  out->angle_rad.resize(n);
  out->rate_rad_per_s.resize(n);
  if (with_sensitivities) {
    out->d_rate.resize(static_cast<Eigen::Index>(n), kNumSensitivities);
    out->d_angle.resize(static_cast<Eigen::Index>(n), kNumSensitivities);
  } else {
    out->d_rate.resize(0, kNumSensitivities);
    out->d_angle.resize(0, kNumSensitivities);
  }
  if (n == 0) return true;

  // Row 0: the initial state; its sensitivities are the identity for (psi0, psi0').
  out->angle_rad[0] = angle0_rad;
  out->rate_rad_per_s[0] = rate0_rad_per_s;
  if (with_sensitivities) {
    out->d_angle.row(0).setZero();
    out->d_rate.row(0).setZero();
    out->d_angle(0, kSensAngle0) = 1.0;
    out->d_rate(0, kSensRate0) = 1.0;
  }
  // Leading times equal to t0 (or indistinguishable from it: a solver cannot take such a step)
  // copy row 0.
  const double t0 = t_s[0];
  const double eps = 4.0 * std::numeric_limits<double>::epsilon();
  size_t first = 1;
  while (first < n && t_s[first] - t0 <= eps * std::max(std::abs(t0), std::abs(t_s[first]))) {
    out->angle_rad[first] = angle0_rad;
    out->rate_rad_per_s[first] = rate0_rad_per_s;
    if (with_sensitivities) {
      out->d_angle.row(first) = out->d_angle.row(0);
      out->d_rate.row(first) = out->d_rate.row(0);
    }
    ++first;
  }
  if (first == n) return true;

  im.params = params;
  if (im.options.method == IntegratorMethod::kRungeKutta) {
    return with_sensitivities
               ? im.IntegrateRk<true>(angle0_rad, rate0_rad_per_s, t_s, first, out, why)
               : im.IntegrateRk<false>(angle0_rad, rate0_rad_per_s, t_s, first, out, why);
  }
  return with_sensitivities
             ? im.IntegrateCvode<true>(angle0_rad, rate0_rad_per_s, t_s, first, out, why)
             : im.IntegrateCvode<false>(angle0_rad, rate0_rad_per_s, t_s, first, out, why);
}

template <bool Sens>
bool PendulumIntegrator::Impl::IntegrateRk(double angle0_rad, double rate0_rad_per_s,
                                           const std::vector<double>& t_s, size_t first,
                                           Trajectory* out, std::string* why) {
  constexpr int kN = Sens ? 2 + 2 * kNumSensitivities : 2;
  typename dop853::Stepper<kN>::Vec y0{};
  y0[0] = angle0_rad;
  y0[1] = rate0_rad_per_s;
  if (Sens) {
    y0[2 + 2 * kSensAngle0] = 1.0;
    y0[3 + 2 * kSensRate0] = 1.0;
  }
  const AugmentedRhs<Sens> rhs{model, &geometry, &params};
  double* angle = out->angle_rad.data();
  double* rate = out->rate_rad_per_s.data();
  const auto write = [&](int k, const double* y) {
    angle[k] = y[0];
    rate[k] = y[1];
    if (Sens) {
      for (int j = 0; j < kNumSensitivities; ++j) {
        out->d_angle(k, j) = y[2 + 2 * j];
        out->d_rate(k, j) = y[3 + 2 * j];
      }
    }
  };
  // The right-hand side is not smooth where psi' = 0 (K_D psi'|psi'| in the state equation,
  // |psi'| and psi'|psi'| in the sensitivity equations). Time to the next turning point from
  // psi' + psi'' tau + j tau^2 / 2 = 0, with the jerk j estimated from the last step.
  const auto kink = [](const double* y, const double* f, const double* f_prev, double h_prev) {
    const double w = y[1], a = f[1];
    if (!(w * a < 0.0)) return std::numeric_limits<double>::infinity();
    const double j = (f[1] - f_prev[1]) / h_prev;
    double tau = -w / a;  // linear estimate, then the quadratic root nearest to it
    const double disc = a * a - 2.0 * j * w;
    if (j != 0.0 && disc >= 0.0) {
      const double q = -0.5 * (a + std::copysign(std::sqrt(disc), a));  // stable root formula
      const double r = w / q;  // root of (j/2) tau^2 + a tau + w near -w/a
      if (r > 0.0 && std::isfinite(r)) tau = r;
    }
    return tau;
  };
  dop853::Stepper<kN> stepper;
  dop853::Stats rk_stats;
  double t_fail = t_s[0];
  const int status = stepper.Integrate(
      rhs, t_s[0], y0, t_s.data(), static_cast<int>(first), static_cast<int>(t_s.size()),
      options.rel_tol, options.abs_tol, options.max_steps, write, kink, &t_fail, &rk_stats);
  stats.steps = rk_stats.steps;
  stats.rejected_steps = rk_stats.rejected;
  stats.rhs_evals = rk_stats.rhs_evals;
  if (status == 0) return true;
  std::ostringstream os;
  os.precision(10);
  if (status == 1) {
    os << "Runge-Kutta integration took more than max_steps = " << options.max_steps
       << " steps by t = " << t_fail << " s";
  } else {
    os << "Runge-Kutta integration failed at t = " << t_fail << " s (" << ToString(model)
       << " model): step size underflow (state or its derivative not finite)";
  }
  return Fail(why, os.str());
}

template <bool Sens>
bool PendulumIntegrator::Impl::IntegrateCvode(double angle0_rad, double rate0_rad_per_s,
                                              const std::vector<double>& t_s, size_t first,
                                              Trajectory* out, std::string* why) {
  constexpr int kN = Sens ? 2 + 2 * kNumSensitivities : 2;
  CvodeSystem* sys = Sens ? &cvode_augmented : &cvode_state;
  // A failed set-up is kept in setup_error, which Integrate reports from then on.
  if (sys->mem == nullptr) {
    std::string reason;
    if (!SetupCvode<Sens>(sys, &reason)) {
      setup_error = reason;
      return Fail(why, reason);
    }
  }
  const size_t n = t_s.size();
  last_cvode_error.clear();
  const double t0 = t_s[0];
  double* yv = N_VGetArrayPointer(sys->y);
  std::fill(yv, yv + kN, 0.0);
  yv[0] = angle0_rad;
  yv[1] = rate0_rad_per_s;
  if (Sens) {
    yv[2 + 2 * kSensAngle0] = 1.0;
    yv[3 + 2 * kSensRate0] = 1.0;
  }
  if (CVodeReInit(sys->mem, t0, sys->y) != CV_SUCCESS) {
    return Fail(why, "CVodeReInit failed: " + last_cvode_error);
  }

  for (size_t k = first; k < n; ++k) {
    const double t = t_s[k];
    // Repeated times copy the previous row.
    if (t == t_s[k - 1]) {
      out->angle_rad[k] = out->angle_rad[k - 1];
      out->rate_rad_per_s[k] = out->rate_rad_per_s[k - 1];
      if (Sens) {
        out->d_angle.row(k) = out->d_angle.row(k - 1);
        out->d_rate.row(k) = out->d_rate.row(k - 1);
      }
      continue;
    }
    realtype t_ret = t0;
    // CV_NORMAL: CVODE steps past t and interpolates back to it.
    const int flag = CVode(sys->mem, t, sys->y, &t_ret, CV_NORMAL);
    if (flag < 0) {
      std::ostringstream os;
      os.precision(10);
      if (flag == CV_TOO_MUCH_WORK) {
        os << "CVODE took more than max_steps = " << options.max_steps << " steps; ";
      }
      os << "CVODE failed at t = " << t_ret << " s (" << ToString(model)
         << " model, integrating from " << t0 << " s to " << t << " s): "
         << (last_cvode_error.empty() ? "flag " + std::to_string(flag) : last_cvode_error);
      return Fail(why, os.str());
    }
    long num_steps = 0;
    CVodeGetNumSteps(sys->mem, &num_steps);
    if (num_steps > options.max_steps) {
      std::ostringstream os;
      os << "CVODE took more than max_steps = " << options.max_steps << " steps by t = " << t
         << " s";
      return Fail(why, os.str());
    }
    for (int i = 0; i < kN; ++i) {
      if (!std::isfinite(yv[i])) {
        std::ostringstream os;
        os << "non-finite " << (i < 2 ? "state" : "sensitivity") << " at t = " << t << " s";
        return Fail(why, os.str());
      }
    }
    out->angle_rad[k] = yv[0];
    out->rate_rad_per_s[k] = yv[1];
    if (Sens) {
      for (int j = 0; j < kNumSensitivities; ++j) {
        out->d_angle(k, j) = yv[2 + 2 * j];
        out->d_rate(k, j) = yv[3 + 2 * j];
      }
    }
  }
  long steps = 0, rhs_evals = 0, test_fails = 0;
  CVodeGetNumSteps(sys->mem, &steps);
  CVodeGetNumRhsEvals(sys->mem, &rhs_evals);
  CVodeGetNumErrTestFails(sys->mem, &test_fails);
  stats.steps = steps;
  stats.rejected_steps = test_fails;
  stats.rhs_evals = rhs_evals;
  return true;
}

}  // namespace bifilar
