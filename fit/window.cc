// The free-oscillation window of one log (fit/window.h): the noise and bias from the rest, the
// half-cycles of the rate, the runs of free oscillation and the longest one, a user's window
// checked (ApplyWindowOverride, ParseWindowSpec). The amplitude band is amplitude_band.cc.
#include "fit/window.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "base/csv.h"
#include "base/enum_names.h"
#include "base/option_check.h"
#include "base/statistics.h"
#include "base/text_format.h"
#include "base/units.h"
#include "fit/window_steps.h"

namespace bifilar {
namespace window {

std::string Prefix(const std::string& name) { return name.empty() ? "" : name + ": "; }

// Half-cycles with hysteresis h on x.
std::vector<HalfCycle> HalfCycles(const std::vector<double>& t, const std::vector<double>& x,
                                  size_t begin, size_t end, double h) {
  std::vector<HalfCycle> out;
  int state = 0;
  for (size_t i = begin; i < end; ++i) {
    const int s = x[i] > h ? 1 : (x[i] < -h ? -1 : 0);
    if (s != 0 && s != state) {  // a new half-cycle; its start is set below
      HalfCycle c;
      c.sign = s;
      c.start_s = t[i];
      c.peak_index = i;
      c.peak = s * x[i];
      c.robust_peak = -HUGE_VAL;
      c.robust_peak_index = i;
      out.push_back(c);
      state = s;
    }
    if (!out.empty() && s == state) ++out.back().samples_beyond;
    if (!out.empty() && state * x[i] > out.back().peak) {
      out.back().peak = state * x[i];
      out.back().peak_index = i;
    }
    if (!out.empty()) {
      double neighbour = -HUGE_VAL;
      if (i > begin) neighbour = std::max(neighbour, state * x[i - 1]);
      if (i + 1 < end) neighbour = std::max(neighbour, state * x[i + 1]);
      const double capped = std::min(state * x[i], neighbour);
      if (capped > out.back().robust_peak) {
        out.back().robust_peak = capped;
        out.back().robust_peak_index = i;
      }
    }
  }
  for (HalfCycle& c : out) c.robust_peak = std::max(c.robust_peak, 0.0);
  if (!out.empty()) {
    out.back().end_s = t[end - 1];
    out.back().open = true;
  }
  // A half-cycle starts at the last zero crossing before its peak (not before its first threshold
  // crossing): a tremor lobe of the same sign just before the release must not stretch it.
  for (size_t j = 0; j < out.size(); ++j) {
    const int s = out[j].sign;
    const size_t lo = j > 0 ? out[j - 1].peak_index : begin;
    for (size_t k = out[j].peak_index; k > lo; --k) {
      if (s * x[k - 1] <= 0.0) {
        const double x0 = x[k - 1], x1 = x[k];
        const double f = (x1 != x0) ? -x0 / (x1 - x0) : 0.0;
        out[j].start_s = t[k - 1] + std::clamp(f, 0.0, 1.0) * (t[k] - t[k - 1]);
        break;
      }
    }
    if (j > 0) out[j - 1].end_s = out[j].start_s;
  }
  return out;
}

size_t FirstAtOrAfter(const std::vector<double>& t, double t0) {
  return std::lower_bound(t.begin(), t.end(), t0) - t.begin();
}
size_t LastAtOrBefore(const std::vector<double>& t, double t1) {
  const size_t e = std::upper_bound(t.begin(), t.end(), t1) - t.begin();
  return e == 0 ? 0 : e - 1;
}

namespace {

// A window [first, last] of samples with a gap (a step between two samples) longer than
// max_gap_periods periods cannot be fitted as one swing: the phase across it is not observed
// (and the two sides may be different swings). False with *message naming the longest gap.
bool GapFree(const std::vector<double>& t, size_t first, size_t last, double period_s,
             const WindowOptions& o, const std::string& name, std::string* message) {
  if (!(period_s > 0.0) || last >= t.size()) return true;
  double longest = 0.0;
  size_t at = first;
  for (size_t k = first; k < last; ++k) {
    if (t[k + 1] - t[k] > longest) {
      longest = t[k + 1] - t[k];
      at = k;
    }
  }
  if (longest <= o.max_gap_periods * period_s) return true;
  *message = Prefix(name) + Fmt("a gap of %.3g s without samples (from %.3f s", longest, t[at]) +
             Fmt(" to %.3f s) lies inside the window", t[at + 1]) + Fmt(" [%.3f, ", t[first]) +
             Fmt("%.3f] s", t[last]) + Fmt(", longer than %g period(s)", o.max_gap_periods) +
             Fmt(" (%.3f s): the swing cannot be followed across it; give a window on one side "
                 "of it (fit.windows or --window)",
                 period_s);
  return false;
}

// Noise, bias and half-cycles of a series.
struct Analysis {
  double sigma = 0.0;
  bool from_rest = false;
  double bias = 0.0;
  double rest_end_s = 0.0;
  int rest_samples = 0;
  double range = 0.0;
  std::vector<double> x;
  std::vector<HalfCycle> cycles;
};

}  // namespace
}  // namespace window

double NeighbourCubicResidual(const std::vector<double>& t, const std::vector<double>& x, size_t k,
                              const size_t idx[4]) {
  double pred = 0.0, w2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    double w = 1.0;
    for (int j = 0; j < 4; ++j) {
      if (j != i) w *= (t[k] - t[idx[j]]) / (t[idx[i]] - t[idx[j]]);
    }
    pred += w * x[idx[i]];
    w2 += w * w;
  }
  return (x[k] - pred) / std::sqrt(1.0 + w2);
}

