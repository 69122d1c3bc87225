// Isolated gyro glitches (fit/glitch.h) against known truth: synthetic windows from
// fit/trace_synth.h (100 Hz with jitter and drops, and ~30 Hz irregular steps of 8-160 ms with
// AR(1) noise) with glitches inserted at known samples; clean and noise-free series, a quantised
// axis and a constant one must give none.
#include "base/units.h"
#include "fit/glitch.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "fit/trace_synth.h"

namespace bifilar {
namespace {

TraceFitInput Window(bool irregular, double noise_deg_per_s, double phi, uint64_t seed) {
  SyntheticTraceOptions o;
  o.geometry = {2.0, 1.8, 6.75, kStandardGravityMps2};
  o.params = {4.1, 0.04, 0.01};
  o.amplitude_deg = 25.0;
  o.duration_s = 40.0;
  o.sample_rate_hz = irregular ? 30.0 : 100.0;
  o.irregular_steps = irregular;
  o.noise_deg_per_s = noise_deg_per_s;
  o.noise_ar1_phi = phi;
  o.seed = seed;
  TraceFitInput in;
  EXPECT_TRUE(MakeSyntheticTrace(o, &in));
  return in;
}

TEST(Glitch, CleanSeriesHaveNone) {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    for (const bool irregular : {false, true}) {
      for (const double phi : {0.0, 0.9}) {
        const TraceFitInput in = Window(irregular, 0.25, phi, seed);
        EXPECT_TRUE(FindGlitches(in.t_s, in.rate_rad_per_s, GlitchOptions()).empty())
            << "seed " << seed << " irregular " << irregular << " phi " << phi;
      }
    }
    // Noise-free, at the coarsest sampling: the 0.1 %-of-swing floor keeps the peaks.
    const TraceFitInput exact = Window(true, 0.0, 0.0, seed);
    EXPECT_TRUE(FindGlitches(exact.t_s, exact.rate_rad_per_s, GlitchOptions()).empty()) << seed;
  }
  // A quantised rest (mostly 0 with one-LSB flips) and a constant series.
  std::vector<double> t, q, c;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    t.push_back(0.01 * k);
    q.push_back(u(rng) < 0.02 ? 0.0012 : 0.0);
    c.push_back(0.7);
  }
  EXPECT_TRUE(FindGlitches(t, q, GlitchOptions()).empty());
  EXPECT_TRUE(FindGlitches(t, c, GlitchOptions()).empty());
}

TEST(Glitch, SpikesOfEverySizeAndSignAreFound) {
  for (const bool irregular : {false, true}) {
    TraceFitInput in = Window(irregular, 0.25, 0.5, 4);
    const size_t n = in.t_s.size();
    // 50 and 5 rad/s, and one 1 rad/s off the swing (which peaks at 1.1 rad/s), at the first
    // and last samples too.
    const std::vector<std::pair<size_t, double>> spikes = {
        {0, 50.0},
        {n / 7, -50.0},
        {n / 3, 5.0},
        {n / 2, -5.0},
        {2 * n / 3, in.rate_rad_per_s[2 * n / 3] + 1.0},
        {n - 1, -5.0}};
    for (const auto& [k, v] : spikes) in.rate_rad_per_s[k] = v;
    const std::vector<size_t> found = FindGlitches(in.t_s, in.rate_rad_per_s, GlitchOptions());
    ASSERT_EQ(found.size(), spikes.size()) << "irregular " << irregular;
    for (size_t i = 0; i < spikes.size(); ++i) EXPECT_EQ(found[i], spikes[i].first);
    // 0 disables the search; too many "glitches" are the signal, not glitches.
    GlitchOptions off;
    off.threshold_sigmas = 0.0;
    EXPECT_TRUE(FindGlitches(in.t_s, in.rate_rad_per_s, off).empty());
    GlitchOptions strict;
    strict.max_fraction = 1.0 / static_cast<double>(n);
    EXPECT_TRUE(FindGlitches(in.t_s, in.rate_rad_per_s, strict).empty());
  }
}

TEST(Glitch, GyroGlitchesAreDroppedFromEveryColumn) {
  const TraceFitInput in = Window(false, 0.25, 0.0, 9);
  ImuData data;
  for (size_t k = 0; k < in.t_s.size(); ++k) {
    data.t_s.push_back(in.t_s[k]);
    data.gyro_in_imu.emplace_back(0.001 * std::sin(0.1 * k), 0.0005 * std::cos(0.07 * k),
                                  in.rate_rad_per_s[k]);
    data.accel_in_imu.emplace_back(0.0, 0.0, -9.8);
  }
  data.gyro_in_imu[100].x() = 30.0;   // one on x
  data.gyro_in_imu[900].z() = -50.0;  // one on z
  const std::vector<size_t> found = FindGyroGlitches(data, GlitchOptions());
  ASSERT_EQ(found, (std::vector<size_t>{100, 900}));
  const ImuData kept = WithoutSamples(data, found);
  EXPECT_EQ(kept.size(), data.size() - 2);
  EXPECT_EQ(kept.accel_in_imu.size(), kept.size());
  EXPECT_EQ(kept.t_s[100], data.t_s[101]);
  EXPECT_EQ(kept.t_s[899], data.t_s[901]);
  const std::string text = DescribeGlitches(data, found);
  EXPECT_NE(text.find("2 glitch samples ignored"), std::string::npos) << text;
  EXPECT_NE(text.find("up to 50 rad/s"), std::string::npos) << text;
}

// Short runs (issue 15 item 9): two glitches adjacent or one sample apart widen each other's
// neighbour range, so the one-sample test keeps both; the run test drops exactly them (the clean
// sample between a pair one apart is kept), at the series' ends too. Three sets of at most 6, so
// that the glitches stay below the 1 % that the swing's excursion (99th percentile) is blind to.
TEST(Glitch, ShortRunsOfTwoOrThreeAreFound) {
  for (const bool irregular : {false, true}) {
    const TraceFitInput clean = Window(irregular, 0.25, 0.5, 6);
    const size_t n = clean.t_s.size();
    const std::vector<std::vector<std::pair<size_t, double>>> sets = {
        {{0, 50.0},
         {1, 50.0},  // adjacent, at the start
         {n / 6, 50.0},
         {n / 6 + 1, 50.0},  // adjacent, same sign
         {n / 4, -50.0},
         {n / 4 + 2, -50.0}},  // one apart
        {{n / 3, 5.0},
         {n / 3 + 1, 5.0},
         {n / 3 + 2, 5.0},  // three in a row
         {n / 2, 50.0},
         {n / 2 + 1, -50.0}},  // adjacent, both signs
        {{2 * n / 3, 2.0},
         {2 * n / 3 + 1, 2.0},  // 2 rad/s on a 1.1 rad/s swing
         {5 * n / 6, -2.0},
         {5 * n / 6 + 2, -2.0},  // ... one apart
         {n - 2, -5.0},
         {n - 1, -5.0}}};  // adjacent, at the end
    for (const auto& spikes : sets) {
      TraceFitInput in = clean;
      std::vector<size_t> expected;
      for (const auto& [k, v] : spikes) {
        in.rate_rad_per_s[k] = v;
        expected.push_back(k);
      }
      EXPECT_EQ(FindGlitches(in.t_s, in.rate_rad_per_s, GlitchOptions()), expected)
          << "irregular " << irregular << ", first glitch at " << spikes[0].first;
    }
  }
}

}  // namespace
}  // namespace bifilar
