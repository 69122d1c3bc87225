// Tensor campaigns through `process` (pipeline/campaign/campaign_tensor.h): attitudes from the runs
// table and from {roll_deg}, exact recovery through discovery and grouping with a fake trace fit,
// the minimal three-axis config, bad rolls, the measured-vs-nominal warning, the planar sample's
// committed ellipse, a simulated 12 x 2 campaign against its truth (nominal and measured
// attitudes), and the real Crazyflie logs of the data folder (BIFILAR_REAL_DATA,
// tests/test_support.h).
#include "pipeline/campaign/campaign.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "base/user_error.h"
#include "fit/tensor.h"
#include "pipeline/campaign/campaign_summary.h"
#include "pipeline/campaign/campaign_tensor.h"
#include "pipeline/commands/simulate_spec.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// Truth (kg m^2): products 2-4 % of the moments; the rig.
const std::array<double, 6> kTruth = {0.20, 0.30, 0.45, 0.008, 0.010, -0.009};
constexpr double kRig = 0.02;
const std::vector<std::array<double, 2>> kAttitudes = {{0, 0},    {0, 45},   {0, -45},   {0, -90},
                                                       {45, 0},   {-45, 0},  {90, 0},    {45, 45},
                                                       {-45, 45}, {45, -45}, {-45, -45}, {90, 45}};

double Moment(double roll, double pitch) {
  return TensorMoment(kTruth, DownInBodyFromAttitude(roll, pitch));
}

// Fake logs "I=<total>" (the fit reads it), and optionally measured attitudes "R=..,P=..".
CampaignOptions FakeOptions(const std::string& out) {
  CampaignOptions o;
  o.out_dir = out;
  o.jobs = 2;
  o.figures = true;
  o.fit_function = [](const CampaignConfig&, const std::string& path,
                      const TraceProcessOptions& options) {
    TraceRecord r;
    r.file = options.display_name;
    const std::string text = ReadFile(path);
    r.status = TraceStatus::kOk;
    double roll = NAN, pitch = NAN;
    std::sscanf(text.c_str(), "I=%lf R=%lf P=%lf", &r.inertia_total_kg_m2, &roll, &pitch);
    if (std::isfinite(pitch)) {
      r.pitch_measured_deg = pitch;
      r.roll_measured_deg = roll;
    }
    r.inertia_total_std_kg_m2 = 1e-5;
    r.model = "full";
    return r;
  };
  return o;
}

std::string Number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// Two trials per attitude, +- 1e-4 about the truth (the means are exact).
std::string WriteTableCampaign(const TempDir& dir, const std::string& extra_rows = "") {
  std::string table = "# attitudes of each log\npath,roll_deg,pitch_deg\n";
  int k = 0;
  for (const auto& a : kAttitudes) {
    for (int t = 0; t < 2; ++t) {
      const std::string name = "log_" + std::to_string(k++) + ".csv";
      WriteFile(dir.path + "/logs/" + name,
                "I=" + Number(Moment(a[0], a[1]) + kRig + (t ? 1e-4 : -1e-4)) + "\n");
      table += name + "," + Number(a[0]) + "," + Number(a[1]) + "\n";
    }
  }
  WriteFile(dir.path + "/runs.csv", table + extra_rows);
  return WriteFile(dir.path + "/campaign.yaml",
                   "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: "
                   "{inertia_kg_m2: 0.02}}\naircraft: {mass_kg: 3}\n"
                   "runs: {root: logs, table: runs.csv}\nellipse: {bootstrap: 200}\n");
}