namespace window {
namespace {

// Noise of a smooth signal sampled at irregular times: each sample is predicted by the cubic
// through its two neighbours on each side, at the real timestamps (so jitter and single drops do
// not count as noise); the residual, divided by sqrt(1 + sum of squared weights) to make its std
// equal to the sample noise, goes into a MAD (1.4826 * median |r|). The cubic's error,
// ~|d4x/dt4| (2 dt)^4 / 24, is below 1 % of 0.25 deg/s for any swing in range at 100 Hz.
double HighFrequencySigma(const std::vector<double>& t, const std::vector<double>& r) {
  std::vector<double> res;
  if (t.size() < 5) return 0.0;
  res.reserve(t.size() - 4);
  for (size_t k = 2; k + 2 < t.size(); ++k) {
    const size_t idx[4] = {k - 2, k - 1, k + 1, k + 2};
    res.push_back(std::abs(NeighbourCubicResidual(t, r, k, idx)));
  }
  return 1.482602218505602 * Median(res);
}

// Initial rest: blocks whose scatter and mean agree with the first block.
void FindRest(const std::vector<double>& t, const std::vector<double>& r, double sigma_hf,
              const WindowOptions& o, Analysis* a) {
  const size_t n = t.size();
  std::vector<size_t> block_end;
  size_t i = 0;
  while (i < n) {
    size_t e = i;
    while (e < n && t[e] - t[i] < o.rest_block_s) ++e;
    block_end.push_back(e);
    i = e;
  }
  auto stats = [&](size_t b, size_t e, double* mean, double* sd) {
    double s = 0, s2 = 0;
    for (size_t k = b; k < e; ++k) s += r[k];
    *mean = s / static_cast<double>(e - b);
    for (size_t k = b; k < e; ++k) s2 += (r[k] - *mean) * (r[k] - *mean);
    *sd = std::sqrt(s2 / std::max<double>(1.0, static_cast<double>(e - b) - 1.0));
  };
  if (block_end.size() < 2 || block_end[0] < 5) return;
  double mean0, sd0;
  stats(0, block_end[0], &mean0, &sd0);
  // Rest shows no more scatter than the high-frequency noise (x2.5: jitter inflates sigma_hf on a
  // swinging log, never the other way round).
  if (!(sd0 <= 2.5 * sigma_hf) && !(sd0 == 0.0 && sigma_hf == 0.0)) return;
  // Blocks join the rest while their scatter and mean agree with the rest so far (2x the std;
  // 5 standard errors of the mean: a false break has a probability of ~1e-6 per block).
  double sum = 0.0, sum2 = 0.0;
  size_t count = 0, accepted = 0, begin = 0;
  for (size_t b = 0; b < block_end.size(); ++b) {
    const size_t e = block_end[b];
    double mean, sd;
    stats(begin, e, &mean, &sd);
    const double rest_mean = count ? sum / count : mean0;
    const double rest_sd =
        count > 1 ? std::sqrt(std::max(0.0, (sum2 - sum * sum / count) / (count - 1.0))) : sd0;
    const double sd_ref = std::max(rest_sd, 1e-12);
    const double m = static_cast<double>(e - begin);
    if (e - begin < 3 || sd > 2.0 * sd_ref ||
        std::abs(mean - rest_mean) > 5.0 * sd_ref / std::sqrt(m))
      break;
    for (size_t k = begin; k < e; ++k) {
      sum += r[k];
      sum2 += r[k] * r[k];
    }
    count += e - begin;
    ++accepted;
    begin = e;
  }
  // Drop the last accepted block: the twist may have begun inside it.
  if (accepted < 2) return;
  const size_t rest_end = block_end[accepted - 2];
  if (t[rest_end - 1] - t[0] < o.min_rest_s) return;
  double s = 0.0;
  for (size_t k = 0; k < rest_end; ++k) s += r[k];
  const double mean = s / static_cast<double>(rest_end);
  double s2 = 0.0;
  for (size_t k = 0; k < rest_end; ++k) s2 += (r[k] - mean) * (r[k] - mean);
  a->from_rest = true;
  a->bias = mean;
  a->sigma = std::sqrt(s2 / static_cast<double>(rest_end - 1));
  a->rest_end_s = t[rest_end - 1];
  a->rest_samples = static_cast<int>(rest_end);
}

// Noise, bias, x and half-cycles of the whole series.
bool Analyse(const std::vector<double>& t, const std::vector<double>& r, const WindowOptions& o,
             const std::string& name, Analysis* a, FreeOscillationWindow* w) {
  std::string why;
  if (!o.Check(&why)) {
    w->status = WindowStatus::kError;
    w->message = Prefix(name) + "invalid window options: " + why;
    return false;
  }
  const size_t n = t.size();
  if (r.size() != n || n < 8) {
    w->status = WindowStatus::kError;
    w->message = Prefix(name) + "the swing-rate series needs at least 8 samples (has " +
                 std::to_string(std::min(n, r.size())) + ")";
    return false;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(r[i]) || (i > 0 && !(t[i] > t[i - 1]))) {
      w->status = WindowStatus::kError;
      w->message = Prefix(name) +
                   "the swing-rate series must be finite with increasing times (sample " +
                   std::to_string(i) + ")";
      return false;
    }
  }
  const auto [mn, mx] = std::minmax_element(r.begin(), r.end());
  a->range = *mx - *mn;
  if (!(a->range > 1e-12 * (1.0 + std::abs(*mx)))) {
    w->status = WindowStatus::kRejected;
    w->message = Prefix(name) + "constant data: the swing rate does not change";
    return false;
  }
  const double sigma_hf = HighFrequencySigma(t, r);
  FindRest(t, r, sigma_hf, o, a);
  if (!a->from_rest) {
    a->sigma = sigma_hf;
    a->bias = Median(r);
  }
  a->x.resize(n);
  for (size_t i = 0; i < n; ++i) a->x[i] = r[i] - a->bias;
  const double sigma_eff = std::max({a->sigma, 1e-6 * a->range, 1e-12});
  a->cycles = HalfCycles(t, a->x, 0, n, o.hysteresis_sigmas * sigma_eff);
  w->noise_sigma_rad_per_s = a->sigma;
  w->noise_from_rest = a->from_rest;
  w->rest_bias_rad_per_s = a->bias;
  w->rest_end_s = a->rest_end_s;
  w->rest_samples = a->rest_samples;
  return true;
}

// The half-cycle duration that covers most time among cycles above `min_peak`.
double HalfPeriod(const std::vector<HalfCycle>& cycles, double min_peak, const WindowOptions& o) {
  std::vector<double> d;
  for (const auto& c : cycles) {
    if (!c.open && c.peak >= min_peak && c.duration() >= 0.5 * o.min_period_s &&
        c.duration() <= 0.5 * o.max_period_s) {
      d.push_back(c.duration());
    }
  }
  double best = 0.0, best_score = 0.0;
  for (double di : d) {
    double score = 0.0;
    for (double dj : d)
      if (dj >= di / 1.2 && dj <= di * 1.2) score += dj;
    if (score > best_score) {
      best_score = score;
      best = di;
    }
  }
  if (best == 0.0) return 0.0;
  std::vector<double> near;
  for (double dj : d)
    if (dj >= best / 1.2 && dj <= best * 1.2) near.push_back(dj);
  return Median(near);
}

void FillPeaks(const Analysis& a, FreeOscillationWindow* w) {
  bool first = true;
  for (const auto& c : a.cycles) {
    if (c.peak_index >= w->first_index && c.peak_index <= w->last_index) {
      if (first) w->peak_rate_start_rad_per_s = c.peak;
      first = false;
      w->peak_rate_end_rad_per_s = c.peak;
    }
  }
}

}  // namespace
}  // namespace window

