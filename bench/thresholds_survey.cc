// What each default quality threshold passes, warns and rejects (issue 8 item 1): every quality
// statistic of the trace fit measured on the real logs beside the repository (Crazyflie CSV logs,
// PX4 .ulg flight logs), on the simulator's presets, on ideal synthetic windows with AR(1) noise
// and irregular 30 Hz sampling, on deliberately bad simulated data, and on the sample campaign.
// Prints one Markdown table (README, "What the defaults pass and reject").
//
//   build/bench/bifilar_thresholds_survey [DATA_DIR]
//
// DATA_DIR holds crazyflie/*.csv (the 24 public Crazyflie logs) and px4/*.ulg; without it the
// real-log rows say "absent".
//
// Every threshold is the default of TraceFitOptions / GlitchOptions: nothing here sets one.
// Data sets that are absent are listed as such. Seeds are fixed: the table is reproducible.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "base/units.h"
#include "base/user_error.h"
#include "fit/glitch.h"
#include "fit/trace_fit.h"
#include "fit/trace_synth.h"
#include "pipeline/campaign/campaign.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/config/config.h"
#include "pipeline/logs/imu_log.h"
#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

namespace fs = std::filesystem;
const std::string kSource = BIFILAR_SOURCE_DIR;

// The quality statistics of one trace (NaN: not computed, e.g. rejected before the fit).
struct TraceStats {
  std::string status;  // "ok", "warned" (ok with a quality flag), "rejected", "error"
  std::string reason;  // message of a rejected/error trace
  double rms_over_noise = NAN;
  double whiteness = NAN;  // max |rho_k| after AR(1) prewhitening
  double secondary = NAN;  // secondary-motion ratio
  double residual_fraction = NAN;
  double cycles = NAN;             // periods in the window (min_periods)
  double trend_z = NAN;            // |z| of the amplitude sweep's trend
  int glitches = 0;                // glitch samples dropped
  std::vector<std::string> flags;  // quality flags raised
};

struct DataSet {
  std::string name;
  std::vector<TraceStats> traces;
  std::string absent;  // non-empty: the data set could not be made (why)
};

double ResidualFraction(const TraceFitResult& fit) {
  if (fit.sweep.trend_detected && fit.sweep.low_band >= 0)
    return fit.sweep.bands[fit.sweep.low_band].residual_fraction;
  return fit.signal_rms_rad_per_s > 0.0 ? fit.residual_rms_rad_per_s / fit.signal_rms_rad_per_s
                                        : NAN;
}

void FillFromFit(const TraceFitResult& fit, TraceStats* s) {
  if (!fit.HasFit()) return;
  s->rms_over_noise = fit.rms_over_noise;
  s->whiteness = fit.prewhitened_autocorr_max;
  s->residual_fraction = ResidualFraction(fit);
  s->cycles = fit.guess.cycles;
  if (fit.sweep.evaluated) s->trend_z = std::abs(fit.sweep.trend_z);
}

// Quality flags that make an ok trace "ok with warnings". `bands_disagree` is no warning: it only
// scales the statistical std by the Birge ratio (docs/method.md, "Amplitude sweep").
bool HasQualityWarning(const std::vector<std::string>& flags) {
  for (const std::string& f : flags)
    if (f != "figure_failed" && f != "bands_disagree") return true;
  return false;
}

int GlitchesIn(const std::vector<std::string>& warnings) {
  int n = 0;
  for (const std::string& w : warnings)
    if (w.find("glitch sample") != std::string::npos) n += std::atoi(w.c_str());
  return n;
}

TraceStats FromRecord(const TraceRecord& r, const TraceFitResult& fit) {
  TraceStats s;
  s.status = r.status == TraceStatus::kOk ? (HasQualityWarning(r.flags) ? "warned" : "ok")
                                          : ToString(r.status);
  if (r.status != TraceStatus::kOk) {
    s.reason = r.message;
    const std::string prefix = r.file + ": ";
    if (s.reason.rfind(prefix, 0) == 0) s.reason = s.reason.substr(prefix.size());
  }
  s.flags = r.flags;
  FillFromFit(fit, &s);
  if (std::isfinite(r.secondary_motion_ratio)) s.secondary = r.secondary_motion_ratio;
  s.glitches = GlitchesIn(r.warnings);
  return s;
}

