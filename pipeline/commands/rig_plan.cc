// `bifilar plan --rig`: the search over (D, L), the evaluation of the chosen rig with the trace
// fit, the release amplitude, the reference object and the Monte-Carlo check (rig_plan.h).
#include "pipeline/commands/rig_plan.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "base/option_check.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "fit/trace_fit.h"
#include "fit/trace_synth.h"
#include "pendulum/integrator.h"
#include "pendulum/model.h"
#include "pendulum/simulate.h"
#include "pipeline/campaign/calibration.h"

namespace bifilar {
namespace {

constexpr int kGridSteps = 60;  // grid points per axis of the search and the figure
constexpr int kMinRepeats = 3, kMaxRepeats = 10;
constexpr double kMinReleaseDeg = 3.0, kMaxReleaseDeg = 30.0;
constexpr double kMinSwingS = 30.0, kMaxSwingS = 300.0;
constexpr double kMaxRelaxedSeparationM = 5.0, kMaxRelaxedLengthM = 20.0;  // plausibility bounds
constexpr double kMaxSeparationOverLength = 0.9;  // keep the wires from splaying past ~64 deg
// Machined reference bar: tolerance on length and width, and the weighing (fraction).
constexpr double kBarToleranceM = 5e-5, kBarWeighingRelStd = 2e-4;

double SuspendedMass(const RigPlanOptions& o) { return o.mass_kg + o.cradle_mass_kg; }

}  // namespace

double RigPlanTerms::Common() const {
  return std::sqrt(filar_length * filar_length + filar_separation * filar_separation + mass * mass +
                   gravity * gravity + calibration * calibration);
}

double RigPlanTerms::Total() const {
  const double per_log = PerLog() / std::sqrt(static_cast<double>(std::max(1, repeats)));
  return std::hypot(Common(), per_log);
}

double RigPlanTerms::SingleSwing() const { return std::hypot(Common(), statistical); }

bool RigPlanOptions::Check(std::string* why) const {
  const std::string context = "plan --rig: ";
  CheckFailure f;
  const int given = !std::isnan(inertia_kg_m2) + !std::isnan(radius_of_gyration_m);
  if (given != 1) {
    CheckFail("--inertia and --radius-of-gyration (given)", given, "exactly one", &f);
    return FailWith(f, why, context);
  }
  if (!std::isnan(radius_of_gyration_m)) {
    if (!CheckIn("--radius-of-gyration", radius_of_gyration_m, 0, 100, Ends::kOpen, &f)) {
      return FailWith(f, why, context);
    }
    RigPlanOptions with_inertia = *this;
    with_inertia.inertia_kg_m2 =
        (mass_kg + cradle_mass_kg) * radius_of_gyration_m * radius_of_gyration_m;
    with_inertia.radius_of_gyration_m = NAN;
    return with_inertia.Check(why);
  }
  // NaN fails every bound; an optional NaN (not given) skips its own.
  const bool ok =
      CheckFiniteGt("--mass", mass_kg, 0, &f) &&
      CheckFiniteGe("--cradle-mass", cradle_mass_kg, 0, &f) &&
      CheckFiniteGt("--inertia", inertia_kg_m2, 0, &f) &&
      (std::isnan(inertia_max_kg_m2) ||
       (CheckFinite("--inertia-max", inertia_max_kg_m2, &f) &&
        CheckGe("--inertia-max", inertia_max_kg_m2, "--inertia", inertia_kg_m2, &f))) &&
      CheckIn("--max-length", max_length_m, 0, kMaxRelaxedLengthM, Ends::kOpenClosed, &f) &&
      CheckFiniteGt("--max-separation", max_separation_m, 0, &f) &&
      // D >= L: the wires would go slack.
      CheckLt("--max-separation", max_separation_m, "--max-length", max_length_m, &f) &&
      CheckFiniteGt("--min-length", min_length_m, 0, &f) &&
      CheckLe("--min-length", min_length_m, "--max-length", max_length_m, &f) &&
      CheckFiniteGt("--min-separation", min_separation_m, 0, &f) &&
      CheckLe("--min-separation", min_separation_m, "--max-separation", max_separation_m, &f) &&
      CheckFiniteGt("--min-period", min_period_s, 0, &f) &&
      CheckFiniteGt("--max-period", max_period_s, 0, &f) &&
      CheckFiniteGe("--length-std", length_std_m, 0, &f) &&
      CheckLt("--length-std", length_std_m, "--max-length", max_length_m, &f) &&
      CheckFiniteGe("--separation-std", separation_std_m, 0, &f) &&
      CheckLt("--separation-std", separation_std_m, "--max-separation", max_separation_m, &f) &&
      (std::isnan(mass_std_kg) ||
       (CheckFiniteGe("--mass-std", mass_std_kg, 0, &f) &&
        CheckLt("--mass-std", mass_std_kg, "the suspended mass --mass + --cradle-mass",
                mass_kg + cradle_mass_kg, &f))) &&
      CheckIn("--gravity", gravity_mps2, 0, 100, Ends::kOpenClosed, &f) &&
      CheckFiniteGe("--gravity-std", gravity_std_mps2, 0, &f) &&
      CheckLt("--gravity-std", gravity_std_mps2, "--gravity", gravity_mps2, &f) &&
      CheckIn("--imu-rate", imu_rate_hz, 5, 10000, Ends::kClosed, &f) &&
      CheckFiniteGt("--gyro-noise", gyro_noise_deg_per_s, 0, &f) &&
      CheckIn("--repeat-scatter", repeat_scatter_percent, 0, 50, Ends::kClosed, &f) &&
      CheckIn("--rig-departure", rig_departure_percent, 0, 50, Ends::kClosed, &f) &&
      CheckIn("--target-percent", target_percent, 0, 100, Ends::kOpen, &f) &&
      CheckGt("decay_periods", decay_periods, 1, &f) &&
      CheckIn("--monte-carlo", monte_carlo_swings, 0, 100000, Ends::kClosed, &f);
  return ok || FailWith(f, why, context);
}

namespace {

// --- The first-order model of the grid (docs/physics.md §5).

struct GridModel {
  const RigPlanOptions& o;
  double inertia_kg_m2;
  double amplitude_rad;