constexpr EnumName<WindowStatus> kWindowStatusNames[] = {{WindowStatus::kOk, "ok"},
                                                         {WindowStatus::kRejected, "rejected"},
                                                         {WindowStatus::kError, "error"}};
constexpr EnumName<WindowEnd> kWindowEndNames[] = {{WindowEnd::kLogEnd, "log_end"},
                                                   {WindowEnd::kNoiseFloor, "noise_floor"},
                                                   {WindowEnd::kStopped, "stopped"},
                                                   {WindowEnd::kOverride, "override"}};

const char* ToString(WindowStatus status) { return EnumToString(kWindowStatusNames, status, "?"); }
const char* ToString(WindowEnd end) { return EnumToString(kWindowEndNames, end, "?"); }

bool WindowOptions::Check(std::string* why) const {
  CheckFailure f;
  const bool ok = CheckGt("min_period_s", min_period_s, 0, &f) &&
                  CheckGt("max_period_s", max_period_s, "min_period_s", min_period_s, &f) &&
                  CheckGt("rest_block_s", rest_block_s, 0, &f) &&
                  CheckGt("min_rest_s", min_rest_s, 0, &f) &&
                  CheckGt("hysteresis_sigmas", hysteresis_sigmas, 0, &f) &&
                  CheckIn("half_period_tolerance", half_period_tolerance, 0, 1, Ends::kOpen, &f) &&
                  CheckGe("growth_tolerance", growth_tolerance, 0, &f) &&
                  CheckIn("stop_drop_factor", stop_drop_factor, 0, 1, Ends::kOpen, &f) &&
                  CheckGt("noise_floor_sigmas", noise_floor_sigmas, 0, &f) &&
                  CheckGe("start_delay_periods", start_delay_periods, 0, &f) &&
                  CheckGe("end_margin_periods", end_margin_periods, 0, &f) &&
                  CheckGt("min_periods", min_periods, 0, &f) &&
                  CheckIn("blip_fraction", blip_fraction, 0, 0.5, Ends::kClosedOpen, &f) &&
                  CheckGt("max_gap_periods", max_gap_periods, 0, &f);
  return ok || FailWith(f, why, "window: ");
}

