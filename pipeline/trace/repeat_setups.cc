#include "pipeline/trace/repeat_setups.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "base/units.h"
#include "fit/distributions.h"

namespace bifilar {
namespace {

constexpr double kQp = 0.001;            // Q's p below which the repeats disagree
constexpr double kGapZ = 5.0;            // the clusters' gap over its std
constexpr double kGapZWithAxes = 3.0;    // ... when the swing axes differ too
constexpr double kSeparation = 3.0;      // the gap over the largest range within a cluster
constexpr double kOwnTrendSigmas = 3.0;  // the own trends' bound: c + 3 std
constexpr double kAxisMinDeg = 1.0;      // the clusters' axes at least this far apart
constexpr double kAxisOverSpread = 3.0;  // and this many times their spread within clusters

struct WeightedMean {
  double mean = NAN, std = NAN, q = 0.0;
};

WeightedMean Weighted(const std::vector<double>& v, const std::vector<double>& s,
                      const std::vector<int>& which) {
  double sw = 0.0, swy = 0.0;
  for (int i : which) {
    sw += 1.0 / (s[i] * s[i]);
    swy += v[i] / (s[i] * s[i]);
  }
  WeightedMean m;
  m.mean = swy / sw;
  m.std = 1.0 / std::sqrt(sw);
  for (int i : which) m.q += std::pow((v[i] - m.mean) / s[i], 2);
  return m;
}

// A log's own I(A) trend (its amplitude sweep) as an A^2 coefficient: c A^p with p = 1 over the
// bands' amplitudes [a, b] has the chord slope of c / (a + b) A^2. False without a measured trend.
bool OwnTrendAsSquare(const TraceRecord& r, double* c, double* s) {
  const AmplitudeSweep& w = r.sweep;
  if (!w.evaluated || !(w.trend_coeff_std > 0.0) || !std::isfinite(w.trend_coeff)) return false;
  double lo = INFINITY, hi = -INFINITY;
  for (const AmplitudeSweepBand& b : w.bands) {
    if (!b.ok) continue;
    lo = std::min(lo, b.amplitude_mean_deg);
    hi = std::max(hi, b.amplitude_mean_deg);
  }
  if (!(hi > lo)) return false;
  const double scale = w.trend_exponent == 2.0   ? 1.0
                       : w.trend_exponent == 1.0 ? 1.0 / (lo + hi)
                                                 : NAN;
  if (!std::isfinite(scale)) return false;
  *c = w.trend_coeff * scale;
  *s = w.trend_coeff_std * scale;
  return true;
}

void PoolOwnTrends(const std::vector<const TraceRecord*>& records, SetupSplit* out) {
  PooledOwnTrend(records, &out->own_coeff_per_deg2, &out->own_coeff_std_per_deg2, &out->n_own);
}

// The cut of the I-sorted logs into two clusters of >= 2 with the least scatter within them.
void BestCut(const std::vector<double>& v, const std::vector<double>& s, SetupSplit* out) {
  const int k = static_cast<int>(v.size());
  std::vector<int> order(k);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return v[a] < v[b]; });
  double best_q = INFINITY;
  for (int cut = 2; cut <= k - 2; ++cut) {
    const std::vector<int> lo(order.begin(), order.begin() + cut),
        hi(order.begin() + cut, order.end());
    const WeightedMean a = Weighted(v, s, lo), b = Weighted(v, s, hi);
    if (a.q + b.q >= best_q) continue;
    best_q = a.q + b.q;
    const double birge = best_q > k - 2 ? std::sqrt(best_q / (k - 2)) : 1.0;
    out->clusters = {lo, hi};
    out->mean_kg_m2 = {a.mean, b.mean};
    out->mean_std_kg_m2 = {a.std * birge, b.std * birge};
  }
  const double gap = out->mean_kg_m2[1] - out->mean_kg_m2[0];
  out->gap_percent = 100.0 * gap / out->mean_kg_m2[0];
  out->gap_z = gap / std::hypot(out->mean_std_kg_m2[0], out->mean_std_kg_m2[1]);
  double range = 0.0;
  for (const std::vector<int>& c : out->clusters) {
    double lo = INFINITY, hi = -INFINITY;
    for (int i : c) {
      lo = std::min(lo, v[i]);
      hi = std::max(hi, v[i]);
    }
    range = std::max(range, hi - lo);
  }
  out->separation = range > 0.0 ? gap / range : INFINITY;
}