TEST(TensorCampaign, TableWithRollsRecoversTheTensorExactly) {
  TempDir dir("bifilar_tensor");
  const std::string config = WriteTableCampaign(dir);
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(config), FakeOptions(dir.path + "/out"));
  EXPECT_EQ(result.summary.exit_code, 0);
  EXPECT_FALSE(result.summary.ellipse_fitted);
  EXPECT_NE(result.summary.ellipse_message.find("outside the x-z plane"), std::string::npos);
  ASSERT_TRUE(result.tensor_fit.has_value());
  EXPECT_TRUE(result.tensor_fit->full);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(result.tensor_fit->components[k].value, kTruth[k], 1e-9);
  // results.json: the issue's keys.
  const nlohmann::json j = nlohmann::json::parse(ReadFile(dir.path + "/out/results.json"));
  const nlohmann::json& t = j["tensor"];
  EXPECT_EQ(t["mode"], "full_3d");
  for (const char* key :
       {"Ixx_kg_m2", "Iyy_kg_m2", "Izz_kg_m2", "Ixy_kg_m2", "Ixz_kg_m2", "Iyz_kg_m2"}) {
    ASSERT_TRUE(t[key].is_number()) << key;
    ASSERT_TRUE(t[std::string(key) + "_std"].is_number()) << key;
  }
  EXPECT_NEAR(t["Ixy_kg_m2"].get<double>(), 0.008, 1e-9);
  EXPECT_EQ(t["covariance_kg2_m4"].size(), 6u);
  ASSERT_EQ(t["principal_moments_kg_m2"].size(), 3u);
  EXPECT_LT(t["principal_moments_kg_m2"][0].get<double>(),
            t["principal_moments_kg_m2"][1].get<double>());
  EXPECT_EQ(t["principal_axes"].size(), 3u);
  EXPECT_EQ(t["orientations"].size(), 12u);
  EXPECT_EQ(t["residuals"].size(), 24u);
  EXPECT_EQ(t["orientations"][0]["roll_deg"], 0.0);
  // The rig's std (0 here) and the traces' roll fields.
  EXPECT_EQ(j["traces"][12]["roll_nominal_deg"], 90.0);
  EXPECT_FALSE(result.tensor_figure.empty());
  EXPECT_TRUE(fs::exists(dir.path + "/out/figures/" + result.tensor_figure));
  // The report shows the tensor.
  const std::string html = ReadFile(dir.path + "/out/report.html");
  EXPECT_NE(html.find("Inertia tensor"), std::string::npos);
  std::ostringstream console;
  PrintCampaignSummary(LoadCampaignConfig(config), result, console);
  EXPECT_NE(console.str().find("I_xy"), std::string::npos) << console.str();
  EXPECT_NE(console.str().find("Principal moments"), std::string::npos) << console.str();
}

TEST(TensorCampaign, RollOutsideItsRangeNamesTheRow) {
  TempDir dir("bifilar_tensor");
  WriteFile(dir.path + "/logs/extra.csv", "I=0.3\n");
  const std::string config = WriteTableCampaign(dir, "extra.csv,200,0\n");
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(config), FakeOptions(dir.path + "/out"));
  EXPECT_EQ(result.summary.exit_code, 1);
  bool named = false;
  for (const TraceRecord& r : result.traces) {
    named |= r.status == TraceStatus::kError &&
             r.message.find("runs.csv:27") != std::string::npos &&
             r.message.find("roll") != std::string::npos;
  }
  EXPECT_TRUE(named);
  ASSERT_TRUE(result.tensor_fit.has_value());  // the rest is fitted
}

