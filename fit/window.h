// The free-oscillation window of one log, found on the swing rate (fit/swing_axis.h), its noise
// and bias from the rest segment (window.cc), and the amplitude band (amplitude_band.cc; issue 3
// items 3 and 4).
//
// A log (docs/physics.md §2): rest, a hand twisting and holding (with tremor), release, free
// oscillation (a decaying near-sinusoid), and an end: the log ends, the amplitude sinks into the
// noise, or a hand stops it (an abrupt decay within a fraction of a period).
//
// Method (all on x = rate - bias, at the log's real timestamps):
//  1. Noise: if the log starts with rest (0.25 s blocks whose mean and scatter match the first
//     block), sigma = std and bias = mean of the rest samples. Otherwise sigma from the
//     high-frequency residual: each sample minus the cubic through its two neighbours on each side
//     at the real timestamps, normalised, 1.4826 MAD (immune to the swing, to timestamp jitter and
//     to single drops), and bias = mean rate over whole periods of the free oscillation.
//  2. Half-cycles: the signal is cut where it crosses zero, with hysteresis (|x| must exceed
//     hysteresis_sigmas * sigma for a new half-cycle to begin); each half-cycle has a start (zero
//     crossing, interpolated), a peak |x| and a duration.
//  3. Half period: the half-cycle duration that covers most of the log's time (segments within
//     +-20 % of each other), so hand tremor (short) and the hold (long) do not count.
//     A free half-cycle must also cross zero within about a quarter period after its peak.
//     Half-cycles with a gap (dropped packets, > 2.5 typical steps) get the gap as slack and
//     their peaks are not compared (the peak may be in the gap).
//  4. Runs of free oscillation: consecutive half-cycles of consistent duration (+-
//     half_period_tolerance) whose peaks decay like a free swing: no growth beyond
//     growth_tolerance, no drop below stop_drop_factor times the decay seen so far (a hand), and
//     above noise_floor_sigmas * sigma. The longest run is the free oscillation; its first
//     half-cycle starts at the release.
//  5. t0 = end of the first half-cycle after the release (the first extreme angle, half a period
//     after release) + start_delay_periods * T. t1 = log end; or the end of the last half-cycle
//     above the noise floor; or, after a stop, the last clean peak - end_margin_periods * T.
// Never NaN: quantities that could not be estimated are 0 with a flag.
#pragma once

#include <string>
#include <vector>

namespace bifilar {

struct WindowOptions {
  double min_period_s = 0.3;       // shortest swing period considered (s); > 0. Default 0.3 s.
  double max_period_s = 10.0;      // longest (s); > min. Default 10 s (rigs swing at 1-3 s).
  double rest_block_s = 0.25;      // block length of the rest detector (s); > 0.
  double min_rest_s = 0.5;         // shortest initial rest used for the noise (s); > 0. 0.5 s at
                                   // 100 Hz gives sigma within ~7 % (1/sqrt(2 N)) at 1 sigma.
  double hysteresis_sigmas = 4.0;  // half-cycle threshold in noise sigmas; > 0. Noise alone
                                   // crosses 4 sigma once per ~16000 samples.
  double half_period_tolerance =
      0.3;                         // half-cycle duration within +-30 % of T/2; in (0, 1).
                                   // Covers the period's growth with amplitude (+7 % at 60 deg).
  double growth_tolerance = 0.15;  // a peak may exceed the previous by 15 % (+3 sigma); >= 0.
  // A peak below stop_drop_factor * (median recent peak ratio) * previous peak means a hand
  // stopped the swing. Default 0.7: free decay of a bifilar rig loses a few % per half-cycle; a
  // hand (rate decaying in ~0.1 s) loses most of it.
  double stop_drop_factor = 0.7;      // in (0, 1)
  double noise_floor_sigmas = 10.0;   // the swing ends when peaks fall below this * sigma; > 0.
  double start_delay_periods = 0.25;  // t0 after the first extreme after release (periods); >= 0.
  double end_margin_periods = 0.25;   // t1 before the last clean peak after a stop (periods); >= 0.
  double min_periods = 2.0;           // windows shorter than this many periods are rejected; > 0.
  // A one-sample half-cycle shorter than this fraction of T/2 between two pieces of the same sign
  // is a glitch that split a half-cycle: the three are merged when the pieces are not half-cycles
  // but their union is (step 3b). [0, 0.5); 0 disables. Default 0.25: a real half-cycle is never
  // a quarter of its neighbours' length, nor a single sample.
  double blip_fraction = 0.25;
  // A window with a gap between two samples longer than this many periods is rejected (found or
  // given): the phase across it is not observed, and the two sides may be different swings.
  // Default 1: dropped packets last tens of ms, a rig's period 1-3 s. > 0.
  double max_gap_periods = 1.0;