std::string FreeOscillationWindow::BriefReport() const {
  if (status != WindowStatus::kOk) return std::string(ToString(status)) + ": " + message;
  return Fmt("window [%.3f, %.3f] s", t0_s, t1_s) + " (" + ToString(end_reason) + ")" +
         Fmt(", period %.3f s, noise %.3g rad/s", period_s, noise_sigma_rad_per_s) +
         (noise_from_rest ? " (rest)" : " (no rest: high-frequency estimate)");
}

namespace window {
namespace {

// What a free half-cycle looks like at this half period and noise floor.
struct HalfCycleRules {
  const std::vector<double>& t;
  const WindowOptions& o;
  double half = 0.0;        // half period, s
  double floor = 0.0;       // noise floor, rad/s
  double sigma_eff = 0.0;   // noise, rad/s
  double dt_typical = 0.0;  // median time step, s

  // Dropped packets: a half-cycle with a gap longer than 2.5 typical steps may have lost its
  // peak, so its peak is not compared, and its duration gets the gap as extra slack.
  bool Gappy(const HalfCycle& c) const { return c.max_gap_s > 2.5 * dt_typical; }

  bool DurationOk(const HalfCycle& c) const {
    const double slack = Gappy(c) ? c.max_gap_s : 0.0;
    if (c.open) {
      // The log ended inside it: fine unless the swing should have crossed zero by now (a quarter
      // period after the peak), which means it was stopped or died out.
      return c.duration() <= (1.0 + o.half_period_tolerance) * half + slack &&
             c.end_s - t[c.robust_peak_index] <=
                 0.5 * (1.0 + o.half_period_tolerance) * half + slack;
    }
    // A free half-cycle peaks near its middle: the rate must cross zero again within about a
    // quarter period of the peak (a hand that grabs near a peak leaves a long, flat tail).
    return std::abs(c.duration() - half) <= o.half_period_tolerance * half + slack &&
           c.end_s - t[c.robust_peak_index] <= 0.5 * (1.0 + o.half_period_tolerance) * half + slack;
  }
};

// The half-cycles with their longest time step (dropped packets); returns the median step.
double MarkPacketGaps(const std::vector<double>& t, std::vector<HalfCycle>* cycles) {
  std::vector<double> steps(t.size() - 1);
  for (size_t k = 0; k + 1 < t.size(); ++k) steps[k] = t[k + 1] - t[k];
  const double dt_typical = Median(steps);
  for (auto& c : *cycles) {
    const size_t b = std::lower_bound(t.begin(), t.end(), c.start_s) - t.begin();
    const size_t e = std::upper_bound(t.begin(), t.end(), c.end_s) - t.begin();
    for (size_t k = (b > 0 ? b - 1 : 0); k + 1 < t.size() && k < e; ++k) {
      c.max_gap_s = std::max(c.max_gap_s, steps[k]);
    }
  }
  return dt_typical;
}

// 3b. A glitch that split a half-cycle inside the swing (between two whole half-cycles, or one
// and the log's end): merged back, so it neither breaks the run nor moves t0. Tremor lobes
// (around the release or a stop) have short lobes around them and stay as they are.
std::vector<HalfCycle> MergeGlitchSplitHalfCycles(const std::vector<HalfCycle>& cycles,
                                                  const HalfCycleRules& rules) {
  return MergeGlitchSplits(
      cycles, rules.o.blip_fraction * rules.half,
      [&](const HalfCycle& joined, const HalfCycle& before, const HalfCycle& after,
          const HalfCycle* outer_before, const HalfCycle* outer_after) {
        return rules.DurationOk(joined) && joined.robust_peak >= rules.floor &&
               !(rules.DurationOk(before) && rules.DurationOk(after)) && outer_before &&
               !outer_before->open && rules.DurationOk(*outer_before) &&
               (!outer_after || rules.DurationOk(*outer_after));
      });
}

// A run of free oscillation.
struct Run {
  size_t first = 0, last = 0;  // cycle indices, inclusive
  WindowEnd end = WindowEnd::kLogEnd;
};

// Runs of free oscillation: half-cycles of the right duration whose peaks decay steadily; a run
// ends at a drop (a hand), the noise floor, a wrong duration, or a push.
std::vector<Run> FreeRuns(const std::vector<HalfCycle>& cycles, const HalfCycleRules& rules) {
  const WindowOptions& o = rules.o;
  const double half = rules.half, floor = rules.floor, sigma_eff = rules.sigma_eff;
  std::vector<Run> runs;
  bool in_run = false;
  Run run;
  std::vector<double> ratios;  // peak ratio per half-cycle, from reliable peaks
  double ref_peak = 0.0;       // last reliable peak of the run and its index
  size_t ref_index = 0;
  for (size_t j = 0; j < cycles.size(); ++j) {
    const HalfCycle& c = cycles[j];
    if (in_run) {
      double rho = 1.0;
      if (!ratios.empty()) {
        std::vector<double> recent(ratios.end() - std::min<size_t>(ratios.size(), 8), ratios.end());
        rho = std::min(1.0, Median(recent));
      }
      const double n_steps = static_cast<double>(j - ref_index);
      const double prev = ref_peak * std::pow(rho, n_steps - 1.0);  // expected previous peak
      const bool short_open = c.open && c.duration() < 0.8 * half;  // peak maybe not reached yet
      const bool unreliable = short_open || rules.Gappy(c) || ref_peak <= 0.0;
      WindowEnd reason = WindowEnd::kLogEnd;
      bool broken = false;
      bool restart = false;
      if (!unreliable && c.robust_peak < o.stop_drop_factor * rho * prev) {
        broken = true;  // a hand (checked first: a stopped swing also ends below the noise floor)
        reason = WindowEnd::kStopped;
      } else if (!unreliable && c.robust_peak < floor) {
        broken = true;
        reason = WindowEnd::kNoiseFloor;
      } else if (!rules.DurationOk(c)) {
        broken = true;
        reason = c.robust_peak < floor || prev < 2.0 * floor ? WindowEnd::kNoiseFloor
                                                             : WindowEnd::kStopped;
      } else if (!unreliable &&
                 c.robust_peak > prev * (1.0 + o.growth_tolerance) + 3.0 * sigma_eff) {
        broken = true;
        reason = WindowEnd::kStopped;  // pushed: the free decay is broken
        restart = true;
      }
      if (!broken) {
        if (!short_open && !rules.Gappy(c)) {
          if (ref_peak > 0.0) ratios.push_back(std::pow(c.robust_peak / ref_peak, 1.0 / n_steps));
          ref_peak = c.robust_peak;
          ref_index = j;
        }
        run.last = j;
        continue;
      }
      run.end = reason;
      runs.push_back(run);
      in_run = false;
      if (!restart) continue;
    }
    if (!c.open && rules.DurationOk(c) && c.robust_peak >= floor) {
      in_run = true;
      run = Run();
      run.first = run.last = j;
      ratios.clear();
      ref_peak = rules.Gappy(c) ? 0.0 : c.robust_peak;  // 0: no reliable peak yet
      ref_index = j;
    }
  }
  if (in_run) {
    run.end = WindowEnd::kLogEnd;
    runs.push_back(run);
  }
  return runs;
}

// The longest run in time with at least two half-cycles, or null.
const Run* LongestRun(const std::vector<Run>& runs, const std::vector<HalfCycle>& cycles) {
  const Run* best = nullptr;
  double best_span = 0.0;
  for (const auto& rn : runs) {
    const double span = cycles[rn.last].end_s - cycles[rn.first].start_s;
    if (rn.last > rn.first && span > best_span) {
      best_span = span;
      best = &rn;
    }
  }
  return best;
}

// Window end of a run that lasts to the log's end. A swing stopped by hand shortly before the
// log ends leaves a quiet tail inside the last, open half-cycle: 3 or more samples with |rate|
// below the noise floor over more than a tenth of a period, which a free swing never shows (it
// is below the floor for about floor/peak of a period around each crossing). The window then
// ends half a period before the tail, clear of the hand.
void TrimHandStopTail(const std::vector<double>& t, const Analysis& a, double floor, double period,
                      FreeOscillationWindow* w) {
  w->t1_s = t.back();
  size_t k = a.x.size();
  while (k > 0 && std::abs(a.x[k - 1]) < floor) --k;
  if (k > 0 && a.x.size() - k >= 3 && t.back() - t[k - 1] > 0.1 * period) {
    w->t1_s = t[k - 1] - 0.5 * period;
    w->end_reason = WindowEnd::kStopped;
  }
}

// No rest: bias = mean rate over whole periods of the free oscillation.
void BiasFromRun(const std::vector<double>& t, const std::vector<double>& r,
                 const std::vector<HalfCycle>& cycles, const Run& best, size_t closed_last,
                 FreeOscillationWindow* w) {
  double s = 0.0;
  size_t count = 0;
  const size_t b = FirstAtOrAfter(t, cycles[best.first].start_s);
  const size_t e = LastAtOrBefore(t, cycles[closed_last].end_s);
  for (size_t k = b; k <= e && k < t.size(); ++k, ++count) s += r[k];
  if (count > 0) w->rest_bias_rad_per_s = s / count;
}

// Why a window shorter than min_periods periods is rejected.
std::string TooShortMessage(const std::vector<double>& t, const std::vector<HalfCycle>& cycles,
                            const Run& best, double period, const WindowOptions& o,
                            const std::string& name, const FreeOscillationWindow& w) {
  if (w.t1_s > w.t0_s) {
    return Prefix(name) +
           Fmt("free oscillation shorter than %g periods: [%.3f, ", o.min_periods, w.t0_s) +
           Fmt("%.3f] s with a period of %.3f s", w.t1_s, period) +
           " (ends: " + ToString(best.end) + ")";
  }
  // The swing ends before a window can start (after the first extreme): say what was found.
  const double end_s = best.end == WindowEnd::kLogEnd ? t.back() : cycles[best.last].end_s;
  return Prefix(name) +
         Fmt("free oscillation shorter than %g periods: the swing released at ", o.min_periods) +
         Fmt("%.3f s ends at ", w.release_s) + Fmt("%.3f s", end_s) + " (" + ToString(best.end) +
         Fmt("), %.2f periods", (end_s - w.release_s) / period) +
         Fmt(" of %.3f s later, before a window could start (at ", period) +
         Fmt("%.3f s, after the first extreme)", w.t0_s);
}

}  // namespace
}  // namespace window