TEST(TensorCampaign, PatternCapturesRollAndPitchInOneComponent) {
  TempDir dir("bifilar_tensor");
  for (const auto& a : {std::array<double, 2>{0, -90}, {90, 0}, {0, 0}}) {
    for (int t = 1; t <= 2; ++t) {
      WriteFile(dir.path + "/logs/roll_" + Number(a[0]) + "_pitch_" + Number(a[1]) + "/t" +
                    std::to_string(t) + ".csv",
                "I=" + Number(Moment(a[0], a[1]) * (t == 1 ? 1.001 : 0.999)) + "\n");
    }
  }
  WriteFile(dir.path + "/logs/roll_x_pitch_0/t1.csv", "I=0.3\n");
  // The minimal config: no aircraft, no rig.inertia (everything that hangs, nothing subtracted).
  const std::string config =
      WriteFile(dir.path + "/c.yaml",
                "rig: {filar_length_m: 0.594, filar_separation_m: 0.03, mass_kg: 0.0343}\n"
                "runs: {root: logs, pattern: \"roll_{roll_deg}_pitch_{pitch_deg}/*.csv\"}\n");
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(config), FakeOptions(dir.path + "/out"));
  ASSERT_TRUE(result.tensor_fit.has_value()) << result.summary.tensor_message;
  const TensorResult& t = *result.tensor_fit;
  EXPECT_EQ(t.rank, 3);
  EXPECT_NEAR(t.components[kIxx].value, kTruth[kIxx], 1e-12);
  EXPECT_NEAR(t.components[kIyy].value, kTruth[kIyy], 1e-12);
  EXPECT_NEAR(t.components[kIzz].value, kTruth[kIzz], 1e-12);
  EXPECT_EQ(t.unobservable, (std::vector<std::string>{"Ixy", "Ixz", "Iyz"}));
  const nlohmann::json j = nlohmann::json::parse(ReadFile(dir.path + "/out/results.json"));
  EXPECT_TRUE(j["tensor"]["Ixy_kg_m2"].is_null());
  EXPECT_EQ(j["rig"]["inertia_source"], "none");
  bool named = false;
  for (const TraceRecord& r : result.traces) {
    named |= r.message.find("roll_x_pitch_0/t1.csv: cannot read the roll") != std::string::npos;
  }
  EXPECT_TRUE(named);
  std::ostringstream console;
  PrintCampaignSummary(LoadCampaignConfig(config), result, console);
  EXPECT_NE(console.str().find("I_xy  not observable"), std::string::npos) << console.str();
}