// One log through the whole `bifilar fit` path (reader, glitches, axis, window, fit, sweep).
TraceStats SurveyLog(const CampaignConfig& config, const std::string& path) {
  ImuData data;
  std::string why;
  if (!TryReadImuLog(path, config.imu.format, ImuLogOptions(), &data, &why)) {
    TraceStats s;
    s.status = "error";
    s.reason = why;
    return s;
  }
  TraceFitResult fit;
  TraceProcessOptions options;
  options.display_name = fs::path(path).filename().string();
  const TraceRecord r = ProcessTraceData(config, data, path, options, &fit);
  return FromRecord(r, fit);
}

// A synthetic window fitted directly (FitTrace: no secondary motion), glitches searched too.
TraceStats SurveyWindow(const TraceFitInput& in) {
  const TraceFitResult fit = FitTrace(in, TraceFitOptions());
  TraceStats s;
  s.status = fit.status == TraceFitStatus::kOk ? (HasQualityWarning(fit.flags) ? "warned" : "ok")
                                               : ToString(fit.status);
  if (fit.status != TraceFitStatus::kOk) s.reason = fit.message;
  s.flags = fit.flags;
  FillFromFit(fit, &s);
  s.glitches = static_cast<int>(FindGlitches(in.t_s, in.rate_rad_per_s, GlitchOptions()).size());
  return s;
}

std::string TempDir() {
  char tmpl[] = "/tmp/bifilar_thresholds_XXXXXX";
  const char* dir = mkdtemp(tmpl);
  if (dir == nullptr) throw UserError("cannot create a temporary folder in /tmp");
  return dir;
}

CampaignConfig FitConfig(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  ConfigLoadOptions options;
  options.require_runs = false;
  return LoadCampaignConfig(path, options);
}

std::vector<std::string> FilesUnder(const std::string& dir, const std::string& ext) {
  std::vector<std::string> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string p = e.path().string();
    if (e.is_regular_file() && p.size() > ext.size() &&
        p.compare(p.size() - ext.size(), ext.size(), ext) == 0)
      files.push_back(p);
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The preset's text with `from` replaced by `to` (a variant of a preset); throws when absent.
std::string Replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) throw UserError("preset has no '" + from + "'");
  return text.replace(at, from.size(), to);
}

DataSet SimulatedPreset(const std::string& name, const std::string& spec_text,
                        const std::string& fit_yaml) {
  DataSet set{name, {}, ""};
  const std::string dir = TempDir();
  try {
    const SimulateSpec spec = ParseSimulateSpec(spec_text, name);
    RunSimulateCampaign(spec, dir + "/logs");
    const CampaignConfig config = FitConfig(dir, "fit.yaml", fit_yaml);
    for (const std::string& path : FilesUnder(dir + "/logs", ".csv"))
      set.traces.push_back(SurveyLog(config, path));
  } catch (const std::exception& e) {
    set.absent = e.what();
  }
  fs::remove_all(dir);
  return set;
}

const char* kQuadrotorFit =
    "gravity_mps2: 9.8066\n"
    "rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: 0.0343}\n"
    "imu:\n  time: {column: t, unit: s}\n  gyro: {columns: [wx, wy, wz], unit: rad/s}\n"
    "  accel: null\n";
const char* kNonIdealFit =
    "rig: {filar_length_m: 0.74, filar_separation_m: 0.16, mass_kg: 3.34}\n"
    "imu:\n  time: {column: t, unit: ms}\n  gyro: {columns: [gx, gy, gz], unit: deg/s}\n"
    "  accel: null\n";

std::string CrazyflieFit(double mass_kg) {
  char text[512];
  std::snprintf(text, sizeof(text),
                "gravity_mps2: 9.8066\n"
                "rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: %.4f}\n"
                "imu:\n  time: {column: t, unit: s}\n"
                "  gyro: {columns: [wx, wy, wz], unit: rad/s}\n  accel: null\n",
                mass_kg);
  return text;
}

// The synthetic window of tests/pipeline_real_rig_test.cc (CoverageUnderColouredNoise...).
SyntheticTraceOptions CoverageTrace(double phi, int seed) {
  SyntheticTraceOptions o;
  o.geometry = {2.0, 1.8, 6.75, kStandardGravityMps2};
  o.params = {4.1, 0.04, 0.01};
  o.amplitude_deg = 10.0 + 0.5 * (seed % 30);
  o.duration_s = 40.0;
  o.sample_rate_hz = 30.0;
  o.irregular_steps = true;
  o.noise_deg_per_s = 0.5;
  o.noise_ar1_phi = phi;
  o.seed = 1000 * static_cast<int>(phi * 100) + seed;
  return o;
}