  double Period(double d, double l) const {
    RigGeometry g{l, d, SuspendedMass(o), o.gravity_mps2};
    return SmallAnglePeriod(g, inertia_kg_m2);
  }
  double SwingS(double period_s) const {
    return std::clamp(o.decay_periods * period_s, kMinSwingS, kMaxSwingS);
  }
  // Cramer-Rao bound of the relative std of I from one swing: rate a(t) = A w e^{-lt} cos(w t),
  // white noise sigma at rate fs: var(w) = 2 sigma^2 / (fs (W2 - W1^2/W0)), W_k = int a^2 t^k dt
  // over the swing; I ~ w^-2, so sigma_I / I = 2 sigma_w / w.
  double Statistical(double period_s) const {
    const double w = 2.0 * kPi / period_s, lambda = 1.0 / (o.decay_periods * period_s);
    const double tw = SwingS(period_s), a = amplitude_rad * w;
    const int n = 400;
    double w0 = 0, w1 = 0, w2 = 0;
    for (int k = 0; k < n; ++k) {
      const double t = (k + 0.5) * tw / n, e = a * a * std::exp(-2.0 * lambda * t) * tw / n;
      w0 += e;
      w1 += e * t;
      w2 += e * t * t;
    }
    const double sigma = o.gyro_noise_deg_per_s * kRadPerDeg;
    const double var_w = 2.0 * sigma * sigma / (o.imu_rate_hz * (w2 - w1 * w1 / w0));
    return 2.0 * std::sqrt(var_w) / w;
  }
  RigPlanTerms Terms(double d, double l, int repeats) const {
    RigPlanTerms t;
    t.statistical = Statistical(Period(d, l));
    t.between_repeat = o.repeat_scatter_percent / 100.0;
    t.filar_length = o.length_std_m / l;
    t.filar_separation = 2.0 * o.separation_std_m / d;
    t.mass = o.mass_std_kg / SuspendedMass(o);
    t.gravity = o.gravity_std_mps2 / o.gravity_mps2;
    t.repeats = repeats;
    return t;
  }
  // Inside the constraints: D well below L and the period of both ends of the inertia range
  // within [min_period, max_period].
  bool Feasible(double d, double l) const {
    const double t = Period(d, l);
    const double t_hi =
        std::isnan(o.inertia_max_kg_m2) ? t : t * std::sqrt(o.inertia_max_kg_m2 / inertia_kg_m2);
    return d <= kMaxSeparationOverLength * l && t >= o.min_period_s && t_hi <= o.max_period_s;
  }
};

// The fewest repeats (kMinRepeats..kMaxRepeats) that bring the total to the target;
// kMinRepeats when none does (more repeats then buy little against the common-mode terms).
int RepeatsFor(RigPlanTerms t, double target) {
  for (int n = kMinRepeats; n <= kMaxRepeats; ++n) {
    t.repeats = n;
    if (t.Total() <= target) return n;
  }
  return kMinRepeats;
}

struct GridPoint {
  double d = NAN, l = NAN, total = INFINITY;
  bool found = false;
};

// Linear axis from lo to hi, or geometric when `geometric`.
std::vector<double> Axis(double lo, double hi, bool geometric) {
  std::vector<double> v(kGridSteps);
  for (int i = 0; i < kGridSteps; ++i) {
    const double f = static_cast<double>(i) / (kGridSteps - 1);
    v[i] = geometric ? lo * std::pow(hi / lo, f) : lo + (hi - lo) * f;
  }
  return v;
}

// The grid of the figure and the best feasible point (the lowest total).
GridPoint SearchGrid(const GridModel& m, RigPlanGrid* grid) {
  grid->separation_m = Axis(m.o.min_separation_m, m.o.max_separation_m, false);
  grid->length_m = Axis(m.o.min_length_m, m.o.max_length_m, false);
  GridPoint best;
  for (double d : grid->separation_m) {
    for (double l : grid->length_m) {
      const double total = m.Terms(d, l, kMinRepeats).Total();
      const bool ok = m.Feasible(d, l);
      grid->total_percent.push_back(100.0 * total);
      grid->feasible.push_back(ok ? 1 : 0);
      if (ok && total < best.total) best = {d, l, total, true};
    }
  }
  return best;
}

// The smallest D (then the shortest L) meeting `target` with max-length and max-separation lifted
// to the plausibility bounds (20 m, 5 m); the period range and the other constraints kept.
// Found on a geometric grid, then D refined by bisection at that L.
GridPoint RelaxedForTarget(const GridModel& m, double target) {
  const auto meets = [&](double d, double l) {
    if (!m.Feasible(d, l)) return false;
    RigPlanTerms t = m.Terms(d, l, kMinRepeats);
    t.repeats = RepeatsFor(t, target);
    return t.Total() <= target;
  };
  const std::vector<double> ds = Axis(m.o.min_separation_m, kMaxRelaxedSeparationM, true);
  const std::vector<double> ls = Axis(m.o.min_length_m, kMaxRelaxedLengthM, true);
  for (size_t i = 0; i < ds.size(); ++i) {
    for (double l : ls) {
      if (!meets(ds[i], l)) continue;
      double lo = i > 0 ? ds[i - 1] : ds[i], hi = ds[i];
      for (int k = 0; k < 40 && hi - lo > 1e-5 * hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        (meets(mid, l) ? hi : lo) = mid;
      }
      return {hi, l, 0.0, true};
    }
  }
  return GridPoint();
}

// --- The release amplitude.

// The largest release (deg) at which a rig that departs from the model like the simulator's
// non-ideal preset (restoring torque x (1 - k psi^2), `rig_departure` at 30 deg,
// pendulum/simulate.h) moves I by at most `fraction` of the target.
double ReleaseAmplitudeDeg(const RigPlanOptions& o, double fraction) {
  if (o.rig_departure_percent <= 0.0) return kMaxReleaseDeg;
  const double k = SofteningCoefficient(o.rig_departure_percent / 100.0, 2.0);
  const double allowed = fraction * o.target_percent / 100.0;
  double lo = kMinReleaseDeg;
  for (double a = kMinReleaseDeg; a <= kMaxReleaseDeg + 1e-9; a += 0.5) {
    if (ApparentInertiaExcess(k, 2.0, a * kRadPerDeg) <= allowed) lo = a;
  }
  return lo;
}

// The full model's period at release amplitude A (undamped), from the integrator: the time for
// the rate to come back to zero, twice. NaN if the integration fails.
double FullModelPeriod(const RigGeometry& g, double inertia, double amplitude_rad) {
  const double t0 = SmallAnglePeriod(g, inertia);
  std::vector<double> t(4001);
  for (size_t k = 0; k < t.size(); ++k) t[k] = 0.75 * t0 * k / (t.size() - 1);
  PendulumIntegrator integ(PendulumModel::kFull, g);
  Trajectory traj;
  std::string why;
  if (!integ.Integrate({inertia, 0.0, 0.0}, amplitude_rad, 0.0, t, false, &traj, &why)) return NAN;
  for (size_t k = t.size() / 3; k + 1 < t.size(); ++k) {  // angle crosses -A: rate sign change
    const double r0 = traj.rate_rad_per_s[k], r1 = traj.rate_rad_per_s[k + 1];
    if (r0 < 0.0 && r1 >= 0.0) return 2.0 * (t[k] + (t[k + 1] - t[k]) * (-r0) / (r1 - r0));
  }
  return NAN;
}

// --- One rig evaluated with the project's fit.

TraceFitOptions FitOptionsFor(const RigPlanOptions& o, bool with_budget) {
  TraceFitOptions f;
  f.keep_series = false;
  if (with_budget) {
    f.filar_length_std_m = o.length_std_m;
    f.filar_separation_std_m = o.separation_std_m;
    f.mass_std_kg = o.mass_std_kg;
    f.gravity_std_mps2 = o.gravity_std_mps2;
  }
  return f;
}

// The rate a swing of `swing_s` is simulated at: --imu-rate, or kMaxPlanSamples over the swing.
double SimulatedRateHz(const RigPlanOptions& o, double swing_s) {
  return std::min(o.imu_rate_hz, kMaxPlanSamples / swing_s);
}

SyntheticTraceOptions SwingFor(const RigPlanOptions& o, const RigGeometry& g, double inertia,
                               double amplitude_deg, double swing_s, uint64_t seed) {
  SyntheticTraceOptions s;
  s.geometry = g;
  s.params.inertia_kg_m2 = inertia;
  const double period = SmallAnglePeriod(g, inertia);
  // Amplitude ~ exp(-t / (decay_periods T)): C = 2 I / (decay_periods T).
  s.params.viscous_coeff_kg_m2_per_s = 2.0 * inertia / (o.decay_periods * period);
  s.amplitude_deg = amplitude_deg;
  s.duration_s = swing_s;
  // A dense log is fitted as block means (fit/block_mean.h): k samples averaged carry the same
  // information as the k samples, at noise / sqrt(k). The plan simulates those means directly, so
  // its time and memory stay bounded at any --imu-rate (issue 33 item 4: 10 kHz on a 300 s swing
  // took 1.1 GB and 40 s).
  s.sample_rate_hz = SimulatedRateHz(o, swing_s);
  s.noise_deg_per_s = o.gyro_noise_deg_per_s * std::sqrt(s.sample_rate_hz / o.imu_rate_hz);
  s.seed = seed;
  return s;
}

RigCandidate Evaluate(const RigPlanOptions& o, const std::string& label, double d, double l,
                      double inertia, double amplitude_deg, double swing_s, double target) {
  RigCandidate c;
  c.label = label;
  c.separation_m = d;
  c.length_m = l;
  const RigGeometry g{l, d, SuspendedMass(o), o.gravity_mps2};
  c.period_s = FullModelPeriod(g, inertia, amplitude_deg * kRadPerDeg);
  TraceFitInput in;
  if (!MakeSyntheticTrace(SwingFor(o, g, inertia, amplitude_deg, swing_s, o.seed), &in)) {
    throw UserError("plan --rig: the swing on L " + Fmt("%.3g", l) + " m, D " + Fmt("%.3g", d) +
                    " m could not be simulated");
  }
  const TraceFitResult r = FitTrace(in, FitOptionsFor(o, true));
  if (!r.HasFit()) {
    throw UserError("plan --rig: the simulated swing on L " + Fmt("%.3g", l) + " m, D " +
                    Fmt("%.3g", d) + " m did not fit (--gyro-noise, --imu-rate): " + r.message);
  }
  const double i = r.params.inertia_kg_m2;
  c.terms.statistical = r.inertia_stat_std_kg_m2 / i;
  c.terms.between_repeat = o.repeat_scatter_percent / 100.0;
  for (const UncertaintyContribution& b : r.budget) {
    const double rel = b.contribution_kg_m2 / i;
    if (b.name == "filar_length") c.terms.filar_length = rel;
    if (b.name == "filar_separation") c.terms.filar_separation = rel;
    if (b.name == "mass") c.terms.mass = rel;
    if (b.name == "gravity") c.terms.gravity = rel;
  }
  c.terms.repeats = RepeatsFor(c.terms, target);
  return c;
}

// --- The reference object.

// Bounds of a bar a workshop makes and a rig carries (m): length, thickness (a flat bar at least
// 3 mm thick, no thicker than wide, so that it stays flat and rigid).
constexpr double kMinBarLengthM = 0.02, kMaxBarLengthM = 2.0, kMinBarThicknessM = 0.003;

// One candidate: a flat bar of `mass` with the aircraft's radius of gyration r (so its period
// matches the aircraft's), b = a / aspect, I = M (a^2 + b^2) / 12 = M r^2, of `density`.
ReferenceBar BarFor(double r, double mass, double aspect, const char* material, double density) {
  ReferenceBar bar;
  const double a = std::sqrt(12.0 * r * r / (1.0 + 1.0 / (aspect * aspect))), b = a / aspect;
  bar.material = material;
  bar.density_kg_m3 = density;
  bar.length_m = a;
  bar.width_m = b;
  bar.thickness_m = mass / (density * a * b);
  bar.mass_kg = mass;
  bar.inertia_kg_m2 = mass * (a * a + b * b) / 12.0;
  bar.tolerance_m = kBarToleranceM;
  bar.swings = kRecommendedReferenceSwings;
  const double s2 = a * a + b * b;
  const double da = 2.0 * a * kBarToleranceM / s2, db = 2.0 * b * kBarToleranceM / s2;
  bar.inertia_rel_std = std::sqrt(da * da + db * db + kBarWeighingRelStd * kBarWeighingRelStd);
  bar.buildable = a >= kMinBarLengthM && a <= kMaxBarLengthM &&
                  bar.thickness_m >= kMinBarThicknessM && bar.thickness_m <= b;
  return bar;
}

// A flat bar, swung flat and centred, with the aircraft's radius of gyration (its period) and a
// mass close to the aircraft's (the wires then stretch alike; docs/method.md §15): the
// aircraft's mass first, then 1.5x, 2x, 0.75x, 0.5x; b = a/8, then a/6, a/4; aluminium, then
// steel. The first that a workshop can make (kMinBarLengthM..kMaxBarLengthM long, at least
// kMinBarThicknessM thick and no thicker than wide); none: `buildable` false and why.
ReferenceBar DesignReference(double inertia, double mass) {
  const double r = std::sqrt(inertia / mass);
  struct Material {
    const char* name;
    double density;
  };
  const Material materials[] = {{"aluminium", 2700.0}, {"steel", 7850.0}};
  for (double factor : {1.0, 1.5, 2.0, 0.75, 0.5}) {
    for (double aspect : {8.0, 6.0, 4.0}) {
      for (const Material& m : materials) {
        const ReferenceBar bar = BarFor(r, factor * mass, aspect, m.name, m.density);
        if (bar.buildable) return bar;
      }
    }
  }
  ReferenceBar bar = BarFor(r, mass, 8.0, "steel", 7850.0);  // what it would take
  if (bar.length_m > kMaxBarLengthM) {
    bar.why_not = "the aircraft's radius of gyration " + Fmt("%.3g", r) + " m needs a bar " +
                  Fmt("%.3g", bar.length_m) + " m long (at most " + Fmt("%g", kMaxBarLengthM) +
                  " m is planned)";
  } else if (bar.length_m < kMinBarLengthM) {
    bar.why_not = "the aircraft's radius of gyration " + Fmt("%.3g", 1e3 * r) +
                  " mm needs a bar shorter than " + Fmt("%g", 1e3 * kMinBarLengthM) + " mm";
  } else {
    bar.why_not = "a bar of the aircraft's radius of gyration (" + Fmt("%.3g", r) +
                  " m) and within 0.5-2x its mass would be " +
                  (bar.thickness_m < kMinBarThicknessM ? "thinner than 3 mm"
                                                       : "thicker than it is wide, even in steel");
  }
  return bar;
}

// The recommended rig with the reference object: L, D and g replaced by the calibration's
// relative std (docs/method.md §15, given rig inertia): the bar's own and its swings' mean
// (per-log std / sqrt(swings), the reference's inertia close to the aircraft's).
RigPlanTerms Calibrated(const RigPlanTerms& t, const ReferenceBar& bar, double target) {
  RigPlanTerms c = t;
  c.filar_length = c.filar_separation = c.gravity = 0.0;
  c.calibration =
      std::hypot(bar.inertia_rel_std, t.PerLog() / std::sqrt(static_cast<double>(bar.swings)));
  c.repeats = RepeatsFor(c, target);
  return c;
}

// --- Monte-Carlo: swings on the recommended rig, L, D, m drawn, fitted with the nominal ones.

RigMonteCarlo MonteCarlo(const RigPlan& plan, double inertia) {
  const RigPlanOptions& o = plan.options;
  RigMonteCarlo mc;
  mc.swings = o.monte_carlo_swings;
  mc.predicted_rel_std = plan.recommended.terms.SingleSwing();
  const RigGeometry nominal{plan.recommended.length_m, plan.recommended.separation_m,
                            SuspendedMass(o), o.gravity_mps2};
  std::mt19937_64 rng(o.seed + 12345);
  std::normal_distribution<double> z(0.0, 1.0);
  std::vector<double> errors;
  for (int k = 0; k < mc.swings; ++k) {
    RigGeometry truth = nominal;
    truth.filar_length_m += o.length_std_m * z(rng);
    truth.filar_separation_m += o.separation_std_m * z(rng);
    truth.mass_kg += o.mass_std_kg * z(rng);
    truth.gravity_mps2 += o.gravity_std_mps2 * z(rng);
    TraceFitInput in;
    if (!MakeSyntheticTrace(SwingFor(o, truth, inertia, plan.release_amplitude_deg, plan.swing_s,
                                     o.seed + 1000 + k),
                            &in)) {
      continue;
    }
    in.geometry = nominal;  // the fit knows only the measured rig
    const TraceFitResult r = FitTrace(in, FitOptionsFor(o, false));
    if (r.HasFit()) errors.push_back(r.params.inertia_kg_m2 / inertia - 1.0);
  }
  mc.usable = static_cast<int>(errors.size());
  if (mc.usable >= 2) {
    double mean = 0, ss = 0;
    for (double e : errors) mean += e / errors.size();
    for (double e : errors) ss += (e - mean) * (e - mean);
    mc.scatter_rel_std = std::sqrt(ss / (errors.size() - 1));
    mc.ratio = mc.scatter_rel_std / mc.predicted_rel_std;
  }
  return mc;
}

// The constraint that binds: the flag behind the largest term at the recommended rig.
std::string BindingFlag(const RigPlanTerms& t) {
  const double per_log = t.PerLog() / std::sqrt(static_cast<double>(t.repeats));
  const std::pair<double, const char*> terms[] = {
      {t.filar_separation, "--max-separation"},
      {t.filar_length, "--max-length"},
      {t.mass, "--mass-std"},
      {t.gravity, "--gravity-std"},
      {per_log, t.statistical > t.between_repeat ? "--gyro-noise" : "--repeat-scatter"}};
  return std::max_element(std::begin(terms), std::end(terms))->second;
}

void Alternatives(const RigPlanOptions& o, const GridModel& m, double inertia, RigPlan* plan) {
  const double target = o.target_percent / 100.0, d0 = plan->recommended.separation_m,
               l0 = plan->recommended.length_m;
  struct Try {
    const char* label;
    double d, l;
  };
  // Around the choice: a shorter and a longer wire, a narrower separation.
  const Try tries[] = {{"shorter L", d0, std::max(o.min_length_m, 0.75 * l0)},
                       {"longer L", d0, std::min(o.max_length_m, 1.25 * l0)},
                       {"narrower D", std::max(o.min_separation_m, 0.75 * d0), l0}};
  for (const Try& t : tries) {
    if ((t.d == d0 && t.l == l0) || !m.Feasible(t.d, t.l)) continue;
    try {
      plan->alternatives.push_back(Evaluate(o, t.label, t.d, t.l, inertia,
                                            plan->release_amplitude_deg,
                                            m.SwingS(m.Period(t.d, t.l)), target));
    } catch (const UserError&) {
      // an alternative whose swing the noise drowns is no alternative: left out
    }
  }
}

// The periods the constraints allow (D <= 0.9 L inside the L and D bounds), both ends of the
// inertia range: what a period window must overlap.
void PossiblePeriods(const GridModel& m, const RigPlanGrid& grid, double out[2]) {
  const RigPlanOptions& o = m.o;
  const double hi_factor =
      std::isnan(o.inertia_max_kg_m2) ? 1.0 : std::sqrt(o.inertia_max_kg_m2 / m.inertia_kg_m2);
  out[0] = INFINITY;
  out[1] = 0.0;
  for (double d : grid.separation_m) {
    for (double l : grid.length_m) {
      if (d > kMaxSeparationOverLength * l) continue;
      const double t = m.Period(d, l);
      out[0] = std::min(out[0], t);
      out[1] = std::max(out[1], t * hi_factor);
    }
  }
  if (!(out[1] > 0.0)) out[0] = out[1] = NAN;  // no D <= 0.9 L at all
}

// No rig swings inside the period window: which end binds, and the advice.
void MissedPeriodWindow(const GridModel& m, RigPlan* plan) {
  const RigPlanOptions& o = m.o;
  plan->period_window_missed = true;
  PossiblePeriods(m, plan->grid, plan->periods_possible_s);
  const double fast = plan->periods_possible_s[0], slow = plan->periods_possible_s[1];
  if (o.min_period_s > o.max_period_s) {
    plan->binding = "--min-period";
    plan->advice = "the period range is empty (--min-period " + Fmt("%g", o.min_period_s) +
                   " s above --max-period " + Fmt("%g", o.max_period_s) + " s)";
  } else {
    plan->binding = std::isfinite(fast) && fast > o.max_period_s ? "--max-period" : "--min-period";
    plan->advice =
        "no rig within --min-length..--max-length and --min-separation.."
        "--max-separation (D <= 0.9 L) swings with a period in [" +
        Fmt("%g", o.min_period_s) + ", " + Fmt("%g", o.max_period_s) + "] s";
    if (std::isfinite(fast)) {
      plan->advice +=
          "; the periods possible span " + Fmt("%.3g", fast) + " to " + Fmt("%.3g", slow) + " s";
    }
    plan->advice += plan->binding == "--max-period"
                        ? ": a wider D (--max-separation), a shorter L or a longer --max-period"
                        : ": a narrower D, a longer L (--max-length) or a shorter --min-period";
  }
  plan->advice += "; the rig shown is the widest D on the longest L, outside the window";
}

// The floor no rig and no reference object lowers (RigPlanFloor): the mass and the per-swing terms
// at kMaxRepeats, at the recommended rig.
RigPlanFloor FloorOf(const RigPlanOptions& o, const RigPlanTerms& t) {
  const double root = std::sqrt(static_cast<double>(kMaxRepeats));
  const double between = t.between_repeat / root, stat = t.statistical / root;
  RigPlanFloor f;
  f.rel_std = std::sqrt(t.mass * t.mass + between * between + stat * stat);
  const std::string over = " %/sqrt(" + std::to_string(kMaxRepeats) + ") = ";
  f.parts = "mass " + Fmt("%.3g", 100.0 * t.mass) + " %, between-repeat " +
            Fmt("%.3g", 100.0 * t.between_repeat) + over + Fmt("%.2g", 100.0 * between) +
            " %, statistical " + Fmt("%.2g", 100.0 * t.statistical) + over +
            Fmt("%.2g", 100.0 * stat) + " %";
  if (t.mass >= between && t.mass >= stat) {
    f.term = "mass";
    f.flag = "--mass-std";
    f.lift = "a better weighing of everything that hangs (now " + Fmt("%.3g", o.mass_std_kg * 1e3) +
             " g, " + Fmt("%.3g", 100.0 * t.mass) + " %; --mass-std)";
  } else if (between >= stat) {
    f.term = "between-repeat";
    f.flag = "--repeat-scatter";
    f.lift = "a rig that hangs up the same way each time (" + Fmt("%g", o.repeat_scatter_percent) +
             " % between repeats assumed, over sqrt(" + std::to_string(kMaxRepeats) +
             ") repeats, the most planned; measure yours: --repeat-scatter)";
  } else {
    f.term = "statistical";
    f.flag = "--gyro-noise";
    f.lift = "a quieter gyro or a faster IMU (--gyro-noise, --imu-rate)";
  }
  return f;
}

// Target not met within the constraints: the floor, or else the constraint that binds, the
// reference object and the relaxed rig.
void NotMet(const GridModel& m, double target, const GridPoint& relaxed, RigPlan* plan) {
  plan->floor = FloorOf(m.o, plan->recommended.terms);
  plan->below_floor = target < plan->floor.rel_std;
  if (plan->period_window_missed) return;  // binding and advice said already
  if (plan->below_floor) {
    plan->binding = plan->floor.flag;
    plan->advice = "no rig, reference object or wider constraint reaches " +
                   Fmt("%g", m.o.target_percent) + " %: the floor " +
                   Fmt("%.3g", 100.0 * plan->floor.rel_std) + " % (" + plan->floor.parts +
                   ") is set mostly by the " + plan->floor.term +
                   " term, which only a measurement lowers: " + plan->floor.lift +
                   "; (within the constraints the largest term is " +
                   BindingFlag(plan->recommended.terms) + "'s)";
    return;
  }
  plan->binding = BindingFlag(plan->recommended.terms);
  const ReferenceBar& bar = plan->reference;
  if (!bar.buildable) {
    plan->advice = "no buildable reference bar (" + bar.why_not + ")";
  } else {
    plan->advice = plan->calibrated.Total() <= target
                       ? "a reference object (below) brings it to " +
                             Fmt("%.2f", 100.0 * plan->calibrated.Total()) + " %"
                       : "even a reference object leaves " +
                             Fmt("%.2f", 100.0 * plan->calibrated.Total()) + " %";
  }
  if (relaxed.found) {
    plan->advice += "; without one, D >= " + Fmt("%.3f", relaxed.d) + " m on L " +
                    Fmt("%.3f", relaxed.l) + " m meets the target";
  }
}

}  // namespace

int RigPlanExitCode(const RigPlan& p) {
  if (p.target_met) return 0;
  const bool by_reference = !p.period_window_missed && !p.below_floor && p.reference.needed &&
                            p.reference.buildable &&
                            p.calibrated.Total() <= p.options.target_percent / 100.0;
  return by_reference ? 0 : 1;
}

RigPlan RunRigPlan(const RigPlanOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!options.Check(&why)) throw UserError(why);
  RigPlan plan;
  plan.options = options;
  RigPlanOptions& o = plan.options;
  if (std::isnan(o.mass_std_kg)) o.mass_std_kg = 1e-3 * SuspendedMass(o);
  if (!std::isnan(o.radius_of_gyration_m)) {
    o.inertia_kg_m2 = SuspendedMass(o) * o.radius_of_gyration_m * o.radius_of_gyration_m;
  }
  // A range of inertia: planned at its low end (the shortest period; the relative L, D, m, g
  // terms do not depend on I); the period range must hold at both ends (GridModel::Feasible).
  const double inertia = o.inertia_kg_m2;
  const double target = o.target_percent / 100.0;
  plan.release_amplitude_deg = ReleaseAmplitudeDeg(o, plan.departure_fraction_of_target);
  const GridModel model{o, inertia, plan.release_amplitude_deg * kRadPerDeg};
  GridPoint best = SearchGrid(model, &plan.grid);
  if (!best.found) {  // the period range excludes every rig: say which end binds
    MissedPeriodWindow(model, &plan);
    best = {o.max_separation_m, o.max_length_m, 0.0, true};  // evaluated anyway, marked
  }
  plan.swing_s = model.SwingS(model.Period(best.d, best.l));
  plan.simulated_rate_hz = SimulatedRateHz(o, plan.swing_s);
  try {
    plan.recommended = Evaluate(o, "recommended", best.d, best.l, inertia,
                                plan.release_amplitude_deg, plan.swing_s, target);
  } catch (const UserError&) {
    // A rig far outside the period window can swing too slowly to fit: its first-order terms
    // then stand for it, and the window stays the cause named.
    if (!plan.period_window_missed) throw;
    plan.recommended.label = "recommended";
    plan.recommended.separation_m = best.d;
    plan.recommended.length_m = best.l;
    plan.recommended.period_s = model.Period(best.d, best.l);
    plan.recommended.terms = model.Terms(best.d, best.l, kMinRepeats);
    plan.recommended.terms.repeats = RepeatsFor(plan.recommended.terms, target);
  }
  const RigGeometry g{best.l, best.d, SuspendedMass(o), o.gravity_mps2};
  plan.small_angle_excess_percent =
      100.0 * (std::pow(plan.recommended.period_s / SmallAnglePeriod(g, inertia), 2) - 1.0);
  plan.best_std_percent = 100.0 * plan.recommended.terms.Total();
  plan.target_met = !plan.period_window_missed && plan.recommended.terms.Total() <= target;
  Alternatives(o, model, inertia, &plan);
  const GridPoint relaxed = RelaxedForTarget(model, target);
  if (relaxed.found) {
    plan.separation_for_target_m = relaxed.d;
    plan.length_for_target_m = relaxed.l;
  }
  plan.reference = DesignReference(inertia, o.mass_kg);
  plan.calibrated = Calibrated(plan.recommended.terms, plan.reference, target);
  plan.reference.needed = !plan.target_met;
  if (!plan.target_met) NotMet(model, target, relaxed, &plan);
  if (o.monte_carlo_swings > 0) plan.monte_carlo = MonteCarlo(plan, inertia);
  plan.plan_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return plan;
}

}  // namespace bifilar