// Whether the clusters' amplitudes interleave, and the gap the logs' own trends allow.
void AmplitudeExplanation(const std::vector<const TraceRecord*>& records, SetupSplit* out) {
  std::array<double, 2> lo = {INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY}, mean_a2 = {0, 0};
  for (int c = 0; c < 2; ++c) {
    for (int i : out->clusters[c]) {
      const double a2 = ResultAmplitudeSquared(*records[i]);
      lo[c] = std::min(lo[c], a2);
      hi[c] = std::max(hi[c], a2);
      mean_a2[c] += a2 / out->clusters[c].size();
    }
    out->amplitude_rms_deg[c] = std::sqrt(mean_a2[c]);
  }
  // A monotonic I(A) puts one cluster's amplitudes wholly above the other's.
  out->amplitudes_interleave = !(lo[0] > hi[1] || lo[1] > hi[0]);
  PoolOwnTrends(records, out);
  if (out->n_own == 0) return;
  const double bound =
      std::abs(out->own_coeff_per_deg2) + kOwnTrendSigmas * out->own_coeff_std_per_deg2;
  out->amplitude_allows_percent = 100.0 * bound * std::abs(mean_a2[1] - mean_a2[0]);
  const double allowed = out->amplitude_allows_percent / 100.0 * out->mean_kg_m2[0];
  out->gap_z_beyond_amplitude = (out->mean_kg_m2[1] - out->mean_kg_m2[0] - allowed) /
                                std::hypot(out->mean_std_kg_m2[0], out->mean_std_kg_m2[1]);
}

// The clusters' swing axes in the IMU frame (a unit axis and its negative are one axis).
void CompareAxes(const std::vector<const TraceRecord*>& records, SetupSplit* out) {
  const auto axis = [&](int i) {
    const std::array<double, 3>& a = records[i]->swing_axis_in_imu;
    return a;
  };
  const std::array<double, 3> ref = axis(out->clusters[0][0]);
  for (double x : ref) {
    if (!std::isfinite(x)) return;
  }
  const auto aligned = [&](int i) {  // the sign nearest the reference
    std::array<double, 3> a = axis(i);
    const double dot = a[0] * ref[0] + a[1] * ref[1] + a[2] * ref[2];
    if (dot < 0.0)
      for (double& x : a) x = -x;
    return a;
  };
  const auto angle = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    const double nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    const double dot = std::abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (na * nb);
    return std::acos(std::clamp(dot, 0.0, 1.0)) * kDegPerRad;
  };
  std::array<std::array<double, 3>, 2> mean = {{{0, 0, 0}, {0, 0, 0}}};
  std::array<double, 3> all = {0, 0, 0};
  for (int c = 0; c < 2; ++c) {
    for (int i : out->clusters[c]) {
      const std::array<double, 3> a = aligned(i);
      for (double x : a) {
        if (!std::isfinite(x)) return;
      }
      for (int k = 0; k < 3; ++k) {
        mean[c][k] += a[k];
        all[k] += a[k];
      }
    }
  }
  out->imu_axis = static_cast<int>(
      std::max_element(all.begin(), all.end(),
                       [](double a, double b) { return std::abs(a) < std::abs(b); }) -
      all.begin());
  std::array<double, 3> unit = {0, 0, 0};
  unit[out->imu_axis] = 1.0;
  out->axis_spread_deg = 0.0;
  for (int c = 0; c < 2; ++c) {
    out->axis_from_imu_deg[c] = {INFINITY, -INFINITY};
    for (int i : out->clusters[c]) {
      const double from_imu = angle(aligned(i), unit);
      out->axis_from_imu_deg[c][0] = std::min(out->axis_from_imu_deg[c][0], from_imu);
      out->axis_from_imu_deg[c][1] = std::max(out->axis_from_imu_deg[c][1], from_imu);
      out->axis_spread_deg = std::max(out->axis_spread_deg, angle(aligned(i), mean[c]));
    }
  }
  out->axis_angle_deg = angle(mean[0], mean[1]);
  out->axes_differ = out->axis_angle_deg >= kAxisMinDeg &&
                     out->axis_angle_deg >= kAxisOverSpread * out->axis_spread_deg;
}

// Steps 2-4 of the header on a group whose Q rejected one value.
void Decide(const std::vector<const TraceRecord*>& records, SetupSplit* out) {
  const double z_needed = out->axes_differ ? kGapZWithAxes : kGapZ;
  char text[320];
  if (!(out->gap_z >= z_needed) || !(out->separation >= kSeparation)) {
    std::snprintf(text, sizeof(text),
                  "no two clusters: the best cut leaves a gap of %.1f sigma (needs %.0f) and %.1f "
                  "times the range within a cluster (needs %.0f)",
                  out->gap_z, z_needed, out->separation, kSeparation);
    out->note = text;
    return;
  }
  if (out->n_own == 0) {  // no own trend: only amplitudes that interleave rule amplitude out
    out->two_setups = out->amplitudes_interleave;
    if (!out->two_setups) {
      out->note =
          "two clusters, but released at different amplitudes and no log measured its "
          "own I(A) trend: amplitude and set-up cannot be told apart";
    }
    return;
  }
  if (!(out->gap_z_beyond_amplitude >= z_needed)) {
    std::snprintf(text, sizeof(text),
                  "two clusters, but their release amplitudes may explain them: the logs' own "
                  "I(A) trends allow up to %.2f %% between them (gap %.2f %%)",
                  out->amplitude_allows_percent, out->gap_percent);
    out->note = text;
    return;
  }
  out->two_setups = true;
  (void)records;
}