TEST(TensorCampaign, ConfigKeysAreChecked) {
  TempDir dir("bifilar_tensor");
  fs::create_directories(dir.path + "/logs");
  auto error_of = [&](const std::string& yaml) {
    try {
      LoadCampaignConfig(WriteFile(dir.path + "/c.yaml", yaml));
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string rig = "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1}\n";
  EXPECT_NE(error_of(rig + "runs: {root: logs, pattern: \"*.csv\", attitude_tolerance_deg: 0}\n")
                .find("runs.attitude_tolerance_deg = 0; must be in (0, 180]"),
            std::string::npos);
  // aircraft without rig.inertia (or the other way round) still names the missing key.
  EXPECT_NE(error_of(rig + "aircraft: {mass_kg: 3}\nruns: {root: logs, pattern: \"*.csv\"}\n")
                .find("missing required key 'rig.inertia'"),
            std::string::npos);
  EXPECT_NE(error_of(rig + "runs: {pattern: \"*.csv\"}\n").find("runs.root"), std::string::npos);
  EXPECT_NE(error_of(rig + "runs: {root: logs, pattern: \"r{roll_deg}/{roll_deg}.csv\"}\n")
                .find("{roll_deg} only once"),
            std::string::npos);
  ConfigLoadOptions load;
  load.runs_root = dir.path + "/logs";
  const CampaignConfig c = LoadCampaignConfig(
      WriteFile(dir.path + "/c.yaml", rig + "runs: {pattern: \"*.csv\"}\n"), load);
  EXPECT_EQ(c.runs.root, fs::path(dir.path + "/logs").lexically_normal().string());
  EXPECT_FALSE(c.rig_inertia_given);
}

TEST(TensorCampaign, MeasuredAttitudeFarFromTheNominalWarnsNamingTheLog) {
  TempDir dir("bifilar_tensor");
  WriteTableCampaign(dir);
  // Every log measures its nominal attitude to 0.2 deg, one is 10 deg off in roll.
  int k = 0;
  for (const auto& a : kAttitudes) {
    for (int t = 0; t < 2; ++t, ++k) {
      const std::string path = dir.path + "/logs/log_" + std::to_string(k) + ".csv";
      const double roll = a[0] + (k == 9 ? 10.0 : 0.2), pitch = a[1] == -90 ? -89.8 : a[1] + 0.2;
      WriteFile(path,
                "I=" + Number(TensorMoment(kTruth, DownInBodyFromAttitude(roll, pitch)) + kRig) +
                    " R=" + Number(roll) + " P=" + Number(pitch) + "\n");
    }
  }
  const std::string config = WriteFile(
      dir.path + "/campaign.yaml",
      "rig: {filar_length_m: 2, filar_separation_m: 1, mass_kg: 1, inertia: {inertia_kg_m2: "
      "0.02}}\naircraft: {mass_kg: 3}\nimu: {accel: {columns: [ax, ay, az]}}\n"
      "runs: {root: logs, table: runs.csv, pitch_source: measured}\nellipse: {bootstrap: 0}\n");
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(config), FakeOptions(dir.path + "/out"));
  int warned = 0;
  for (const TraceRecord& r : result.traces) {
    for (const std::string& w : r.warnings) {
      if (w.find("attitude_tolerance_deg") != std::string::npos) {
        ++warned;
        EXPECT_NE(w.find("log_9.csv"), std::string::npos) << w;
      }
    }
  }
  EXPECT_EQ(warned, 1);
  // The measured axes are used: the moments were made at them, so the fit is exact.
  ASSERT_TRUE(result.tensor_fit.has_value());
  for (int c = 0; c < 6; ++c) EXPECT_NEAR(result.tensor_fit->components[c].value, kTruth[c], 1e-9);
}

// The committed sample's results.json (written on another machine) against a fresh run: the
// ellipse and its stds to 1e-9 relative. Another machine differs in the last digits (its BLAS,
// libm code path and CPU; measured up to 7e-11 relative, issue 22), so bit for bit holds only
// within one build; a change in the code moves these by far more (a 1 % of std change is ~5e-6
// relative, SmallThings.CommittedSampleOutputsHoldTheCodesNumbers). Within this run, the tensor
// section repeats the ellipse bit for bit.
TEST(TensorCampaign, PlanarSampleGivesTheCommittedEllipse) {
  constexpr double kRelTol = 1e-9;
  const std::string source = BIFILAR_SOURCE_DIR;
  TempDir dir("bifilar_tensor");
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  options.write_report = false;
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(source + "/configs/prandtl_d.yaml"), options);
  const nlohmann::json before =
      nlohmann::json::parse(ReadFile(source + "/sample_runs/prandtl_d/out/results.json"));
  ASSERT_TRUE(result.ellipse_fit.has_value());
  for (const char* key : {"Ix_kg_m2", "Iz_kg_m2", "Ixz_kg_m2", "tau_deg", "Ix_kg_m2_std",
                          "Iz_kg_m2_std", "Ixz_kg_m2_std", "tau_deg_std"}) {
    const double committed = before["ellipse"][key].get<double>();
    EXPECT_NEAR(result.ellipse[key].get<double>(), committed, kRelTol * std::fabs(committed))
        << key;
  }
  // The tensor section repeats them.
  EXPECT_EQ(result.tensor["mode"], "planar_xz");
  EXPECT_EQ(result.tensor["Ixx_kg_m2"].get<double>(), result.ellipse_fit->ix.value);
  EXPECT_EQ(result.tensor["Ixz_kg_m2"].get<double>(), result.ellipse_fit->ixz.value);
  EXPECT_TRUE(result.tensor["Iyy_kg_m2"].is_null());
}

// The simulated campaign of configs/simulate_tensor.yaml (12 attitudes x 2 trials, products 2-4 %
// of the moments, 0.5 deg hanging errors, irregular radio steps, AR(1) noise), every trace
// fitted: the issue's numbers.
void CheckAgainstTruth(const TensorResult& t, const nlohmann::json& truth) {
  const nlohmann::json& tensor = truth["aircraft"]["tensor"];
  const double largest = tensor["Izz_kg_m2"].get<double>();
  for (int k = 0; k < 6; ++k) {
    const double value = tensor[std::string(TensorComponentName(k)) + "_kg_m2"].get<double>();
    const double error = t.components[k].value - value;
    EXPECT_LT(std::fabs(error), 3 * t.components[k].std) << TensorComponentName(k);
    EXPECT_LT(std::fabs(error), 0.01 * largest) << TensorComponentName(k);
  }
  for (int k = 0; k < 3; ++k) {
    const double value = tensor["principal_moments_kg_m2"][k].get<double>();
    EXPECT_LT(std::fabs(t.principal_moments[k].value / value - 1), 0.005) << k;
  }
}

