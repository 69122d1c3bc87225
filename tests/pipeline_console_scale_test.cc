// Figures and text true at any scale, and a console that stays readable (issue 32, "Numbers to
// reach"): three-axis campaigns simulated at I = 1e-5 ... 1000 kg m^2 and processed in kg m^2 and
// in slug ft^2 give a report.html with no "± 0" and no axis whose tick labels repeat (each inline
// SVG parsed: the numeric tick labels of an axis share its x (y axis) or y (x axis)); the
// console lines of `process` and `fit --repeats` are at most 160 characters, on simulated
// campaigns and on the real logs (BIFILAR_DATA_DIR; skipped when absent).
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/text_format.h"
#include "base/units.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/figures/figure.h"
#include "test_support.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
using test_support::Bifilar;
using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;

// A three-axis campaign whose moments are 0.67 I, I and 1.5 I, with masses and a rig scaled so
// that the period stays near 2-3.5 s: one trial per axis, short logs (fast).
struct ScaledCampaign {
  std::string spec, config_si, config_imperial;
};

ScaledCampaign ScaledSpec(double inertia, const std::string& logs, int trials) {
  const double mass = std::min(800.0, std::max(0.02, 2.5 * std::pow(inertia / 0.3, 0.6)));
  const double length = inertia < 10 ? 1.5 : 6.0, period = inertia < 10 ? 2.2 : 3.5;
  const double g = kStandardGravityMps2, pi = kPi;
  const double separation =
      std::sqrt(16 * pi * pi * inertia * length / (mass * g * period * period));
  const double rig_mass = 0.2 * mass, rig_inertia = 0.05 * inertia;
  auto n = [](double v) { return Fmt("%.6g", v); };
  ScaledCampaign c;
  c.spec =
      "seed: 5\nmodel: full\n"
      "geometry: {filar_length_m: " +
      n(length) + ", filar_separation_m: " + n(separation) +
      ", gravity_mps2: " + n(kStandardGravityMps2) +
      "}\n"
      "aircraft: {mass_kg: " +
      n(mass) + ", ix_kg_m2: " + n(0.67 * inertia) + ", iy_kg_m2: " + n(inertia) +
      ", iz_kg_m2: " + n(1.5 * inertia) +
      ", ixy_kg_m2: 0, ixz_kg_m2: 0, iyz_kg_m2: 0}\n"
      "rig: {mass_kg: " +
      n(rig_mass) + ", imu_mass_kg: " + n(0.01 * mass) + ", inertia_kg_m2: " + n(rig_inertia) +
      ", tare_logs: 0, imu_offset_m: [0, 0, 0], imu_mounting_rpy_deg: [0, 0, 0]}\n"
      "campaign: {attitudes_deg: [[0, 0], [0, -90], [90, 0]], trials_per_pitch: " +
      std::to_string(trials) +
      ", pitch_error_sigma_deg: 0.3, roll_error_sigma_deg: 0.3}\n"
      "swing: {amplitude_deg: [8, 15], negative_amplitude_probability: 0.5, "
      "drag_coeff_kg_m2: [" +
      n(0.02 * inertia) + ", " + n(0.05 * inertia) + "], viscous_coeff_kg_m2_per_s: [" +
      n(0.005 * inertia) + ", " + n(0.01 * inertia) +
      "]}\n"
      "timeline: {rest_before_s: [1, 2], twist_s: [0.8, 1.0], hold_s: [1, 1.5], tremor_deg: "
      "0.05, tremor_hz: [4, 9], release_rate_sigma_deg_per_s: 0.3, free_s: [" +
      n(5.5 * period) + ", " + n(6.5 * period) +
      "], stop_probability: 0.0, stop_time_constant_s: 0.1, rest_after_s: [1, 1]}\n"
      "sensor: {sample_rate_hz: 50, sample_steps: regular, gyro_noise_sigma_deg_per_s: 0.2, "
      "gyro_bias_sigma_deg_per_s: 0.2, gyro_scale_error_sigma: 0.001, accelerometer: true, "
      "accel_noise_sigma_mps2: 0.02, accel_bias_sigma_mps2: 0.02}\n"
      "format: {time_column: t, time_unit: s, gyro_columns: [gx, gy, gz], gyro_unit: rad/s, "
      "accel_columns: [ax, ay, az], accel_unit: m/s^2, significant_digits: 7, gzip: false}\n";
  const std::string config =
      "gravity_mps2: " + n(kStandardGravityMps2) +
      "\n"
      "rig:\n  filar_length_m: " +
      n(length) + "\n  filar_separation_m: " + n(separation) +
      "\n  mass_kg: " + n(rig_mass + 0.01 * mass) +
      "\n  inertia: {inertia_kg_m2: " + n(rig_inertia) +
      ", inertia_std_kg_m2: " + n(0.001 * rig_inertia) +
      "}\n  uncertainties: {filar_length_std_m: 0.001, filar_separation_std_m: 0.0005, "
      "mass_std_kg: " +
      n(0.001 * mass) +
      "}\n"
      "aircraft: {mass_kg: " +
      n(mass) + ", mass_std_kg: " + n(0.002 * mass) +
      "}\n"
      "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [gx, gy, gz], unit: rad/s}\n"
      "  accel: {columns: [ax, ay, az], unit: m/s^2}\n"
      "runs:\n  root: " +
      logs +
      "\n  pattern: \"roll_{roll_deg}_pitch_{pitch_deg}/*.csv\"\n"
      "  pitch_source: nominal\n";
  c.config_si = "units: si\n" + config;
  c.config_imperial = "units: imperial\n" + config;
  return c;
}