FreeOscillationWindow FindFreeOscillationWindow(const std::vector<double>& t,
                                                const std::vector<double>& r,
                                                const WindowOptions& o, const std::string& name) {
  using namespace window;  // the shared steps (window_steps.h)
  FreeOscillationWindow w;
  Analysis a;
  if (!Analyse(t, r, o, name, &a, &w)) return w;
  const double sigma_eff = std::max({a.sigma, 1e-6 * a.range, 1e-12});
  const double floor = o.noise_floor_sigmas * sigma_eff;
  double max_peak = 0.0;
  for (const auto& c : a.cycles) max_peak = std::max(max_peak, c.peak);
  const double half = HalfPeriod(a.cycles, std::max(floor, 0.1 * max_peak), o);
  if (half <= 0.0) {
    w.no_oscillation_found = true;
    w.message = Prefix(name) + Fmt("no oscillation found (no swing with a period in [%g, %g] s "
                                   "above the noise floor of %.3g rad/s)",
                                   o.min_period_s, o.max_period_s, floor);
    return w;
  }
  std::vector<HalfCycle> cycles = a.cycles;
  const double dt_typical = MarkPacketGaps(t, &cycles);
  const HalfCycleRules rules{t, o, half, floor, sigma_eff, dt_typical};
  cycles = MergeGlitchSplitHalfCycles(cycles, rules);
  const std::vector<Run> runs = FreeRuns(cycles, rules);
  const Run* best = LongestRun(runs, cycles);
  if (!best) {
    w.no_oscillation_found = true;
    w.message = Prefix(name) +
                "no oscillation found (no sequence of half-cycles that decays like a "
                "free swing)";
    return w;
  }
  // Mean period over the closed half-cycles of the run.
  size_t closed_last = best->last;
  if (cycles[closed_last].open && closed_last > best->first) --closed_last;
  const double period = 2.0 * (cycles[closed_last].end_s - cycles[best->first].start_s) /
                        (closed_last - best->first + 1);
  w.period_s = period;
  w.release_s = cycles[best->first].start_s;
  w.end_reason = best->end;
  w.t0_s = cycles[best->first].end_s + o.start_delay_periods * period;
  switch (best->end) {
    case WindowEnd::kLogEnd:
      TrimHandStopTail(t, a, floor, period, &w);
      break;
    case WindowEnd::kNoiseFloor:
      w.t1_s = cycles[best->last].end_s;
      break;
    default:
      w.t1_s = t[cycles[best->last].peak_index] - o.end_margin_periods * period;
      break;
  }
  if (!a.from_rest) BiasFromRun(t, r, cycles, *best, closed_last, &w);
  if (w.t1_s - w.t0_s < o.min_periods * period) {
    w.status = WindowStatus::kRejected;
    w.message = TooShortMessage(t, cycles, *best, period, o, name, w);
    return w;
  }
  w.first_index = FirstAtOrAfter(t, w.t0_s);
  w.last_index = LastAtOrBefore(t, w.t1_s);
  if (!GapFree(t, w.first_index, w.last_index, period, o, name, &w.message)) {
    w.status = WindowStatus::kRejected;
    return w;
  }
  FillPeaks(a, &w);
  w.status = WindowStatus::kOk;
  return w;
}