TEST(TensorCampaign, SimulatedCampaignMeetsTheIssueNumbers) {
  const std::string source = BIFILAR_SOURCE_DIR;
  TempDir dir("bifilar_tensor");
  RunSimulateCampaign(ReadSimulateSpec(source + "/configs/simulate_tensor.yaml"),
                      dir.path + "/logs");
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(dir.path + "/logs/truth.json"));
  ConfigLoadOptions load;
  load.runs_root = dir.path + "/logs";
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  options.write_report = false;
  CampaignConfig config = LoadCampaignConfig(source + "/configs/tensor_uav.yaml", load);
  const CampaignResult nominal = RunCampaign(config, options);
  EXPECT_EQ(nominal.summary.n_ok, 24);
  ASSERT_TRUE(nominal.tensor_fit.has_value()) << nominal.summary.tensor_message;
  CheckAgainstTruth(*nominal.tensor_fit, truth);
  config.runs.pitch_source = PitchSource::kMeasured;  // the accelerometer's down vector
  const CampaignResult measured = RunCampaign(config, options);
  EXPECT_EQ(measured.summary.n_fitted, 0);  // the traces are reused: only the attitudes change
  ASSERT_TRUE(measured.tensor_fit.has_value());
  CheckAgainstTruth(*measured.tensor_fit, truth);
}

TEST(TensorCampaign, CrazyflieAirframeGivesItsThreeMoments) {
  BIFILAR_REAL_DATA(data, "crazyflie");
  TempDir dir("bifilar_tensor");
  ConfigLoadOptions load;
  load.runs_root = data;
  CampaignOptions options;
  options.out_dir = dir.path + "/out";
  options.jobs = 2;
  options.figures = false;
  options.write_report = false;
  const CampaignResult result =
      RunCampaign(LoadCampaignConfig(
                      std::string(BIFILAR_SOURCE_DIR) + "/configs/crazyflie_basemodel.yaml", load),
                  options);
  EXPECT_EQ(result.summary.n_ok, 12);
  ASSERT_TRUE(result.tensor_fit.has_value()) << result.summary.tensor_message;
  const TensorResult& t = *result.tensor_fit;
  EXPECT_EQ(t.unobservable.size(), 3u);
  // The authors' own script rerun on these logs (small-angle formula, which a fit of the
  // nonlinear model comes out slightly below: 10-25 deg swings): 15.78e-6, 15.26e-6 (Iyy from
  // logs 1-3) and 31.96e-6 kg m^2 (the data folder's README.md). Within 4 %, and the repeats'
  // 0.2-0.3 % scatter shows in the std (not 20-40 x smaller).
  EXPECT_NEAR(t.components[kIxx].value, 15.78e-6, 0.04 * 15.78e-6);
  EXPECT_NEAR(t.components[kIyy].value, 15.6e-6, 0.05 * 15.6e-6);
  EXPECT_NEAR(t.components[kIzz].value, 31.96e-6, 0.04 * 31.96e-6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(t.components[k].std, 0.0004 * t.components[k].value) << k;
    EXPECT_LT(t.components[k].std, 0.02 * t.components[k].value) << k;
  }
  // I_zz exceeds I_xx + I_yy by 2.5 % (the authors' script: 31.96 > 15.78 + 15.26 too), 25 std:
  // no rigid body does that (issue 32). The level (yaw) swings are named; their rig geometry
  // likely differs from the side-hung ones'. Marked not physical, exit 1.
  ASSERT_TRUE(result.physical.has_value());
  EXPECT_EQ(result.physical->status, PhysicalStatus::kNotPhysical) << result.physical->message;
  EXPECT_EQ(result.physical->attitude, "roll 0, pitch 0 deg");
  EXPECT_EQ(result.summary.exit_code, 1);
}

}  // namespace
}  // namespace bifilar
