// Issue 16, item 5: the amplitude dependence of a large release. The simulator's preset
// configs/simulate_large_release.yaml: a 3.34 kg fixed-wing (D 0.16 m, L 0.74 m) released at
// 60-85 deg in yaw and in roll, two releases each, on a rig whose I rises about 1 % per 10 deg of
// amplitude, linearly in A (softening exponent 1), so that a line in A^2 misfits the sweep. The
// truth is the small-amplitude I (truth.json: inertia_total_kg_m2), what a fit should converge to.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/config/config.h"
#include "pipeline/trace/trace_process.h"
#include "tests/test_support.h"

namespace bifilar {
namespace {

const std::string kSource = BIFILAR_SOURCE_DIR;

TEST(LargeRelease, TwoReleasesAgreeAndCoverTheSmallAmplitudeTruth) {
  const test_support::TempDir dir("bifilar_large_release");
  const std::string command = std::string(BIFILAR_BINARY) + " simulate " + kSource +
                              "/configs/simulate_large_release.yaml --out " + dir.path +
                              "/logs > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const CampaignConfig config = test_support::LoadFitConfig(test_support::WriteFile(
      dir.path + "/fit.yaml",
      "rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\n"
      "imu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: deg/s}\n"
      "  accel: null\n"));
  const nlohmann::json truth =
      nlohmann::json::parse(test_support::ReadFile(dir.path + "/logs/truth.json"));
  std::map<std::string, nlohmann::json> truth_by_file;
  for (const nlohmann::json& t : truth.at("traces")) truth_by_file[t.at("file")] = t;

  for (const char* pitch : {"pitch_0", "pitch_90"}) {
    TraceRecord r[2];
    double truth_i = 0.0;
    for (int k = 0; k < 2; ++k) {
      const std::string file = std::string(pitch) + "/trial_" + std::to_string(k + 1) + ".csv";
      ASSERT_TRUE(truth_by_file.count(file)) << file;
      const nlohmann::json& t = truth_by_file[file];
      truth_i = t.at("inertia_total_kg_m2");
      // The preset releases at 60-85 deg, where the ideal model's fit is ~7-9 % high.
      EXPECT_GE(std::abs(t.at("amplitude_deg").get<double>()), 60.0) << file;
      EXPECT_LE(std::abs(t.at("amplitude_deg").get<double>()), 85.0) << file;
      r[k] = ProcessTrace(config, dir.path + "/logs/" + file, {});
      const TraceRecord& x = r[k];
      ASSERT_EQ(x.status, TraceStatus::kOk) << file << ": " << x.message;
      EXPECT_TRUE(x.sweep.trend_detected) << file << " z " << x.sweep.trend_z;
      EXPECT_EQ(x.inertia_source, "low_amplitude_band") << file;
      // The data choose the curve linear in A (the preset's softening exponent 1).
      EXPECT_EQ(x.sweep.trend_exponent, 1.0) << file;
      // The std is scaled by the bands' scatter about the trend, not about a constant: against
      // a constant the trend itself (4-5 % over bands of 0.02-0.2 % std) would scale it ~20x.
      EXPECT_EQ(x.sweep.std_scale, x.sweep.trend_scale) << file;
      const double constant_scale = std::sqrt(x.sweep.chi2_constant / x.sweep.chi2_dof);
      EXPECT_GT(constant_scale, 5.0 * x.sweep.std_scale) << file;
      // The whole-window fit is biased high by the rig; the result is not.
      EXPECT_GT(x.inertia_window_kg_m2, truth_i * 1.01) << file;
      const double rel = x.inertia_total_std_kg_m2 / x.inertia_total_kg_m2;
      const double z = (x.inertia_total_kg_m2 - truth_i) / x.inertia_total_std_kg_m2;
      std::printf(
          "  %s: I = %.5f +- %.5f (%.2f %%), truth %.5f (z %+.2f); window fit %+.2f %%; "
          "trend %+.2f %% per 10 deg as A^%g, z = %.1f, band scatter x%.2f about the trend "
          "(x%.0f about a constant)\n",
          file.c_str(), x.inertia_total_kg_m2, x.inertia_total_std_kg_m2, 100.0 * rel, truth_i, z,
          100.0 * (x.inertia_window_kg_m2 / truth_i - 1.0), x.sweep.trend_percent_per_10deg,
          x.sweep.trend_exponent, x.sweep.trend_z, x.sweep.std_scale, constant_scale);
      EXPECT_LE(rel, 0.015) << file;        // sigma <= 1.5 % (issue 16)
      EXPECT_LE(std::abs(z), 2.0) << file;  // covers the small-amplitude truth
    }
    // Two releases of one set-up agree within 2 sigma of their difference.
    const double diff = r[0].inertia_total_kg_m2 - r[1].inertia_total_kg_m2;
    const double diff_std = std::hypot(r[0].inertia_total_std_kg_m2, r[1].inertia_total_std_kg_m2);
    std::printf("  %s: releases differ by %.2f %% = %.2f sigma\n", pitch, 100.0 * diff / truth_i,
                diff / diff_std);
    EXPECT_LE(std::abs(diff), 2.0 * diff_std) << pitch;
  }
}

}  // namespace
}  // namespace bifilar