DataSet SyntheticSet(const std::string& name, double phi, int n, double sway_fraction,
                     bool noise_only, double duration_s = 40.0) {
  DataSet set{name, {}, ""};
  for (int seed = 1; seed <= n; ++seed) {
    SyntheticTraceOptions o = CoverageTrace(phi, seed);
    if (noise_only) o.amplitude_deg = 0.0;
    o.duration_s = duration_s;
    TraceFitInput in;
    if (!MakeSyntheticTrace(o, &in)) {
      set.absent = "synthetic trace failed";
      return set;
    }
    in.noise_rad_per_s = 0.0;  // unknown, as in `bifilar fit` without a rest segment
    if (sway_fraction > 0.0) {
      // Sway leaking into the measured rate: a decaying 0.65 Hz oscillation (the swing is at
      // 0.41 Hz) of sway_fraction times the swing's initial rate amplitude.
      const double omega = 2.0 * kPi * 0.407;
      const double amp = sway_fraction * o.amplitude_deg * kRadPerDeg * omega;
      for (size_t k = 0; k < in.t_s.size(); ++k) {
        const double t = in.t_s[k] - in.t_s[0];
        in.rate_rad_per_s[k] += amp * std::exp(-t / 30.0) * std::sin(2.0 * kPi * 0.65 * t + seed);
      }
    }
    set.traces.push_back(SurveyWindow(in));
  }
  return set;
}

// The sample campaign through RunCampaign, every trace's statistics kept.
DataSet SampleCampaign() {
  DataSet set{"sample campaign (`configs/prandtl_d.yaml`)", {}, ""};
  const std::string dir = TempDir();
  try {
    const CampaignConfig config = LoadCampaignConfig(kSource + "/configs/prandtl_d.yaml");
    std::mutex mutex;
    std::map<std::string, TraceStats> stats;
    CampaignOptions options;
    options.out_dir = dir + "/out";
    options.force = true;
    options.write_report = false;
    options.figures = false;
    options.jobs = 2;
    options.fit_function = [&](const CampaignConfig& c, const std::string& path,
                               const TraceProcessOptions& o) {
      ImuData data;
      std::string why;
      TraceRecord r;
      TraceFitResult fit;
      if (TryReadImuLog(path, c.imu.format, ImuLogOptions(), &data, &why)) {
        r = ProcessTraceData(c, data, path, o, &fit);
      } else {
        r.file = path;
        r.status = TraceStatus::kError;
        r.message = why;
      }
      std::lock_guard<std::mutex> lock(mutex);
      stats[path] = FromRecord(r, fit);
      return r;
    };
    RunCampaign(config, options);
    for (auto& [path, s] : stats) set.traces.push_back(s);
  } catch (const std::exception& e) {
    set.absent = e.what();
  }
  fs::remove_all(dir);
  return set;
}

// --- Markdown --------------------------------------------------------------------------------

std::string Num(double v) {
  char text[32];
  const double a = std::abs(v);
  if (a >= 100)
    std::snprintf(text, sizeof(text), "%.0f", v);
  else if (a >= 10)
    std::snprintf(text, sizeof(text), "%.1f", v);
  else
    std::snprintf(text, sizeof(text), "%.2f", v);
  return text;
}

// "min–max · k" over the finite values; k = how many fire (`fires`).
template <typename Get, typename Fires>
std::string Cell(const std::vector<TraceStats>& traces, Get get, Fires fires) {
  std::vector<double> v;
  int k = 0;
  for (const TraceStats& s : traces) {
    const double x = get(s);
    if (!std::isfinite(x)) continue;
    v.push_back(x);
    if (fires(x)) ++k;
  }
  if (v.empty()) return "–";
  std::sort(v.begin(), v.end());
  std::string cell = Num(v.front()) + "–" + Num(v.back());
  if (v.size() >= 20) {  // 95th percentile (nearest rank)
    const size_t rank = static_cast<size_t>(std::ceil(0.95 * v.size())) - 1;
    cell += " (p95 " + Num(v[rank]) + ")";
  }
  return cell + " · **" + std::to_string(k) + "**";
}