// The value of attribute `name` in the tag text `tag` ("" when absent).
std::string Attribute(const std::string& tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const size_t at = tag.find(key);
  if (at == std::string::npos) return "";
  const size_t end = tag.find('"', at + key.size());
  return tag.substr(at + key.size(), end - at - key.size());
}

bool IsNumber(const std::string& text) {
  if (text.empty()) return false;
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

// Every axis of every inline figure of `html` whose numeric tick labels repeat, described.
std::vector<std::string> RepeatedTicks(const std::string& html) {
  std::vector<std::string> out;
  for (size_t at = html.find("<svg class=\""); at != std::string::npos;
       at = html.find("<svg class=\"", at + 1)) {
    const size_t end = html.find("</svg>", at);
    const std::string svg = html.substr(at, end - at);
    std::map<std::string, std::vector<std::string>> by_x, by_y;  // y axes share x, x axes y
    for (size_t t = svg.find("<text"); t != std::string::npos; t = svg.find("<text", t + 1)) {
      const size_t tag_end = svg.find('>', t);
      const std::string tag = svg.substr(t, tag_end - t);
      const std::string open = "<tspan>", close = "</tspan></text>";
      if (svg.compare(tag_end + 1, open.size(), open) != 0) continue;
      const size_t label_end = svg.find(close, tag_end);
      const std::string label =
          svg.substr(tag_end + 1 + open.size(), label_end - tag_end - 1 - open.size());
      if (!IsNumber(label) || !Attribute(tag, "transform").empty()) continue;
      by_x[Attribute(tag, "x")].push_back(label);
      by_y[Attribute(tag, "y")].push_back(label);
    }
    for (const auto* axes : {&by_x, &by_y}) {
      for (const auto& [position, labels] : *axes) {
        const std::set<std::string> distinct(labels.begin(), labels.end());
        if (distinct.size() == labels.size()) continue;
        std::string text = svg.substr(0, svg.find('>')) + ": axis at " + position + ":";
        for (const std::string& l : labels) text += " " + l;
        out.push_back(text);
      }
    }
  }
  return out;
}

// Every "± 0" (a std shown as zero) of `html`, with its context.
std::vector<std::string> PlusMinusZero(const std::string& html) {
  std::vector<std::string> out;
  for (const std::string mark : {"&plusmn; ", "± "}) {
    for (size_t at = html.find(mark); at != std::string::npos; at = html.find(mark, at + 1)) {
      const size_t v = at + mark.size();
      if (v >= html.size() || html[v] != '0') continue;
      if (v + 1 < html.size() &&
          (html[v + 1] == '.' || std::isdigit(static_cast<unsigned char>(html[v + 1]))))
        continue;
      out.push_back(html.substr(at > 80 ? at - 80 : 0, 100));
    }
  }
  return out;
}

size_t LongestLine(const std::string& text, std::string* line) {
  std::istringstream in(text);
  std::string l;
  size_t longest = 0;
  while (std::getline(in, l)) {
    if (l.size() > longest) {
      longest = l.size();
      *line = l;
    }
  }
  return longest;
}

TEST(ScaleFigures, NoPlusMinusZeroNorRepeatedTickAtAnyScaleAndUnit) {
  for (const double inertia : {1e-5, 1e-3, 0.05, 0.1, 3.0, 1000.0}) {
    TempDir dir("bifilar_scale");
    const std::string logs = dir.path + "/logs";
    const ScaledCampaign c = ScaledSpec(inertia, logs, 1);
    WriteFile(dir.path + "/spec.yaml", c.spec);
    RunSimulateCampaign(ReadSimulateSpec(dir.path + "/spec.yaml"), logs);
    for (const std::string* config : {&c.config_si, &c.config_imperial}) {
      SCOPED_TRACE("I = " + Fmt("%g", inertia) + " kg m^2, " +
                   config->substr(0, config->find('\n')));
      WriteFile(dir.path + "/config.yaml", *config);
      CampaignOptions options;
      options.out_dir = dir.path + (config == &c.config_si ? "/out_si" : "/out_imperial");
      options.jobs = 2;
      const CampaignResult result =
          RunCampaign(LoadCampaignConfig(dir.path + "/config.yaml"), options);
      ASSERT_EQ(result.summary.n_ok, 3) << result.summary.tensor_message;
      const std::string html = ReadFile(options.out_dir + "/report.html");
      EXPECT_NE(html.find("(stat) &plusmn; "), std::string::npos);
      EXPECT_NE(html.find(" (total)"), std::string::npos);  // the result box gives the total
      for (const std::string& bad : PlusMinusZero(html))
        ADD_FAILURE() << "a std shown as 0: " << bad;
      for (const std::string& bad : RepeatedTicks(html)) ADD_FAILURE() << "repeated ticks: " << bad;
      EXPECT_NE(html.find("<svg class=\"sweep\""), std::string::npos);
    }
  }
}

TEST(ScaleFigures, TickHelpersTellEveryTickApart) {
  // A sweep of 2.2001-2.2005 kg m^2 printed "2.2" five times: the decimals follow the step.
  const double step = TickStep(2.2001, 2.2005, 6);
  EXPECT_DOUBLE_EQ(step, 0.0001);
  EXPECT_EQ(TickDecimals(step), 4);
  EXPECT_EQ(TickLabel(2.2003, TickDecimals(step)), "2.2003");
  EXPECT_EQ(TickLabel(-0.00001, 2), "0.00");
  EXPECT_EQ(TickDecimals(20.0), 0);
  EXPECT_EQ(TickDecimals(0.25), 1);  // 1, 2 or 5 x 10^n steps: 0.25 does not occur
}

TEST(ConsoleWidth, NaturalOrderAndWrapping) {
  EXPECT_TRUE(NaturalLess("trial_2.csv", "Trial_10.csv"));
  EXPECT_TRUE(NaturalLess("a_Log-1.csv", "A_log-2.csv"));
  EXPECT_FALSE(NaturalLess("trial_10.csv", "trial_9.csv"));
  const std::string text =
      "    warning: " + std::string(30, 'x') + "  aligned  " + std::string(200, 'y');
  const std::string wrapped = WrapText(text, 60, "        ");
  EXPECT_EQ(wrapped.rfind("    warning: ", 0), 0u);
  EXPECT_NE(wrapped.find("  aligned"), std::string::npos);  // blanks between words kept
  EXPECT_NE(wrapped.find("\n        yyyy"), std::string::npos);
}

// `process` and `fit --repeats` (stdout and stderr) on a simulated campaign of two trials per
// axis: no line over 160 characters.
TEST(ConsoleWidth, SimulatedCampaignLinesAtMost160) {
  TempDir dir("bifilar_console");
  const std::string logs = dir.path + "/logs";
  const ScaledCampaign c = ScaledSpec(0.05, logs, 2);
  WriteFile(dir.path + "/spec.yaml", c.spec);
  RunSimulateCampaign(ReadSimulateSpec(dir.path + "/spec.yaml"), logs);
  WriteFile(dir.path + "/config.yaml", c.config_imperial);
  std::string logs_list;
  for (const char* a : {"roll_0_pitch_0", "roll_0_pitch_-90", "roll_90_pitch_0"}) {
    for (const char* t : {"trial_1.csv", "trial_2.csv"})
      logs_list += " " + logs + "/" + a + "/" + t;
  }
  for (const std::string& args : {"process " + dir.path + "/config.yaml --out " + dir.path + "/out",
                                  "fit " + dir.path + "/config.yaml" + logs_list + " --repeats",
                                  "fit " + dir.path + "/config.yaml" + logs_list}) {
    const test_support::CliRun run = Bifilar(dir, args);
    EXPECT_LE(run.exit_code, 1) << args << "\n" << run.err;
    for (const std::string* text : {&run.out, &run.err}) {
      std::string line;
      EXPECT_LE(LongestLine(*text, &line), 160u) << args << ":\n" << line;
    }
  }
}

// Every command's --help, `export`'s included (its documents on stdout are not wrapped, its help
// is): no line over 160 characters.
TEST(ConsoleWidth, EveryHelpAtMost160) {
  TempDir dir("bifilar_help_width");
  for (const char* command : {"", "process", "report", "fit", "ellipse", "plan", "simulate",
                              "inspect", "init", "export", "watch"}) {
    const test_support::CliRun run = Bifilar(dir, std::string(command) + " --help");
    EXPECT_EQ(run.exit_code, 0) << command << "\n" << run.err;
    std::string line;
    EXPECT_LE(LongestLine(run.out, &line), 160u) << command << ":\n" << line;
  }
}

// The same on the real quadrotor logs: `fit --repeats` over all 24 and `process` of the BaseModel
// campaign (configs/crazyflie_basemodel.yaml).
TEST(ConsoleWidth, RealLogsLinesAtMost160) {
  BIFILAR_REAL_DATA(data, "crazyflie");
  TempDir dir("bifilar_console_real");
  const std::string source = BIFILAR_SOURCE_DIR;
  std::string logs;
  for (const auto& entry : fs::directory_iterator(data)) {
    if (entry.path().extension() == ".csv") logs += " " + entry.path().string();
  }
  WriteFile(dir.path + "/fit.yaml", test_support::QuadrotorFitConfig());
  for (const std::string& args :
       {"fit " + dir.path + "/fit.yaml" + logs + " --repeats",
        "process " + source + "/configs/crazyflie_basemodel.yaml --runs-root " + data + " --out " +
            dir.path + "/out"}) {
    const test_support::CliRun run = Bifilar(dir, args);
    EXPECT_LE(run.exit_code, 1) << args << "\n" << run.err.substr(0, 2000);
    for (const std::string* text : {&run.out, &run.err}) {
      std::string line;
      EXPECT_LE(LongestLine(*text, &line), 160u) << args << ":\n" << line;
    }
  }
}

}  // namespace
}  // namespace bifilar
