#include "fit/trace_guess.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include <Eigen/Dense>

#include "base/statistics.h"
#include "base/units.h"

namespace bifilar {
namespace {

struct Crossing {
  double t_s;
  bool upward;
};

// Zero crossings of x - bias with hysteresis `band`: a crossing counts once the signal has left
// the band on the other side; its time is the last sign change before that, interpolated
// linearly between the two samples around it.
std::vector<Crossing> FindCrossings(const std::vector<double>& t, const std::vector<double>& x,
                                    double bias, double band) {
  std::vector<Crossing> out;
  int state = 0;           // -1 below -band, +1 above +band
  size_t last_change = 0;  // index i such that x[i]-bias and x[i+1]-bias differ in sign
  bool have_change = false;
  for (size_t i = 0; i < x.size(); ++i) {
    const double y = x[i] - bias;
    if (i > 0) {
      const double y_prev = x[i - 1] - bias;
      if ((y_prev <= 0.0) != (y <= 0.0)) {
        last_change = i - 1;
        have_change = true;
      }
    }
    const int s = y > band ? 1 : (y < -band ? -1 : 0);
    if (s == 0 || s == state) continue;
    if (state != 0 && have_change) {
      const double y0 = x[last_change] - bias, y1 = x[last_change + 1] - bias;
      const double f = (y0 == y1) ? 0.5 : y0 / (y0 - y1);
      const double tc = t[last_change] + f * (t[last_change + 1] - t[last_change]);
      out.push_back({tc, s > 0});
    }
    state = s;
  }
  return out;
}

// A single sample of the other sign (a glitch too small for fit/glitch.h, e.g. 0.4 rad/s on a
// 1 rad/s swing) makes two crossings around it. A half-cycle is never one sample nor a quarter
// of the others, so such pairs are dropped: only the median crossing spacing and the samples
// beyond the band between the two decide, so a clean series keeps all its crossings.
std::vector<Crossing> WithoutGlitchPairs(const std::vector<double>& t, const std::vector<double>& x,
                                         double bias, double band, std::vector<Crossing> cross) {
  if (cross.size() < 4) return cross;
  std::vector<double> spacing(cross.size() - 1);
  for (size_t i = 0; i + 1 < cross.size(); ++i) spacing[i] = cross[i + 1].t_s - cross[i].t_s;
  const double typical = UpperMedian(spacing, 0.0);
  std::vector<Crossing> out;
  for (size_t i = 0; i < cross.size(); ++i) {
    if (i + 1 < cross.size() && cross[i + 1].t_s - cross[i].t_s < 0.25 * typical) {
      const auto b = std::upper_bound(t.begin(), t.end(), cross[i].t_s) - t.begin();
      const auto e = std::upper_bound(t.begin(), t.end(), cross[i + 1].t_s) - t.begin();
      int beyond = 0;
      for (auto k = b; k < e; ++k) beyond += std::abs(x[k] - bias) > band;
      if (beyond == 1) {
        ++i;  // both crossings of the one-sample lobe
        continue;
      }
    }
    out.push_back(cross[i]);
  }
  return out;
}

// Mean of x over [ta, tb] by the trapezoid rule on the samples inside (ends interpolated).
double MeanOver(const std::vector<double>& t, const std::vector<double>& x, double ta, double tb) {
  auto interp = [&](double tq) {
    const auto it = std::upper_bound(t.begin(), t.end(), tq);
    if (it == t.begin()) return x.front();
    if (it == t.end()) return x.back();
    const size_t j = static_cast<size_t>(it - t.begin());
    const double f = (tq - t[j - 1]) / (t[j] - t[j - 1]);
    return x[j - 1] + f * (x[j] - x[j - 1]);
  };
  double area = 0.0, t_prev = ta, x_prev = interp(ta);
  for (size_t j = 0; j < t.size(); ++j) {
    if (t[j] <= ta) continue;
    if (t[j] >= tb) break;
    area += 0.5 * (x[j] + x_prev) * (t[j] - t_prev);
    t_prev = t[j];
    x_prev = x[j];
  }
  area += 0.5 * (interp(tb) + x_prev) * (tb - t_prev);
  return area / (tb - ta);
}

// Undamped period of `model` at angle amplitude `amplitude_rad` for inertia I: integrate from
// (A, 0) and find the second zero of the rate (psi back at +A), interpolated linearly (the rate
// is near-linear there: its curvature vanishes at the turning point).
bool ModelPeriod(PendulumModel model, const RigGeometry& geometry,
                 const IntegratorOptions& integrator, double inertia, double amplitude_rad,
                 double period_hint_s, double* period_s) {
  const int n = 1500;
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = 1.3 * period_hint_s * i / (n - 1);
  PendulumIntegrator integ(model, geometry, integrator);
  PendulumParams params;
  params.inertia_kg_m2 = inertia;
  Trajectory traj;
  std::string why;
  if (!integ.Integrate(params, amplitude_rad, 0.0, t, false, &traj, &why)) return false;
  int zeros = 0;
  for (int i = 1; i < n; ++i) {
    const double r0 = traj.rate_rad_per_s[i - 1], r1 = traj.rate_rad_per_s[i];
    if (i > 1 && (r0 < 0.0) != (r1 < 0.0)) {
      if (++zeros == 2) {
        *period_s = t[i - 1] + r0 / (r0 - r1) * (t[i] - t[i - 1]);
        return true;
      }
    }
  }
  return false;
}

}  // namespace

double EstimateSampleNoise(const std::vector<double>& t_s, const std::vector<double>& x) {
  if (x.size() < 3) return 0.0;
  std::vector<double> e;
  e.reserve(x.size() - 2);
  for (size_t k = 1; k + 1 < x.size(); ++k) {
    const double span = t_s[k + 1] - t_s[k - 1];
    if (!(span > 0.0)) continue;
    const double w2 = (t_s[k] - t_s[k - 1]) / span, w0 = 1.0 - w2;
    const double pred = w0 * x[k - 1] + w2 * x[k + 1];
    e.push_back(std::abs(x[k] - pred) / std::sqrt(1.0 + w0 * w0 + w2 * w2));
  }
  return 1.4826 * UpperMedian(std::move(e), 0.0);
}

namespace {

// Robust half peak-to-peak: 2nd and 98th percentiles.
double RobustHalfPeakToPeak(const std::vector<double>& x) {
  const size_t n = x.size();
  std::vector<double> sorted = x;
  std::sort(sorted.begin(), sorted.end());
  const double p_lo = sorted[static_cast<size_t>(0.02 * (n - 1))];
  const double p_hi = sorted[static_cast<size_t>(0.98 * (n - 1))];
  return 0.5 * (p_hi - p_lo);
}

// Crossings with hysteresis, twice: the second pass uses the bias over whole cycles (*bias in,
// the mean rate; out, the bias of the crossings).
std::vector<Crossing> ZeroCrossings(const std::vector<double>& t, const std::vector<double>& x,
                                    double band, double* bias) {
  std::vector<Crossing> cross;
  for (int pass = 0; pass < 2; ++pass) {
    cross = WithoutGlitchPairs(t, x, *bias, band, FindCrossings(t, x, *bias, band));
    if (cross.size() < 3) break;
    // Whole cycles: from the first crossing to the last crossing of the same direction.
    size_t last = cross.size() - 1;
    if (cross[last].upward != cross[0].upward) --last;
    if (last >= 2) *bias = MeanOver(t, x, cross[0].t_s, cross[last].t_s);
  }
  return cross;
}

// Period: least-squares line through crossing times vs index (slope = T/2).
double PeriodFromCrossings(const std::vector<Crossing>& cross) {
  const size_t m = cross.size();
  double si = 0, st = 0, sii = 0, sit = 0;
  for (size_t i = 0; i < m; ++i) {
    si += i;
    st += cross[i].t_s;
    sii += double(i) * i;
    sit += i * cross[i].t_s;
  }
  const double half_period = (m * sit - si * st) / (m * sii - si * si);
  return 2.0 * half_period;
}

// The largest |rate - bias| between consecutive crossings, and its time.
void HalfCyclePeaks(const std::vector<double>& t, const std::vector<double>& x,
                    const std::vector<Crossing>& cross, double bias, std::vector<double>* peak_t,
                    std::vector<double>* peak_a) {
  const size_t n = x.size();
  const size_t m = cross.size();
  for (size_t i = 0; i + 1 < m; ++i) {
    double best = 0.0, best_t = 0.0;
    for (size_t k = 0; k < n; ++k) {
      if (t[k] < cross[i].t_s) continue;
      if (t[k] > cross[i + 1].t_s) break;
      if (std::abs(x[k] - bias) > best) {
        best = std::abs(x[k] - bias);
        best_t = t[k];
      }
    }
    if (best > 0.0) {
      peak_t->push_back(best_t);
      peak_a->push_back(best);
    }
  }
}

// Log decrement of the peaks: minus the slope of ln(peak) against time, >= 0.
double DecayRateOfPeaks(const std::vector<double>& peak_t, const std::vector<double>& peak_a) {
  double lambda = 0.0;
  if (peak_a.size() >= 3) {
    double a = 0, b = 0, c = 0, d = 0;
    const double k = peak_a.size();
    for (size_t i = 0; i < peak_a.size(); ++i) {
      a += peak_t[i];
      b += std::log(peak_a[i]);
      c += peak_t[i] * peak_t[i];
      d += peak_t[i] * std::log(peak_a[i]);
    }
    const double slope = (k * d - a * b) / (k * c - a * a);
    if (std::isfinite(slope)) lambda = std::max(0.0, -slope);
  }
  return lambda;
}

// Split of the decay: the angle amplitude A obeys dA/dt = -(lambda_v + kappa A) A with
// lambda_v = C / (2 I) and kappa = (4 / (3 pi)) (K_D / I) omega. Pairs of peaks `stride`
// half-cycles apart give the local rate ln(a_i / a_j) / (t_j - t_i) at A = sqrt(a_i a_j) / w;
// a straight line through them gives lambda_v (intercept) and kappa (slope), both >= 0.
void SplitDecay(const std::vector<double>& peak_t, const std::vector<double>& peak_a, double omega0,
                double lambda, double* lambda_v_out, double* kappa_out) {
  double lambda_v = 0.8 * lambda, kappa = 0.0;
  const size_t np = peak_a.size();
  const size_t stride = std::max<size_t>(1, np / 6);
  std::vector<double> amp, rate;
  for (size_t i = 0; i + stride < np; ++i) {
    const double dt = peak_t[i + stride] - peak_t[i];
    if (!(dt > 0.0)) continue;
    amp.push_back(std::sqrt(peak_a[i] * peak_a[i + stride]) / omega0);
    rate.push_back(std::log(peak_a[i] / peak_a[i + stride]) / dt);
  }
  if (amp.size() >= 3) {
    double sa = 0, sr = 0, saa = 0, sar = 0;
    const double m_pairs = amp.size();
    for (size_t i = 0; i < amp.size(); ++i) {
      sa += amp[i];
      sr += rate[i];
      saa += amp[i] * amp[i];
      sar += amp[i] * rate[i];
    }
    const double den = m_pairs * saa - sa * sa;
    double slope = den > 0.0 ? (m_pairs * sar - sa * sr) / den : 0.0;
    double intercept = (sr - slope * sa) / m_pairs;
    if (!std::isfinite(slope) || !std::isfinite(intercept)) slope = 0.0, intercept = lambda;
    if (slope < 0.0) {
      slope = 0.0;
      intercept = sr / m_pairs;
    }
    if (intercept < 0.0) {
      intercept = 0.0;
      slope = saa > 0.0 ? std::max(0.0, sar / saa) : 0.0;
    }
    lambda_v = intercept;
    kappa = slope;
  }
  *lambda_v_out = lambda_v;
  *kappa_out = kappa;
}

// First cycle: rate ~ e^{-lambda0 tau}(a cos w tau + b sin w tau) + c, tau = t - t0. The angle
// psi = e^{-lambda0 tau}(alpha cos + beta sin) with psi' = rate has
// alpha = psi(t0) = -(lambda0 a + w b) / (lambda0^2 + w^2) (zero-mean about the equilibrium).
void FirstCycleFit(const std::vector<double>& t, const std::vector<double>& x, double period,
                   double omega_d, double lambda0, TraceInitialGuess* guess) {
  const size_t n = x.size();
  const double t0 = t.front();
  std::vector<size_t> first;
  for (size_t k = 0; k < n && t[k] <= t0 + period; ++k) first.push_back(k);
  Eigen::MatrixXd A(first.size(), 3);
  Eigen::VectorXd y(first.size());
  for (size_t i = 0; i < first.size(); ++i) {
    const double tau = t[first[i]] - t0, env = std::exp(-lambda0 * tau);
    A(i, 0) = env * std::cos(omega_d * tau);
    A(i, 1) = env * std::sin(omega_d * tau);
    A(i, 2) = 1.0;
    y(i) = x[first[i]];
  }
  const Eigen::Vector3d coef = A.colPivHouseholderQr().solve(y);
  guess->rate0_rad_per_s = coef(0);
  guess->rate_amplitude_rad_per_s = std::hypot(coef(0), coef(1));
  guess->angle0_rad =
      -(lambda0 * coef(0) + omega_d * coef(1)) / (lambda0 * lambda0 + omega_d * omega_d);
}

// Inertia: small-angle formula at the undamped frequency, then corrected for amplitude.
double InertiaFromGuess(const TraceFitInput& input, PendulumModel model,
                        const IntegratorOptions& integrator, const std::vector<double>& peak_a,
                        double omega0) {
  const double period0 = 2.0 * kPi / omega0;
  double inertia = InertiaFromSmallAnglePeriod(input.geometry, period0);
  double sum_a2 = 0.0;
  for (double a : peak_a) sum_a2 += (a / omega0) * (a / omega0);
  const double amp_rms = peak_a.empty() ? 0.0 : std::sqrt(sum_a2 / peak_a.size());
  if (model != PendulumModel::kLinear && amp_rms > 1e-3) {
    const int iterations = model == PendulumModel::kFull ? 2 : 1;
    for (int it = 0; it < iterations; ++it) {
      double model_period = 0.0;
      if (!ModelPeriod(model, input.geometry, integrator, inertia, std::min(amp_rms, 1.4), period0,
                       &model_period) ||
          !(model_period > 0.0)) {
        break;  // keep the small-angle value; the fit still starts close
      }
      inertia *= (period0 / model_period) * (period0 / model_period);
    }
  }
  return inertia;
}

}  // namespace

bool EstimateTraceGuess(const TraceFitInput& input, PendulumModel model,
                        const IntegratorOptions& integrator, double min_periods,
                        TraceInitialGuess* guess, std::string* why) {
  const std::vector<double>& t = input.t_s;
  const std::vector<double>& x = input.rate_rad_per_s;
  const size_t n = x.size();
  *guess = TraceInitialGuess();
  if (n < 16) {
    *why = "too few samples in the window (" + std::to_string(n) + ", need at least 16)";
    return false;
  }
  const auto [mn, mx] = std::minmax_element(x.begin(), x.end());
  if (!(*mx - *mn > 1e-12 * std::max(1.0, std::abs(*mx)))) {
    *why = "constant data: the swing rate does not change over the window";
    return false;
  }
  const double noise = EstimateSampleNoise(t, x);
  guess->data_noise_rad_per_s = noise;
  const double half_range = RobustHalfPeakToPeak(x);
  const double noise_ref = std::max(noise, input.noise_rad_per_s);
  if (!(half_range > 5.0 * noise_ref)) {
    std::ostringstream s;
    s << "no oscillation: rate amplitude " << half_range << " rad/s is not above 5x the noise "
      << noise_ref << " rad/s";
    *why = s.str();
    return false;
  }
  const double band = std::max(3.0 * noise_ref, 0.05 * half_range);
  double bias = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const std::vector<Crossing> cross = ZeroCrossings(t, x, band, &bias);
  const double duration = t.back() - t.front();
  if (cross.size() < 3) {
    std::ostringstream s;
    s << "shorter than " << min_periods << " periods: only " << cross.size()
      << " zero crossings in " << duration << " s";
    *why = s.str();
    return false;
  }
  const double period = PeriodFromCrossings(cross);
  if (!(period > 0.0) || !std::isfinite(period)) {
    *why = "no regular oscillation: zero crossings do not give a period";
    return false;
  }
  guess->period_s = period;
  guess->cycles = duration / period;
  if (guess->cycles < min_periods) {
    std::ostringstream s;
    s << "shorter than " << min_periods << " periods: window " << duration << " s, period "
      << period << " s (" << guess->cycles << " periods)";
    *why = s.str();
    return false;
  }
  guess->bias_rad_per_s = bias;

  std::vector<double> peak_t, peak_a;
  HalfCyclePeaks(t, x, cross, bias, &peak_t, &peak_a);
  const double omega_d = 2.0 * kPi / period;
  const double lambda = DecayRateOfPeaks(peak_t, peak_a);
  guess->decay_rate_per_s = lambda;
  const double omega0 = std::sqrt(omega_d * omega_d + lambda * lambda);
  double lambda_v = 0.0, kappa = 0.0;
  SplitDecay(peak_t, peak_a, omega0, lambda, &lambda_v, &kappa);
  // Decay rate at the start of the window (largest amplitude).
  const double amp_first = peak_a.empty() ? 0.0 : peak_a.front() / omega0;
  const double lambda0 = std::max(0.0, lambda_v + kappa * amp_first);
  FirstCycleFit(t, x, period, omega_d, lambda0, guess);

  const double inertia = InertiaFromGuess(input, model, integrator, peak_a, omega0);
  guess->params.inertia_kg_m2 = inertia;
  guess->params.viscous_coeff_kg_m2_per_s = 2.0 * inertia * lambda_v;
  guess->params.drag_coeff_kg_m2 = kappa * inertia * 3.0 * kPi / (4.0 * omega0);
  return true;
}

}  // namespace bifilar