void PrintTable(const std::vector<DataSet>& sets) {
  const TraceFitOptions d;
  std::printf(
      "| data set | n | ok / warned / rejected / error | RMS/noise (warn > %s) | whiteness "
      "(warn > %s) | secondary motion (warn > %s, reject > %s) | residual fraction (reject > %s) "
      "| cycles (reject < %s) | amplitude trend \\|z\\| (trend > %s) | glitch samples | flags "
      "raised |\n",
      Num(d.max_rms_over_noise).c_str(), Num(d.max_residual_autocorr).c_str(),
      Num(d.max_secondary_motion_ratio).c_str(), Num(d.reject_secondary_motion_ratio).c_str(),
      Num(d.reject_residual_fraction).c_str(), Num(d.min_periods).c_str(),
      Num(d.sweep_trend_z).c_str());
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const DataSet& set : sets) {
    if (!set.absent.empty()) {
      std::printf("| %s | – | absent: %s | | | | | | | | |\n", set.name.c_str(),
                  set.absent.c_str());
      continue;
    }
    std::map<std::string, int> count, flags;
    for (const TraceStats& s : set.traces)
      for (const std::string& f : s.flags) ++flags[f];
    std::string flag_text;
    for (const auto& [f, k] : flags)
      flag_text += (flag_text.empty() ? "" : ", ") + ("`" + f + "` " + std::to_string(k));
    int glitch_traces = 0, glitch_samples = 0;
    for (const TraceStats& s : set.traces) {
      ++count[s.status];
      if (s.glitches > 0) ++glitch_traces;
      glitch_samples += s.glitches;
    }
    const std::string secondary =
        Cell(
            set.traces, [](const TraceStats& s) { return s.secondary; },
            [&](double x) { return x > d.max_secondary_motion_ratio; }) +
        " / **" +
        std::to_string(std::count_if(
            set.traces.begin(), set.traces.end(),
            [&](const TraceStats& s) { return s.secondary > d.reject_secondary_motion_ratio; })) +
        "**";
    std::printf(
        "| %s | %zu | %d / %d / %d / %d | %s | %s | %s | %s | %s | %s | %d in %d logs | %s |\n",
        set.name.c_str(), set.traces.size(), count["ok"], count["warned"], count["rejected"],
        count["error"],
        Cell(
            set.traces, [](const TraceStats& s) { return s.rms_over_noise; },
            [&](double x) { return x > d.max_rms_over_noise; })
            .c_str(),
        Cell(
            set.traces, [](const TraceStats& s) { return s.whiteness; },
            [&](double x) { return x > d.max_residual_autocorr; })
            .c_str(),
        secondary.c_str(),
        Cell(
            set.traces, [](const TraceStats& s) { return s.residual_fraction; },
            [&](double x) { return x > d.reject_residual_fraction; })
            .c_str(),
        Cell(
            set.traces, [](const TraceStats& s) { return s.cycles; },
            [&](double x) { return x < d.min_periods; })
            .c_str(),
        Cell(
            set.traces, [](const TraceStats& s) { return s.trend_z; },
            [&](double x) { return x > d.sweep_trend_z; })
            .c_str(),
        glitch_samples, glitch_traces, flag_text.empty() ? "–" : flag_text.c_str());
  }
  // Why the rejected and failed traces were refused (first 90 characters, counted).
  std::map<std::string, int> reasons;
  for (const DataSet& set : sets)
    for (const TraceStats& s : set.traces)
      if (!s.reason.empty()) {
        // Up to the first number, so that one reason with different values is counted once.
        std::string r = s.reason.substr(0, s.reason.find_first_of("0123456789"));
        const bool cut = r.size() < s.reason.size();
        while (!r.empty() && std::string(" ([:=").find(r.back()) != std::string::npos) r.pop_back();
        if (r.size() > 100) r = r.substr(0, 100);
        if (cut) r += " …";
        ++reasons[set.name + ": " + r];
      }
  if (!reasons.empty()) std::printf("\nRejected / error:\n\n");
  for (const auto& [r, n] : reasons) std::printf("- %d × %s\n", n, r.c_str());
}