FreeOscillationWindow ApplyWindowOverride(const std::vector<double>& t,
                                          const std::vector<double>& r, double t0_s, double t1_s,
                                          const WindowOptions& o, const std::string& name) {
  using namespace window;  // the shared steps (window_steps.h)
  FreeOscillationWindow w;
  w.overridden = true;
  w.end_reason = WindowEnd::kOverride;
  Analysis a;
  if (!Analyse(t, r, o, name, &a, &w)) return w;
  const double half_dt = 0.5 * (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  if (!std::isfinite(t0_s) || !std::isfinite(t1_s) || !(t1_s > t0_s)) {
    w.status = WindowStatus::kError;
    w.message =
        Prefix(name) + Fmt("window [%g, %g] s: the end must be after the start", t0_s, t1_s);
    return w;
  }
  if (t0_s < t.front() - half_dt || t1_s > t.back() + half_dt) {
    w.status = WindowStatus::kError;
    w.message = Prefix(name) + Fmt("window [%g, %g] s is outside the log, which spans [%g, %g] s",
                                   t0_s, t1_s, t.front(), t.back());
    return w;
  }
  w.t0_s = std::max(t0_s, t.front());
  w.t1_s = std::min(t1_s, t.back());
  w.first_index = FirstAtOrAfter(t, w.t0_s);
  w.last_index = LastAtOrBefore(t, w.t1_s);
  // Period from the half-cycles inside the window.
  const double sigma_eff = std::max({a.sigma, 1e-6 * a.range, 1e-12});
  std::vector<HalfCycle> inside;
  for (const auto& c : a.cycles) {
    if (!c.open && c.start_s >= w.t0_s && c.end_s <= w.t1_s) inside.push_back(c);
  }
  const double half = HalfPeriod(inside, o.noise_floor_sigmas * sigma_eff, o);
  if (half <= 0.0) {
    w.status = WindowStatus::kRejected;
    w.no_oscillation_found = true;
    w.message =
        Prefix(name) + Fmt("no oscillation found inside the window [%g, %g] s", w.t0_s, w.t1_s);
    return w;
  }
  w.period_s = 2.0 * half;
  if (!a.from_rest) {
    double s = 0.0;
    for (size_t k = w.first_index; k <= w.last_index; ++k) s += r[k];
    w.rest_bias_rad_per_s = s / static_cast<double>(w.last_index - w.first_index + 1);
  }
  if (w.t1_s - w.t0_s < o.min_periods * w.period_s) {
    w.status = WindowStatus::kRejected;
    w.message =
        Prefix(name) + Fmt("window [%.3f, %.3f] s is shorter than %g periods (period %.3f s)",
                           w.t0_s, w.t1_s, o.min_periods, w.period_s);
    return w;
  }
  if (!GapFree(t, w.first_index, w.last_index, w.period_s, o, name, &w.message)) {
    w.status = WindowStatus::kRejected;
    return w;
  }
  FillPeaks(a, &w);
  w.status = WindowStatus::kOk;
  return w;
}

bool ParseWindowSpec(const std::string& text, double* t0_s, double* t1_s, std::string* why) {
  const auto fail = [&](const std::string& what) {
    *why = "--window '" + text + "': " + what;
    return false;
  };
  const size_t colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) {
    return fail("expected T0:T1 in seconds, e.g. 12.5:48");
  }
  // Each side is a whole finite number (base/csv.h), white space around it allowed.
  auto parse = [](const std::string& s, double* v) {
    const size_t b = s.find_first_not_of(" \t\n\v\f\r");
    if (b == std::string::npos) return false;
    const size_t e = s.find_last_not_of(" \t");
    return e != std::string::npos && e >= b &&
           ParseNumber(std::string_view(s).substr(b, e - b + 1), v);
  };
  double a, b;
  if (!parse(text.substr(0, colon), &a) || !parse(text.substr(colon + 1), &b)) {
    return fail("expected T0:T1 in seconds, e.g. 12.5:48 (two finite numbers)");
  }
  if (!(b > a)) return fail("the end T1 must be after the start T0");
  *t0_s = a;
  *t1_s = b;
  return true;
}

}  // namespace bifilar
