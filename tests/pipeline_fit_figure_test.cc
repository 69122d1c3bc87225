// Issue 25 items 1-2: the fit figure draws the fit that gave the reported I (the lowest-amplitude
// band's on a rig whose I grows with amplitude), its title names the std and gives I to the
// std's digits, and its SVG is light and searchable (text as <text>, tick labels on the page).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "base/units.h"
#include "fit/trace_synth.h"
#include "pendulum/model.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/figures/sweep_plot.h"
#include "pipeline/figures/trace_plot.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/trace_process.h"
#include "test_support.h"

namespace bifilar {
namespace {

using test_support::ReadFile;
using test_support::TempDir;
using test_support::WriteFile;
const std::string kSource = BIFILAR_SOURCE_DIR;

// Where the figures go: the test's own folder, or BIFILAR_KEEP_FIGURES=DIR to keep them there and
// look at them (e.g. chromium --headless --screenshot).
std::string FigureDir(const TempDir& dir) {
  const char* keep = std::getenv("BIFILAR_KEEP_FIGURES");
  return keep != nullptr && *keep != '\0' ? std::string(keep) : dir.path;
}

// Mean period of v (deg/s) about `level` from its upward crossings (linear interpolation).
double PeriodByCrossings(const std::vector<double>& t, const std::vector<double>& v, double level,
                         int* crossings) {
  std::vector<double> up;
  for (size_t k = 1; k < t.size(); ++k) {
    const double a = v[k - 1] - level, b = v[k] - level;
    if (a < 0.0 && b >= 0.0) up.push_back(t[k - 1] + (t[k] - t[k - 1]) * (-a) / (b - a));
  }
  *crossings = static_cast<int>(up.size());
  return up.size() < 2 ? NAN : (up.back() - up.front()) / (up.size() - 1);
}

// One yaw log of the non-ideal rig preset (I grows ~4 % per 10 deg), fitted as `fit` does.
struct NonIdealFit {
  TempDir dir{"bifilar_fit_figure"};
  CampaignConfig config;
  TraceFitResult fit;
  TraceRecord record;
  NonIdealFit() {
    std::string spec = ReadFile(kSource + "/configs/simulate_nonideal_rig.yaml");
    spec.replace(spec.find("pitch_deg: [0, 90]"), 18, "pitch_deg: [0]");
    spec.replace(spec.find("trials_per_pitch: 4"), 19, "trials_per_pitch: 1");
    RunSimulateCampaign(ParseSimulateSpec(spec, "nonideal.yaml"), dir.path + "/logs");
    WriteFile(dir.path + "/c.yaml",
              "rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\n"
              "imu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: deg/s}\n"
              "  accel: null\n");
    ConfigLoadOptions load;
    load.require_runs = false;
    config = LoadCampaignConfig(dir.path + "/c.yaml", load);
    const std::string log = dir.path + "/logs/pitch_0/trial_1.csv";
    ImuData data;
    std::string why;
    EXPECT_TRUE(TryReadImuLog(log, config.imu.format, config.limits.LogOptions(), &data, &why))
        << why;
    TraceProcessOptions options;
    options.figure_paths = {dir.path + "/fit.svg", dir.path + "/fit.png"};
    record = ProcessTraceData(config, data, log, options, &fit);
  }
};

NonIdealFit& Shared() {
  static NonIdealFit* f = new NonIdealFit();
  return *f;
}

// The curve drawn has the period of the reported I (small-angle period of the band's low
// amplitude, 3-6 deg: the amplitude and damping corrections are < 0.05 %), to 0.1 %; the
// whole-window fit's I, 3 % higher, would be 1.5 % off.
TEST(FitFigure, DrawnCurveHasThePeriodOfTheReportedInertia) {
  const NonIdealFit& f = Shared();
  ASSERT_EQ(f.record.status, TraceStatus::kOk) << f.record.message;
  ASSERT_EQ(f.fit.inertia_source, "low_amplitude_band");
  TraceFigureData d;
  std::string why;
  ASSERT_TRUE(MakeTraceFigureData(f.fit, TracePlotOptions(), &d, &why)) << why;
  EXPECT_TRUE(d.from_band);
  int crossings = 0;
  const double drawn = PeriodByCrossings(d.t_s, d.fitted_deg_per_s, d.bias_deg_per_s, &crossings);
  EXPECT_GE(crossings, 5);
  const RigGeometry geometry = GeometryForRole(f.config, TraceRole::kAircraft);
  // I = m g D^2 T^2 / (16 pi^2 L) is linear in T^2: T(I) = T_ref sqrt(I / I(T_ref)).
  auto period_of = [&](double inertia) {
    return std::sqrt(inertia / InertiaFromSmallAnglePeriod(geometry, 1.0));
  };
  const double reported = period_of(f.fit.params.inertia_kg_m2);
  const double window = period_of(f.fit.inertia_window_kg_m2);
  std::printf(
      "  drawn period %.5f s over %d crossings; reported I %.6f -> %.5f s; whole-window "
      "I %.6f -> %.5f s\n",
      drawn, crossings, f.fit.params.inertia_kg_m2, reported, f.fit.inertia_window_kg_m2, window);
  EXPECT_NEAR(drawn / reported, 1.0, 1e-3);
  EXPECT_GT(std::abs(window / reported - 1.0), 5e-3);  // the test tells the two fits apart
  // The residual panel is the drawn fit's: measured - fitted, its rms and rms/noise.
  for (size_t k = 0; k < d.t_s.size(); k += 97)
    EXPECT_NEAR(d.residual_deg_per_s[k], d.measured_deg_per_s[k] - d.fitted_deg_per_s[k], 1e-9);
  EXPECT_NE(d.residual_label.find("× gyro noise"), std::string::npos);
  EXPECT_LT(d.rms_over_noise, f.fit.rms_over_noise);  // the band fits better than the window
  // Whole window also drawn, and said not to be the result.
  EXPECT_GT(d.whole_t_s.size(), d.t_s.size());
  EXPECT_NE(d.whole_label.find("not the result"), std::string::npos);
}

TEST(FitFigure, TitleNamesTheStdAndGivesTheDigitsItSupports) {
  const NonIdealFit& f = Shared();
  TracePlotOptions options;
  options.inertia_std_kg_m2 = f.record.inertia_total_std_total_kg_m2;
  options.std_label = "total";
  TraceFigureData d;
  std::string why;
  ASSERT_TRUE(MakeTraceFigureData(f.fit, options, &d, &why)) << why;
  EXPECT_NE(d.title.find(
                ValueWithStd(f.fit.params.inertia_kg_m2, f.record.inertia_total_std_total_kg_m2)),
            std::string::npos)
      << d.title;
  EXPECT_NE(d.title.find("1σ total"), std::string::npos) << d.title;
  // No bare symbols: the subtitles name what K_D, C and the bias are; no rho.
  for (const std::string& text : {d.title, d.subtitle, d.detail, d.residual_label}) {
    EXPECT_EQ(text.find("#gr"), std::string::npos) << text;
    EXPECT_EQ(text.find("bias ="), std::string::npos) << text;
  }
  EXPECT_NE(d.detail.find("drag K#dD#u"), std::string::npos);
  EXPECT_NE(d.detail.find("viscous C"), std::string::npos);
  EXPECT_NE(d.detail.find("gyro bias"), std::string::npos);
}

TEST(FitFigure, ValueWithStdKeepsTwoDigitsOfTheStd) {
  EXPECT_EQ(ValueWithStd(0.0501823, 0.00066), "0.05018 ± 0.00066");
  EXPECT_EQ(ValueWithStd(0.127, 0.0032), "0.1270 ± 0.0032");
  EXPECT_EQ(ValueWithStd(1234.6, 12.0), "1235 ± 12");
  EXPECT_EQ(ValueWithStd(1.6e-5, 2.0e-7), "(1.600 ± 0.020) × 10#u-5#d");
  EXPECT_EQ(ValueWithStd(2.5e6, 3.0e4), "(2.500 ± 0.030) × 10#u6#d");
}

// Each <text> of an SVG: its x, anchor, font size and characters (UTF-8 code points).
struct SvgText {
  double x = 0.0, size = 0.0;
  std::string anchor, content;
};
// (Scanned by hand: std::regex recurses per character and overflows the stack on a path's
// 100 kB d attribute.)
std::vector<SvgText> Texts(const std::string& svg) {
  std::vector<SvgText> out;
  const std::regex tag("<[^>]*>");
  for (size_t at = svg.find("<text"); at != std::string::npos; at = svg.find("<text", at + 1)) {
    const size_t attrs_end = svg.find('>', at), close = svg.find("</text>", at);
    if (attrs_end == std::string::npos || close == std::string::npos) break;
    const std::string attrs = svg.substr(at + 5, attrs_end - at - 5);
    SvgText t;
    std::smatch m;
    if (std::regex_search(attrs, m, std::regex(" x=\"([-0-9.]+)\""))) t.x = std::stod(m[1]);
    if (std::regex_search(attrs, m, std::regex("font-size=\"([0-9.]+)\"")))
      t.size = std::stod(m[1]);
    t.anchor =
        std::regex_search(attrs, m, std::regex("text-anchor=\"([a-z]+)\"")) ? m[1].str() : "start";
    t.content = std::regex_replace(svg.substr(attrs_end + 1, close - attrs_end - 1), tag, "");
    if (attrs.find("transform") == std::string::npos) out.push_back(t);  // rotated: skipped
  }
  return out;
}

size_t CodePoints(const std::string& s) {
  size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

// Light and searchable: at most 300 kB, text as <text> (no glyph outlines), the title's I
// readable in the file, and every horizontal text inside the page: a tick label at 0.64 em a
// character (DejaVu Sans digits, the widest common sans-serif), other text at 0.5 em (its mean
// over mixed lower case).
void ExpectLightSearchableSvg(const std::string& path, const std::string& must_contain) {
  const std::string svg = ReadFile(path);
  EXPECT_LE(svg.size(), 300u * 1024u) << path;
  EXPECT_EQ(svg.find("<symbol"), std::string::npos) << path;
  EXPECT_NE(svg.find(must_contain), std::string::npos) << path << " lacks " << must_contain;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, std::regex("viewBox=\"0 0 ([0-9.]+) ")));
  const double width = std::stod(m[1]);
  // Well-formed enough for a browser: no attribute twice in one element.
  for (size_t at = svg.find('<'); at != std::string::npos; at = svg.find('<', at + 1)) {
    const size_t end = svg.find('>', at);
    if (end == std::string::npos) break;
    const std::string tag = svg.substr(at, end + 1 - at);
    for (const char* attr : {" fill=\"", " stroke=\"", " d=\"", " x=\"", " y=\""}) {
      const size_t first = tag.find(attr);
      EXPECT_TRUE(first == std::string::npos || tag.find(attr, first + 1) == std::string::npos)
          << path << ": " << attr << " twice in " << tag.substr(0, 120);
    }
  }
  const std::vector<SvgText> texts = Texts(svg);
  EXPECT_GE(texts.size(), 10u) << path;
  for (const SvgText& t : texts) {
    const bool number = std::regex_match(t.content, std::regex("[-0-9.]+"));
    const double w = (number ? 0.64 : 0.5) * t.size * CodePoints(t.content);
    const double lo = t.anchor == "end" ? t.x - w : t.anchor == "middle" ? t.x - w / 2 : t.x;
    EXPECT_GE(lo, 0.0) << path << ": \"" << t.content << "\" starts off the page";
    EXPECT_LE(lo + w, width) << path << ": \"" << t.content << "\" ends off the page";
  }
}

TEST(FitFigure, SvgIsLightAndSearchable) {
  const NonIdealFit& f = Shared();
  ASSERT_EQ(f.record.figures.size(), 2u) << f.record.message;
  ExpectLightSearchableSvg(
      f.dir.path + "/fit.svg",
      ValueWithStd(f.fit.params.inertia_kg_m2, f.record.inertia_total_std_total_kg_m2));
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// A sweep of `bands` bands about `inertia` (kg m^2) with a 3 % per 10 deg trend.
AmplitudeSweep SyntheticSweep(double inertia, int bands) {
  AmplitudeSweep s;
  s.evaluated = true;
  s.trend_detected = true;
  s.trend_exponent = 2.0;
  s.trend_coeff = 3e-4;
  s.inertia_zero_amplitude_kg_m2 = inertia;
  s.trend_z = 12.0;
  s.trend_percent_per_10deg = 3.0;
  for (int j = 0; j < bands; ++j) {
    AmplitudeSweepBand b;
    b.amplitude_start_deg = 30.0 - 25.0 * j / bands;
    b.amplitude_end_deg = 30.0 - 25.0 * (j + 1) / bands;
    b.amplitude_mean_deg = 0.5 * (b.amplitude_start_deg + b.amplitude_end_deg);
    b.inertia_kg_m2 = s.TrendAt(b.amplitude_mean_deg) * (1.0 + 1e-3 * ((j % 3) - 1));
    b.inertia_std_kg_m2 = 2e-3 * inertia;
    if (inertia == 0.12703) {  // flat: a narrow axis, long tick labels (0.12705)
      b.inertia_kg_m2 = inertia * (1.0 + 2e-4 * ((j % 3) - 1));
      b.inertia_std_kg_m2 = 1e-4 * inertia;
    }
    b.ok = true;
    s.bands.push_back(b);
  }
  s.low_band = bands - 1;
  return s;
}

// The sweep figure at the extremes: tiny and huge I, kg m^2 and slug ft^2, an unscaled axis
// (0.127: issue 25 saw ".127"), 3 bands and 20; full and compact.
TEST(FigureExtremes, SweepTickLabelsAndTextStayOnThePage) {
  TempDir dir("bifilar_sweep_extremes");
  int k = 0;
  for (double inertia : {1.6e-5, 0.127, 0.12703, 0.25, 2.9, 4500.0}) {
    for (double unit_scale : {1.0, 1.0 / kKgM2PerSlugFt2}) {
      for (int bands : {3, 20}) {
        for (int page : {0, 1, 2}) {  // 800 x 500 (default), 640 x 400 compact, 1100 x 700
          const bool compact = page == 1;
          const AmplitudeSweep sweep = SyntheticSweep(inertia, bands);
          SweepPlotOptions options;
          options.title = "pitch_-10/trial_1.csv";
          options.unit_scale = unit_scale;
          options.unit_label = unit_scale == 1.0 ? "kg m#u2#d" : "slug ft#u2#d";
          options.compact = compact;
          if (compact) options.figure = {640, 400};
          if (page == 2) options.figure = {1100, 700};  // `fit --plot`
          const std::string path = FigureDir(dir) + "/s" + std::to_string(k++) + ".svg";
          std::string why;
          ASSERT_TRUE(WriteAmplitudeSweepFigure(sweep, sweep.bands.back().inertia_kg_m2,
                                                2e-3 * inertia, path, options, &why))
              << why;
          SCOPED_TRACE("I " + std::to_string(inertia) + ", scale " + std::to_string(unit_scale) +
                       ", " + std::to_string(bands) + " bands" + (compact ? ", compact" : ""));
          ExpectLightSearchableSvg(path, "amplitude (deg)");
        }
      }
    }
  }
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// An ideal rig (the result is the whole window's fit): the figure draws that fit, at the
// extremes of I (a 34 g quadrotor's 1.6e-5 kg m^2, an airliner model's 4500 kg m^2), slug ft^2
// and kg m^2, and a dense log (15 000 samples: an envelope instead of dots), each SVG light,
// searchable and on the page.
TEST(FigureExtremes, WindowFitFiguresAtTheExtremes) {
  TempDir dir("bifilar_fit_extremes");
  int k = 0;
  for (double inertia : {1.6e-5, 1.1616, 4500.0}) {
    for (double rate_hz : {20.0, 100.0}) {
      SyntheticTraceOptions o;
      o.geometry = {2.0, 0.88, 6.0 * inertia / 1.1616,
                    kStandardGravityMps2};  // same period for every I
      o.params = {inertia, 0.004 * inertia, 0.002 * inertia};
      o.amplitude_deg = 10.0;
      o.duration_s = 150.0;
      o.sample_rate_hz = rate_hz;
      o.seed = 7;
      TraceFitInput in;
      ASSERT_TRUE(MakeSyntheticTrace(o, &in));
      const TraceFitResult fit = FitTrace(in, TraceFitOptions());
      ASSERT_TRUE(fit.HasFit()) << fit.BriefReport();
      ASSERT_EQ(fit.inertia_source, "window");
      TraceFigureData d;
      std::string why;
      ASSERT_TRUE(MakeTraceFigureData(fit, TracePlotOptions(), &d, &why)) << why;
      EXPECT_FALSE(d.from_band);
      EXPECT_EQ(d.t_s.size(), fit.t_s.size());
      EXPECT_TRUE(d.whole_t_s.empty());
      for (double unit_scale : {1.0, 1.0 / kKgM2PerSlugFt2}) {
        TracePlotOptions options;
        options.title = "pitch_-10/trial_1.csv";
        options.unit_scale = unit_scale;
        options.unit_label = unit_scale == 1.0 ? "kg m#u2#d" : "slug ft#u2#d";
        const std::string path = FigureDir(dir) + "/f" + std::to_string(k++) + ".svg";
        ASSERT_TRUE(WriteTraceFitFigure(fit, path, options, &why)) << why;
        SCOPED_TRACE(path);
        ExpectLightSearchableSvg(path, "fit of the whole window");
      }
    }
  }
}

}  // namespace
}  // namespace bifilar

namespace bifilar {
namespace {

// The ellipse figures (moments against pitch, polar) at the extremes: 200 points of a 1.6e-5
// kg m^2 quadrotor, and 4 points of a 4500 slug ft^2 airframe.
TEST(FigureExtremes, EllipseFiguresStayOnThePage) {
  TempDir dir("bifilar_ellipse_extremes");
  std::string many = "pitch_deg,inertia,std\n", four = "pitch_deg,inertia,std\n";
  for (int i = 0; i < 200; ++i) {
    const double theta = -85.0 + 170.0 * i / 199.0, t = (theta - 2.0) * kRadPerDeg;
    many +=
        std::to_string(theta) + "," +
        std::to_string(1.6e-5 * std::cos(t) * std::cos(t) + 2.4e-5 * std::sin(t) * std::sin(t)) +
        ",3e-8\n";
  }
  for (int theta : {-60, -20, 20, 60}) {
    const double t = (theta - 5.0) * kRadPerDeg;
    four +=
        std::to_string(theta) + "," +
        std::to_string(4500.0 * std::cos(t) * std::cos(t) + 6100.0 * std::sin(t) * std::sin(t)) +
        ",5\n";
  }
  WriteFile(dir.path + "/many.csv", many);
  WriteFile(dir.path + "/four.csv", four);
  const std::string out = FigureDir(dir);
  for (const std::string& table : {std::string("many"), std::string("four")}) {
    const std::string units = table == "four" ? " --units imperial --covariance absolute" : "";
    const test_support::CliRun run =
        test_support::Bifilar(dir, "ellipse " + dir.path + "/" + table +
                                       ".csv --bootstrap 0 --plot " + out + "/" + table + units);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    for (const char* figure : {"/ellipse_moments.svg", "/ellipse_polar.svg"}) {
      SCOPED_TRACE(table + figure);
      ExpectLightSearchableSvg(out + "/" + table + figure, "llipse of inertia");
    }
    // The polar panels draw tiny and huge radii in units of a power of ten named in the axis
    // labels, not with PLplot's own "(x10^n)" mark, which covered the title and the unit.
    const std::string polar = ReadFile(out + "/" + table + "/ellipse_polar.svg");
    EXPECT_EQ(polar.find("(x10"), std::string::npos) << table;
    const std::string power = table == "four" ? "3" : "-5";  // slug ft^2 in thousands; 1e-5 kg m^2
    const size_t ten = polar.find("(10<tspan");
    ASSERT_NE(ten, std::string::npos) << table;
    const size_t exponent = polar.find('>', ten + 9) + 1;
    EXPECT_EQ(polar.compare(exponent, power.size() + 1, power + "<"), 0) << polar.substr(ten, 80);
  }
}

}  // namespace
}  // namespace bifilar