  bool Check(std::string* why) const;
};

enum class WindowStatus { kOk, kRejected, kError };  // rejected: the data; error: the request
enum class WindowEnd { kLogEnd, kNoiseFloor, kStopped, kOverride };
const char* ToString(WindowStatus status);  // "ok", "rejected", "error"
const char* ToString(WindowEnd end);        // "log_end", "noise_floor", "stopped", "override"

struct FreeOscillationWindow {
  WindowStatus status = WindowStatus::kRejected;
  std::string message;  // why rejected / error, naming the log; empty when ok
  // Rejected because no oscillation was found at all (the message says "no oscillation found"):
  // callers act on this (pipeline/trace/trace_process.cc's time-unit hint), never on the text.
  bool no_oscillation_found = false;
  double t0_s = 0.0, t1_s = 0.0;           // the window (s, the log's own time)
  size_t first_index = 0, last_index = 0;  // samples with t0 <= t <= t1 (inclusive)
  WindowEnd end_reason = WindowEnd::kLogEnd;
  bool overridden = false;             // [t0, t1] given by the user
  double release_s = 0.0;              // detected release (start of the first free half-cycle)
  double period_s = 0.0;               // mean period over the free oscillation (0: unknown)
  double noise_sigma_rad_per_s = 0.0;  // rate noise std
  bool noise_from_rest = false;      // true: from the rest segment; false: high-frequency residual
  double rest_bias_rad_per_s = 0.0;  // mean rate at rest (without rest: over whole periods)
  double rest_end_s = 0.0;           // end of the initial rest (valid when noise_from_rest)
  int rest_samples = 0;
  double peak_rate_start_rad_per_s = 0.0;  // |rate - bias| of the first/last peak in the window
  double peak_rate_end_rad_per_s = 0.0;

  bool IsUsable() const { return status == WindowStatus::kOk; }
  double duration_s() const { return t1_s - t0_s; }
  // "window [12.31, 58.02] s (log_end), period 1.84 s, noise 0.0044 rad/s (rest)" or the message.
  std::string BriefReport() const;
};

// Residual of x[k] against the cubic through its neighbours x[idx[0..3]], evaluated at the real
// timestamps t (so jitter and single drops do not count), divided by sqrt(1 + sum of squared
// Lagrange weights) so that its std equals the sample noise. Shared by the window's noise
// estimate and the glitch detector (fit/glitch.h).
double NeighbourCubicResidual(const std::vector<double>& t, const std::vector<double>& x, size_t k,
                              const size_t idx[4]);

// Finds the window on a swing-rate series (t strictly increasing, same size, finite). `name`
// (the log's file name) prefixes messages. Never throws; bad series -> kError.
FreeOscillationWindow FindFreeOscillationWindow(const std::vector<double>& t_s,
                                                const std::vector<double>& rate_rad_per_s,
                                                const WindowOptions& options,
                                                const std::string& name = "");

// A user-given window (CLI --window T0:T1, config override): validated against the log (finite,
// t1 > t0, inside [t_first, t_last] up to half a sample) -> kError naming the log otherwise; the
// noise, bias and period are estimated as above; fewer than min_periods periods -> kRejected.
FreeOscillationWindow ApplyWindowOverride(const std::vector<double>& t_s,
                                          const std::vector<double>& rate_rad_per_s, double t0_s,
                                          double t1_s, const WindowOptions& options,
                                          const std::string& name = "");

// Parses "T0:T1" (seconds, the log's own time, e.g. "12.5:48"), as given to --window. False with
// *why ("--window '12:': expected T0:T1 in seconds, ...") on anything else, including T1 <= T0.
bool ParseWindowSpec(const std::string& text, double* t0_s, double* t1_s, std::string* why);

// ---- Amplitude (issue 3 item 4) ----

// One extreme of the swing angle inside the window: at a zero crossing of the rate.
struct AngleExtreme {
  double t_s = 0.0;            // time of the extreme (interpolated zero crossing of the rate)
  double amplitude_deg = 0.0;  // |psi| there, relative to the neighbouring extremes
};

// The angle extremes in [t0, t1]: psi is the cumulative trapezoid integral of (rate - bias);
// the amplitude at an extreme is half its distance from the mean of its neighbouring extremes
// (or from its one neighbour at the ends), so a slow drift from a bias error cancels. Needs at
// least two extremes; returns fewer otherwise.
std::vector<AngleExtreme> AngleExtremes(const std::vector<double>& t_s,
                                        const std::vector<double>& rate_rad_per_s,
                                        const FreeOscillationWindow& window);

struct AmplitudeBandOptions {
  // Band of swing amplitude (deg) kept for the fit. Defaults keep everything; the fit's caller
  // sets the band it has evidence for (issue 3 item 4).
  double min_amplitude_deg = 0.0;   // >= 0
  double max_amplitude_deg = 90.0;  // > min
  double min_periods = 2.0;         // the trimmed window must still hold this many periods; > 0

  bool Check(std::string* why) const;
};

struct AmplitudeBand {
  WindowStatus status = WindowStatus::kRejected;
  std::string message;
  double t0_s = 0.0, t1_s = 0.0;  // the trimmed window
  size_t first_index = 0, last_index = 0;
  double amplitude_start_deg = 0.0;  // amplitude at the first / last extreme inside it
  double amplitude_end_deg = 0.0;
  bool trimmed_start = false, trimmed_end = false;
  std::vector<AngleExtreme> extremes;  // all extremes of the untrimmed window

  bool IsUsable() const { return status == WindowStatus::kOk; }
};

// Trims a usable window to the part whose amplitude is inside the band: since the amplitude
// decays, a later start (at the first extreme <= max) and an earlier end (at the last extreme
// >= min). Rejected when no extreme is inside the band or fewer than min_periods remain.
AmplitudeBand TrimToAmplitudeBand(const std::vector<double>& t_s,
                                  const std::vector<double>& rate_rad_per_s,
                                  const FreeOscillationWindow& window,
                                  const AmplitudeBandOptions& options,
                                  const std::string& name = "");

}  // namespace bifilar
