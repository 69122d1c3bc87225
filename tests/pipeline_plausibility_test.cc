// Units and plausibility (issue 16 items 3 and 4): config values no lab rig can have are errors
// naming the key and the likely unit; real rigs pass; a gyro in rad/s declared deg/s warns naming
// imu.gyro.unit; time in s declared ms (and the reverse) says "no oscillation found" with a hint
// to imu.time.unit; an accelerometer that reads neither gravity nor zero gives a warning and a
// gyro-only fit, and an error row only with runs.pitch_source: measured.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "base/user_error.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/config/plausibility.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/logs/imu_log_writer.h"
#include "pipeline/trace/trace_process.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::Contains;
using test_support::LoadFitConfig;
using test_support::QuadrotorFitConfig;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

const std::string kSource = BIFILAR_SOURCE_DIR;

// The message of loading `yaml` as a `bifilar fit` config ("" when it loads).
std::string FitConfigError(const TempDir& dir, const std::string& yaml) {
  WriteFile(dir.path + "/fit.yaml", yaml);
  try {
    LoadFitConfig(dir.path + "/fit.yaml");
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

std::string Rig(const std::string& length, const std::string& separation, const std::string& mass) {
  return "rig: {filar_length_m: " + length + ", filar_separation_m: " + separation +
         ", mass_kg: " + mass + "}\n";
}

bool AnyWarningContains(const TraceRecord& r, const std::string& part) {
  for (const std::string& w : r.warnings) {
    if (Contains(w, part)) return true;
  }
  return false;
}

// ---- Config values no lab rig can have ----------------------------------------------------------

TEST(PlausibleConfig, LengthsAndMassInMillimetresAndGramsNameKeyLineAndUnit) {
  TempDir dir;
  // The case: the quadrotor rig written in mm and g.
  std::string why = FitConfigError(dir, Rig("594", "30", "34.3"));
  EXPECT_TRUE(Contains(why, "fit.yaml:1:")) << why;  // the line of the key
  EXPECT_TRUE(
      Contains(why, "rig.filar_length_m = 594; must be in [0.05, 20] (m), a lab rig's range"))
      << why;
  EXPECT_TRUE(Contains(why, "if this is in mm, write 0.594")) << why;
  // The separation alone in mm.
  why = FitConfigError(dir, Rig("0.594", "30", "0.0343"));
  EXPECT_TRUE(Contains(why, "rig.filar_separation_m = 30; must be in [0.005, 5] (m)")) << why;
  EXPECT_TRUE(Contains(why, "if this is in mm, write 0.03")) << why;
  // The separation in cm is within D's range but not below L: named, with the cm reading.
  why = FitConfigError(dir, Rig("0.594", "3", "0.0343"));
  EXPECT_TRUE(Contains(why,
                       "'rig.filar_separation_m': filar_separation_m (D) = 3; must be < "
                       "filar_length_m (L) = 0.594"))
      << why;
  EXPECT_TRUE(Contains(why, "if this is in cm, write 0.03")) << why;
  // The fixed-wing's length in cm.
  why = FitConfigError(dir, Rig("74", "0.16", "3.34"));
  EXPECT_TRUE(Contains(why, "rig.filar_length_m = 74; must be in [0.05, 20] (m)")) << why;
  EXPECT_TRUE(Contains(why, "if in cm, 0.74")) << why;
  // Masses in g: the rig's, and the aircraft's of a campaign.
  why = FitConfigError(dir, Rig("0.74", "0.16", "3340"));
  EXPECT_TRUE(Contains(why, "rig.mass_kg = 3340; must be in [0, 1000] (kg)")) << why;
  EXPECT_TRUE(Contains(why, "if this is in g, write 3.34")) << why;
  why = FitConfigError(dir, Rig("2", "1.8", "1.25") + "aircraft: {mass_kg: 5500}\n");
  EXPECT_TRUE(Contains(why, "aircraft.mass_kg = 5500; must be in [0, 1000] (kg)")) << why;
  EXPECT_TRUE(Contains(why, "if this is in g, write 5.5")) << why;
  // Too short for any rig, with no unit that fixes it: the range and "SI" are named.
  why = FitConfigError(dir, Rig("0.01", "0.006", "0.0343"));
  EXPECT_TRUE(Contains(why,
                       "rig.filar_length_m = 0.01; must be in [0.05, 20] (m), a lab rig's range; "
                       "values are SI (m)"))
      << why;
}

TEST(PlausibleConfig, RigInertiaInKgCm2IsAnError) {
  TempDir dir;
  const std::string rest = "aircraft: {mass_kg: 5.5}\n";
  // The sample campaign's rig (1.25 kg, D 1.8 m, 0.25 kg m^2) written in kg cm^2.
  const std::string rig =
      "rig:\n  filar_length_m: 2.0\n  filar_separation_m: 1.8\n  mass_kg: 1.25\n";
  std::string why = FitConfigError(dir, rig + "  inertia: {inertia_kg_m2: 2500}\n" + rest);
  EXPECT_TRUE(Contains(why, "fit.yaml:5:")) << why;
  EXPECT_TRUE(Contains(why, "rig.inertia.inertia_kg_m2 = 2500; must be <= 101.2 (kg m^2)")) << why;
  EXPECT_TRUE(Contains(why, "if this is in kg cm^2, write 0.25")) << why;
  why = FitConfigError(dir, rig + "  inertia:\n    table: {0: 0.25, 90: 2600}\n" + rest);
  EXPECT_TRUE(Contains(why, "rig.inertia.table (pitch 90 deg) = 2600; must be <= 101.2 (kg m^2)"))
      << why;
  EXPECT_EQ(FitConfigError(dir, rig + "  inertia: {inertia_kg_m2: 0.25}\n" + rest), "");
  // The quadrotor preset's thread "rig" (0.1 g, 1e-10 kg m^2) is fine.
  EXPECT_EQ(FitConfigError(dir, Rig("0.594", "0.030", "0.0001") + "aircraft: {mass_kg: 0.0342}\n"),
            "");
}

// Real rigs and the simulator presets' rigs load without error; so does the sample campaign.
TEST(PlausibleConfig, RealRigsPass) {
  TempDir dir;
  const char* rigs[][3] = {
      {"0.594", "0.030", "0.0343"},  // quadrotor (Crazyflie logs, simulate_quadrotor.yaml)
      {"0.594", "0.030", "0.0381"},  // quadrotor with legs
      {"0.74", "0.16", "3.34"},      // fixed-wing (simulate_nonideal_rig.yaml)
      {"2.0", "1.8", "6.75"},        // PRANDTL-D (simulate_prandtl_d.yaml), rig + aircraft
      {"3", "1.5", "25"},            // a 25 kg UAV on a large rig
  };
  for (const auto& r : rigs) {
    EXPECT_EQ(FitConfigError(dir, Rig(r[0], r[1], r[2])), "") << r[0] << " " << r[1] << " " << r[2];
  }
  EXPECT_NO_THROW(LoadCampaignConfig(kSource + "/configs/prandtl_d.yaml"));
  // The programmatic check agrees with the loader.
  CampaignConfig config = LoadFitConfig(dir.path + "/fit.yaml");
  std::string why;
  EXPECT_TRUE(config.Check(&why)) << why;
  config.aircraft_mass_kg = 3240;
  EXPECT_FALSE(config.Check(&why));
  EXPECT_TRUE(Contains(why, "aircraft.mass_kg = 3240; must be in [0, 1000] (kg)")) << why;
  EXPECT_TRUE(Contains(why, "if this is in g, write 3.24")) << why;
}

// ---- Fits that do not fit the stated rig
// ---------------------------------------------------------

// r/(D/2) = T / (2 pi sqrt(L/g)): only L, g and the time base enter, D and m cancel.
TEST(PlausibleFit, RadiusOfGyrationAgainstHalfSeparation) {
  // The quadrotor's Izz (31.96e-6 kg m^2 at 34.3 g): r = 30.5 mm = 2.0 D/2. No warning.
  EXPECT_TRUE(
      FitPlausibilityWarnings(31.96e-6, 0.0343, 0.030, 0.594, 20.0, RateUnit::kRadPerS).empty());
  // The large UAV: I_z 5 kg m^2 at 25 kg on D 1.5 m: r = 0.45 m = 0.6 D/2. No warning.
  EXPECT_TRUE(FitPlausibilityWarnings(5.0, 25.0, 1.5, 3.0, 30.0, RateUnit::kRadPerS).empty());
  // The same period with L written 10x too small would have given I 10x larger: r = 6.44 D/2.
  const std::vector<std::string> w =
      FitPlausibilityWarnings(10 * 31.96e-6, 0.0343, 0.030, 0.0594, 20.0, RateUnit::kRadPerS);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Contains(w[0], "6.44 times")) << w[0];
  EXPECT_TRUE(Contains(w[0], "rig.filar_length_m")) << w[0];
  EXPECT_TRUE(Contains(w[0], "imu.time.unit")) << w[0];
  // And on the other side: I 200x too small, r = 0.14 D/2.
  EXPECT_EQ(FitPlausibilityWarnings(31.96e-6 / 200, 0.0343, 0.030, 0.594, 20.0, RateUnit::kRadPerS)
                .size(),
            1u);
}

// The quadrotor preset (rad/s), declared deg/s: the fit reads a 57x smaller swing, 0.2-0.45 deg,
// and warns naming imu.gyro.unit; declared right, no plausibility warning. Two logs (one per
// axis) keep it fast.
TEST(PlausibleFit, GyroInRadPerSDeclaredDegPerSWarns) {
  TempDir dir;
  RunSimulateCampaign(ParseSimulateSpec(ReadFile(kSource + "/configs/simulate_quadrotor.yaml"),
                                        "simulate_quadrotor.yaml"),
                      dir.path + "/logs");
  std::string wrong = QuadrotorFitConfig();
  wrong.replace(wrong.find("unit: rad/s"), 11, "unit: deg/s");
  WriteFile(dir.path + "/right.yaml", QuadrotorFitConfig());
  WriteFile(dir.path + "/wrong.yaml", wrong);
  const CampaignConfig right_config = LoadFitConfig(dir.path + "/right.yaml");
  const CampaignConfig wrong_config = LoadFitConfig(dir.path + "/wrong.yaml");
  for (const char* log : {"pitch_0/trial_1.csv", "pitch_90/trial_1.csv"}) {
    const std::string path = dir.path + "/logs/" + log;
    const TraceRecord good = ProcessTrace(right_config, path, {});
    ASSERT_EQ(good.status, TraceStatus::kOk) << good.message;
    EXPECT_FALSE(AnyWarningContains(good, "imu.gyro.unit")) << log;
    EXPECT_FALSE(AnyWarningContains(good, "radius of gyration")) << log;
    const TraceRecord bad = ProcessTrace(wrong_config, path, {});
    ASSERT_TRUE(std::isfinite(bad.inertia_total_kg_m2)) << bad.message;
    EXPECT_LT(bad.amplitude_deg[0], 1.0) << log;
    EXPECT_TRUE(AnyWarningContains(bad, "set imu.gyro.unit: rad/s")) << log << ": " << bad.message;
    // The period, and so r/(D/2), does not depend on the gyro unit: no radius warning.
    EXPECT_FALSE(AnyWarningContains(bad, "radius of gyration")) << log;
  }
}

// Time in s declared ms: every period 1000x too short, "no oscillation found", and the hint.
// The fixed-wing preset logs ms: declared s, the hint says ms; its deg/s declared rad/s, the
// rejection names imu.gyro.unit.
TEST(PlausibleFit, TimeAndGyroUnitHintsOnRejectedLogs) {
  TempDir dir;
  RunSimulateCampaign(ParseSimulateSpec(ReadFile(kSource + "/configs/simulate_quadrotor.yaml"),
                                        "simulate_quadrotor.yaml"),
                      dir.path + "/quad");
  std::string ms = QuadrotorFitConfig();
  ms.replace(ms.find("unit: s}"), 8, "unit: ms}");
  WriteFile(dir.path + "/ms.yaml", ms);
  const TraceRecord r = ProcessTrace(LoadFitConfig(dir.path + "/ms.yaml"),
                                     dir.path + "/quad/pitch_0/trial_1.csv", {});
  EXPECT_EQ(r.status, TraceStatus::kRejected) << r.message;
  EXPECT_TRUE(Contains(r.message, "no oscillation found")) << r.message;
  EXPECT_TRUE(Contains(r.message, "imu.time.unit: s instead of ms")) << r.message;

  RunSimulateCampaign(ParseSimulateSpec(ReadFile(kSource + "/configs/simulate_nonideal_rig.yaml"),
                                        "simulate_nonideal_rig.yaml"),
                      dir.path + "/wing");
  const std::string wing = Rig("0.74", "0.16", "3.34") +
                           "imu:\n  time: {column: t, unit: %s}\n"
                           "  gyro: {columns: [gx, gy, gz], unit: deg/s}\n  accel: null\n";
  std::string as_s = wing;
  as_s.replace(as_s.find("%s"), 2, "s");
  WriteFile(dir.path + "/s.yaml", as_s);
  const TraceRecord w =
      ProcessTrace(LoadFitConfig(dir.path + "/s.yaml"), dir.path + "/wing/pitch_0/trial_1.csv", {});
  EXPECT_NE(w.status, TraceStatus::kOk) << w.message;
  EXPECT_TRUE(Contains(w.message, "imu.time.unit: ms instead of s")) << w.message;
  // Its gyro (deg/s) declared rad/s: a swing of ~2000 deg, which no bifilar makes (the wires
  // cross at 180 deg): rejected with the hint.
  std::string rad = wing;
  rad.replace(rad.find("%s"), 2, "ms");
  rad.replace(rad.find("unit: deg/s"), 11, "unit: rad/s");
  WriteFile(dir.path + "/rad.yaml", rad);
  const TraceRecord g = ProcessTrace(LoadFitConfig(dir.path + "/rad.yaml"),
                                     dir.path + "/wing/pitch_0/trial_1.csv", {});
  EXPECT_NE(g.status, TraceStatus::kOk) << g.message;
  EXPECT_TRUE(Contains(g.message, "set imu.gyro.unit: deg/s")) << g.message;
  // Declared right: ok, and no plausibility warning on the fixed-wing either.
  std::string as_ms = wing;
  as_ms.replace(as_ms.find("%s"), 2, "ms");
  WriteFile(dir.path + "/ms_wing.yaml", as_ms);
  const TraceRecord ok = ProcessTrace(LoadFitConfig(dir.path + "/ms_wing.yaml"),
                                      dir.path + "/wing/pitch_0/trial_1.csv", {});
  ASSERT_EQ(ok.status, TraceStatus::kOk) << ok.message;
  EXPECT_FALSE(AnyWarningContains(ok, "imu.gyro.unit"));
  EXPECT_FALSE(AnyWarningContains(ok, "radius of gyration"));
  EXPECT_FALSE(AnyWarningContains(ok, "imu.time.unit"));
}

// ---- An accelerometer that reads neither gravity nor zero
// ----------------------------------------

// A small campaign from the sample spec (4 angles, 1 trial, no tare) whose accelerometer reads
// 0.27 of its true specific force: 0.27 g along the down vertical, like the fixed-wing rig.
struct OddAccelCampaign {
  TempDir dir;
  OddAccelCampaign() {
    std::string spec = ReadFile(kSource + "/configs/simulate_prandtl_d.yaml");
    auto replace = [&](const std::string& from, const std::string& to) {
      const size_t at = spec.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      spec.replace(at, from.size(), to);
    };
    replace(
        "pitch_deg: [-80, -70, -60, -50, -40, -30, -20, -10, 0, 10, 20, 30, 40, 50, 60, 70, 80, "
        "90]",
        "pitch_deg: [-40, 0, 45, 90]");
    replace("trials_per_pitch: 3", "trials_per_pitch: 1");
    replace("tare_logs: 3", "tare_logs: 0");
    replace("free_s: [35, 45]", "free_s: [20, 25]");
    replace("gzip: true", "gzip: false");
    RunSimulateCampaign(ParseSimulateSpec(spec, "odd_accel.yaml"), dir.path + "/logs");
    ImuFormat format;  // the sample spec's columns and units are the defaults
    for (const char* pitch : {"-40", "0", "45", "90"}) {
      const std::string path = dir.path + "/logs/pitch_" + pitch + "/trial_1.csv";
      ImuData data = ReadImuLog(path, format);
      for (auto& f : data.accel_in_imu) f *= 0.27;
      WriteImuLog(path, data, format);
    }
  }
  CampaignResult Run(const std::string& pitch_source, const std::string& accel) {
    WriteFile(dir.path + "/campaign.yaml",
              "rig:\n  filar_length_m: 2.0\n  filar_separation_m: 1.8\n  mass_kg: 1.25\n"
              "  inertia: {inertia_kg_m2: 0.25}\n"
              "aircraft: {mass_kg: 5.5}\n"
              "imu: {accel: " +
                  accel +
                  "}\n"
                  "runs: {root: logs, pattern: \"pitch_{pitch_deg}/*.csv\", pitch_source: " +
                  pitch_source +
                  "}\n"
                  "ellipse: {bootstrap: 0}\n");
    CampaignOptions options;
    options.out_dir = dir.path + "/out_" + pitch_source + (accel == "null" ? "_null" : "");
    options.jobs = 2;
    options.force = true;
    return RunCampaign(LoadCampaignConfig(dir.path + "/campaign.yaml"), options);
  }
};

TEST(OddAccelerometer, WarningAndGyroOnlyFitUnlessThePitchIsMeasured) {
  OddAccelCampaign c;
  // Nominal pitch: every trace ok, warned, without measured pitch, and the same I as gyro-only.
  const CampaignResult with = c.Run("nominal", "{columns: [ax, ay, az], unit: m/s^2}");
  const CampaignResult without = c.Run("nominal", "null");
  ASSERT_EQ(with.traces.size(), 4u);
  ASSERT_EQ(without.traces.size(), 4u);
  EXPECT_EQ(with.summary.n_ok, 4);
  EXPECT_TRUE(with.summary.ellipse_fitted);
  for (size_t k = 0; k < with.traces.size(); ++k) {
    const TraceRecord& r = with.traces[k];
    ASSERT_EQ(r.status, TraceStatus::kOk) << r.file << ": " << r.message;
    EXPECT_FALSE(r.pitch_measured_deg.has_value()) << r.file;
    // 0.27 of the specific force at rest (the accelerometer bias moves the third digit: 0.269).
    EXPECT_TRUE(AnyWarningContains(r, "the accelerometer reads 0.2"))
        << r.file << ": " << r.message;
    EXPECT_TRUE(AnyWarningContains(r, "neither gravity")) << r.file;
    EXPECT_TRUE(AnyWarningContains(r, "imu.accel: null")) << r.file;
    EXPECT_EQ(r.file, without.traces[k].file);
    EXPECT_EQ(r.inertia_total_kg_m2, without.traces[k].inertia_total_kg_m2) << r.file;
  }
  // Measured pitch needs the accelerometer: every trace an error row quoting the reading.
  const CampaignResult measured = c.Run("measured", "{columns: [ax, ay, az], unit: m/s^2}");
  EXPECT_EQ(measured.summary.n_ok, 0);
  EXPECT_FALSE(measured.summary.ellipse_fitted);
  for (const TraceRecord& r : measured.traces) {
    EXPECT_EQ(r.status, TraceStatus::kError) << r.file;
    EXPECT_TRUE(Contains(r.message, "runs.pitch_source: measured needs the accelerometer's pitch"))
        << r.message;
    EXPECT_TRUE(Contains(r.message, "the accelerometer reads 0.2")) << r.message;
  }
}

}  // namespace
}  // namespace bifilar
