// Private to fit/ (window.cc, amplitude_band.cc): the half-cycles of a swing rate that the
// window search (window.cc) and the angle extremes of the amplitude band (amplitude_band.cc) both
// read, and the helpers they share.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace bifilar {
namespace window {

// "name: " for a message about the log `name`; "" without a name.
std::string Prefix(const std::string& name);

// One half-cycle of x = rate - bias between zero crossings (with hysteresis).
struct HalfCycle {
  int sign = 0;
  double start_s = 0.0;  // interpolated zero crossing where it begins
  double end_s = 0.0;    // where the next begins (or the last sample time when open)
  size_t peak_index = 0;
  double peak = 0.0;          // max sign * x
  bool open = false;          // the log ended before it did
  double max_gap_s = 0.0;     // longest time step between samples inside it (dropped packets)
  size_t samples_beyond = 0;  // samples with sign * x above the hysteresis threshold
  // max sign * x over samples capped at their larger neighbour: one glitch sample cannot raise it
  double robust_peak = 0.0;
  size_t robust_peak_index = 0;
  double duration() const { return end_s - start_s; }
};

// Half-cycles with hysteresis h on x.
std::vector<HalfCycle> HalfCycles(const std::vector<double>& t, const std::vector<double>& x,
                                  size_t begin, size_t end, double h);

// A glitch sample of the other sign (one reading, too small for fit/glitch.h, e.g. 0.4 rad/s on
// a 1 rad/s swing just after a long timestamp gap) splits a half-cycle in three: two pieces of
// the same sign around a one-sample half-cycle. Such a blip (closed, a single sample beyond the
// hysteresis, shorter than `blip_max_s`) is merged with its neighbours into one half-cycle when
// `accept(joined, before, after, outer_before, outer_after)` says the joined one is a half-cycle
// the pieces are not (the outer half-cycles around them, null at the ends, tell a swing from hand
// tremor). A real swing half-cycle holds many samples (>= 10 at 30 Hz for the shortest period in
// range), so only hand tremor and glitches make blips.
template <typename Accept>
std::vector<HalfCycle> MergeGlitchSplits(const std::vector<HalfCycle>& cycles, double blip_max_s,
                                         Accept accept) {
  std::vector<HalfCycle> out;
  out.reserve(cycles.size());
  for (size_t j = 0; j < cycles.size(); ++j) {
    const HalfCycle& blip = cycles[j];
    if (!out.empty() && j + 1 < cycles.size() && !blip.open && blip.samples_beyond == 1 &&
        blip.duration() < blip_max_s) {
      const HalfCycle& before = out.back();
      const HalfCycle& after = cycles[j + 1];
      HalfCycle joined = before;
      joined.end_s = after.end_s;
      joined.open = after.open;
      joined.max_gap_s = std::max({before.max_gap_s, blip.max_gap_s, after.max_gap_s});
      joined.samples_beyond = before.samples_beyond + after.samples_beyond;
      if (after.peak > joined.peak) {
        joined.peak = after.peak;
        joined.peak_index = after.peak_index;
      }
      if (after.robust_peak > joined.robust_peak) {
        joined.robust_peak = after.robust_peak;
        joined.robust_peak_index = after.robust_peak_index;
      }
      const HalfCycle* outer_before = out.size() >= 2 ? &out[out.size() - 2] : nullptr;
      const HalfCycle* outer_after = j + 2 < cycles.size() ? &cycles[j + 2] : nullptr;
      if (accept(joined, before, after, outer_before, outer_after)) {
        out.back() = joined;
        ++j;  // `after` is inside `joined`
        continue;
      }
    }
    out.push_back(blip);
  }
  return out;
}

// The first sample at or after t0 / the last at or before t1 (t sorted).
size_t FirstAtOrAfter(const std::vector<double>& t, double t0);
size_t LastAtOrBefore(const std::vector<double>& t, double t1);

}  // namespace window
}  // namespace bifilar