std::string Names(std::vector<int> which, const std::vector<std::string>& names) {
  std::sort(which.begin(), which.end());
  std::string out;
  for (size_t k = 0; k < which.size(); ++k) {
    out += (k ? ", " : "") + names[which[k]];
  }
  return out;
}

}  // namespace

double ResultAmplitudeSquared(const TraceRecord& r) {
  if (r.inertia_source == "low_amplitude_band" && r.sweep.low_band >= 0 &&
      r.sweep.low_band < static_cast<int>(r.sweep.bands.size())) {
    const double a = r.sweep.bands[r.sweep.low_band].amplitude_mean_deg;
    return a * a;
  }
  return 0.5 * (r.amplitude_deg[0] * r.amplitude_deg[0] + r.amplitude_deg[1] * r.amplitude_deg[1]);
}

bool PooledOwnTrend(const std::vector<const TraceRecord*>& records, double* coeff_per_deg2,
                    double* coeff_std_per_deg2, int* n_logs) {
  std::vector<double> c, s;
  for (const TraceRecord* r : records) {
    double ci = 0.0, si = 0.0;
    if (OwnTrendAsSquare(*r, &ci, &si)) {
      c.push_back(ci);
      s.push_back(si);
    }
  }
  if (c.empty()) return false;
  std::vector<int> all(c.size());
  std::iota(all.begin(), all.end(), 0);
  const WeightedMean m = Weighted(c, s, all);
  const int dof = static_cast<int>(c.size()) - 1;
  *coeff_per_deg2 = m.mean;
  *coeff_std_per_deg2 = m.std * (dof > 0 && m.q > dof ? std::sqrt(m.q / dof) : 1.0);
  *n_logs = static_cast<int>(c.size());
  return true;
}

SetupSplit TestTwoSetups(const std::vector<const TraceRecord*>& records) {
  SetupSplit out;
  const int k = static_cast<int>(records.size());
  if (k < 4) {
    out.note = "fewer than 4 usable repeats (two set-ups need 2 each)";
    return out;
  }
  std::vector<double> v, s;
  for (const TraceRecord* r : records) {
    v.push_back(r->inertia_total_kg_m2);
    s.push_back(r->inertia_total_std_kg_m2);
  }
  std::vector<int> all(k);
  std::iota(all.begin(), all.end(), 0);
  out.q = Weighted(v, s, all).q;
  // Q's p from its chi^2 tail, reported as the normal z of the same tail (-z of the tail keeps
  // its digits where the tail is tiny).
  const double p = ChiSquareUpperTail(out.q, k - 1);
  out.q_z = -NormalQuantile(p);
  if (!(p < kQp)) {
    out.note = "the repeats agree within their stds (Q's p >= 0.001)";
    return out;
  }
  out.tested = true;
  BestCut(v, s, &out);
  AmplitudeExplanation(records, &out);
  CompareAxes(records, &out);
  Decide(records, &out);
  return out;
}

std::string TwoSetupsText(const SetupSplit& split, const std::vector<std::string>& names) {
  if (!split.two_setups) return "";
  char text[640];
  std::snprintf(text, sizeof(text),
                "two set-ups, not one: %s at I = %#.5g +- %.2g kg m^2 and %s at "
                "I = %#.5g +- %.2g kg m^2, %.1f %% apart (%.0f sigma, Q = %.0f on %d dof)",
                Names(split.clusters[0], names).c_str(), split.mean_kg_m2[0],
                split.mean_std_kg_m2[0], Names(split.clusters[1], names).c_str(),
                split.mean_kg_m2[1], split.mean_std_kg_m2[1], split.gap_percent, split.gap_z,
                split.q, static_cast<int>(split.clusters[0].size() + split.clusters[1].size()) - 1);
  std::string out = text;
  if (split.n_own == 0) {
    std::snprintf(text, sizeof(text),
                  "; not the release amplitude: the clusters were released at the same amplitudes "
                  "(RMS %.1f and %.1f deg)",
                  split.amplitude_rms_deg[0], split.amplitude_rms_deg[1]);
  } else {
    std::snprintf(text, sizeof(text),
                  "; not the release amplitude (RMS %.1f and %.1f deg): the logs' own I(A) trends "
                  "allow at most %.2g %% between them",
                  split.amplitude_rms_deg[0], split.amplitude_rms_deg[1],
                  split.amplitude_allows_percent);
  }
  out += text;
  if (split.imu_axis >= 0) {
    const char axis = "xyz"[split.imu_axis];
    std::snprintf(text, sizeof(text),
                  "; swing axes %.1f-%.1f deg and %.1f-%.1f deg from the IMU %c axis (%.1f deg "
                  "apart%s)",
                  split.axis_from_imu_deg[0][0], split.axis_from_imu_deg[0][1],
                  split.axis_from_imu_deg[1][0], split.axis_from_imu_deg[1][1], axis,
                  split.axis_angle_deg,
                  split.axes_differ ? ": a different hanging" : ", as within a cluster");
    out += text;
  }
  return out;
}

}  // namespace bifilar
