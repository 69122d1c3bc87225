// Block means of a densely sampled fit window (issue 9 item 12: a 2.8 M-sample log took 69 s and
// 1.4 GB in `bifilar fit`). A swing of period T needs a few hundred points per period to be
// fitted; an IMU at 16 kHz gives tens of thousands. Above BlockMeanOptions::max_points samples,
// consecutive samples are averaged over short time spans (at most T / min_blocks_per_period) and
// the fit sees the means at their mean times. Conventions: docs/method.md §6 ("Dense logs").
//
// Why the numbers hold: for white noise the mean of k samples carries the same information about
// a signal that is constant over the block as the k samples (std / sqrt(k)). The signal is not
// constant: mean(psi') over a block differs from psi'(mean t) by psi''' var(t) / 2, a relative
// (omega h)^2 / 24 for a block of span h, an amplitude scale of 1.6e-6 at h = T / 1000, which
// moves I by about A^2 / 4 of it (the gyro-scale sensitivity, README "Accuracy"): 1e-7 relative
// at 30 deg. Blocks never span a gap in the timestamps (a block is a time span, not a count), so
// drops and jitter do not move the mean time off the samples.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace bifilar {

struct BlockMeanOptions {
  // The fit sees at most about this many points (more samples are averaged); >= 1000.
  // Default 65536: a fit then costs ~0.1-1 s whatever the sample rate.
  size_t max_points = 65536;
  // A block spans at most period / this (so the bias above stays ~1e-7); >= 100. Default 1000.
  double min_blocks_per_period = 1000.0;

  bool Check(std::string* why) const;
};

// Time span (s) of one block for the n samples of a window of duration_s and swing period
// period_s: about k sample steps with k = min(ceil(n / max_points), samples per period /
// min_blocks_per_period), minus half a step (so a regular series gives exactly k per block).
// 0 when k < 2 (no averaging: every log at the usual 25-1000 Hz and up to ~65 k samples), or when
// the inputs are not finite and positive.
double BlockMeanSpan(size_t n, double duration_s, double period_s, const BlockMeanOptions& options);

// Means of samples first..last (inclusive) of (t_s, value), grouped into blocks: a block starts
// at a sample and holds it and every following sample with t < start + span_s. The block time is
// the mean of its sample times. t_s strictly increasing; first <= last < t_s.size(). With
// span_s <= 0 the samples are copied unchanged.
void BlockMeans(const std::vector<double>& t_s, const std::vector<double>& value, size_t first,
                size_t last, double span_s, std::vector<double>* t_out,
                std::vector<double>* value_out);

// The fit's series of one log: samples first..last of (t_s, rate), as block means when the
// window is dense (BlockMeanSpan > 0). noise_rad_per_s: the per-sample rate noise measured at rest
// (0: none), rest over [t_s.front(), rest_end_s]; for block means it becomes the std of the rest's
// block means (so coloured noise is counted right), or noise / sqrt(samples per block) when the
// rest holds fewer than 20 blocks.
struct FitSeries {
  std::vector<double> t_s;
  std::vector<double> rate_rad_per_s;
  double noise_rad_per_s = 0.0;
  double samples_per_point = 1.0;  // mean samples per block (1: the samples themselves)
  bool block_means() const { return samples_per_point > 1.0; }
};
FitSeries MakeFitSeries(const std::vector<double>& t_s, const std::vector<double>& rate_rad_per_s,
                        size_t first, size_t last, double period_s, double noise_rad_per_s,
                        double rest_end_s, const BlockMeanOptions& options = BlockMeanOptions());

}  // namespace bifilar