int Main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : "";
  std::vector<DataSet> sets;
  std::fprintf(stderr, "real logs...\n");
  {
    DataSet set{"real: Crazyflie, 24 logs", {}, ""};
    const std::string dir = TempDir();
    try {
      const CampaignConfig base = FitConfig(dir, "base.yaml", CrazyflieFit(0.0343));
      const CampaignConfig narrow = FitConfig(dir, "narrow.yaml", CrazyflieFit(0.0381));
      for (const std::string& path : FilesUnder(data + "/crazyflie", ".csv")) {
        const bool is_narrow = fs::path(path).filename().string().rfind("Narrow", 0) == 0;
        set.traces.push_back(SurveyLog(is_narrow ? narrow : base, path));
      }
      if (set.traces.empty()) set.absent = "no DATA_DIR/crazyflie/*.csv";
    } catch (const std::exception& e) {
      set.absent = e.what();
    }
    sets.push_back(set);
    DataSet px4{"real: PX4 `.ulg` flight logs", {}, ""};
    try {
      const CampaignConfig config = FitConfig(
          dir, "px4.yaml", "rig: {filar_length_m: 0.594, filar_separation_m: 0.030, mass_kg: 1}\n");
      for (const std::string& path : FilesUnder(data + "/px4", ".ulg"))
        px4.traces.push_back(SurveyLog(config, path));
      if (px4.traces.empty()) px4.absent = "no DATA_DIR/px4/*.ulg";
    } catch (const std::exception& e) {
      px4.absent = e.what();
    }
    sets.push_back(px4);
    fs::remove_all(dir);
  }
  std::fprintf(stderr, "simulator presets...\n");
  const std::string quad = ReadText(kSource + "/configs/simulate_quadrotor.yaml");
  const std::string nonideal = ReadText(kSource + "/configs/simulate_nonideal_rig.yaml");
  sets.push_back(SimulatedPreset("sim: `simulate_quadrotor.yaml`", quad, kQuadrotorFit));
  sets.push_back(SimulatedPreset("sim: `simulate_nonideal_rig.yaml` (bad: softening)", nonideal,
                                 kNonIdealFit));
  std::fprintf(stderr, "synthetic windows...\n");
  for (const double phi : {0.0, 0.5, 0.8, 0.95}) {
    char name[96];
    std::snprintf(name, sizeof(name), "sim: ideal window, AR(1) φ = %.2g, irregular 30 Hz", phi);
    sets.push_back(SyntheticSet(name, phi, 40, 0.0, false));
  }
  std::fprintf(stderr, "bad simulations...\n");
  sets.push_back(SimulatedPreset("sim (bad): quadrotor, 3 glitches of 50 rad/s per log",
                                 Replaced(Replaced(quad, "spike_count: 1", "spike_count: 3"),
                                          "spike_rate_rad_per_s: 5", "spike_rate_rad_per_s: 50"),
                                 kQuadrotorFit));
  sets.push_back(SimulatedPreset("sim (bad): quadrotor, rocking up to 6° (real: 1.5°)",
                                 Replaced(quad, "rocking_max_deg: 1.5", "rocking_max_deg: 6"),
                                 kQuadrotorFit));
  sets.push_back(SimulatedPreset("sim (bad): quadrotor, rocking up to 10° (the simulator's limit)",
                                 Replaced(quad, "rocking_max_deg: 1.5", "rocking_max_deg: 10"),
                                 kQuadrotorFit));
  for (const double sway : {0.03, 0.1, 0.3, 1.0}) {
    char name[96];
    std::snprintf(name, sizeof(name), "sim (bad): window φ = 0.5 + %.0f %% sway on the swing axis",
                  100 * sway);
    sets.push_back(SyntheticSet(name, 0.5, 20, sway, false));
  }
  sets.push_back(
      SyntheticSet("sim (bad): window φ = 0.5 of 4 s (1.6 periods)", 0.5, 10, 0.0, false, 4.0));
  sets.push_back(SyntheticSet("sim (bad): AR(1) noise only, φ = 0.5", 0.5, 10, 0.0, true));
  std::fprintf(stderr, "sample campaign...\n");
  sets.push_back(SampleCampaign());
  PrintTable(sets);
  return 0;
}

}  // namespace
}  // namespace bifilar

int main(int argc, char** argv) {
  try {
    return bifilar::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "thresholds_survey: %s\n", e.what());
    return 2;
  }
}
