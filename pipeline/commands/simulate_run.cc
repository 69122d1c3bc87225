// `bifilar simulate`'s run: the command-line settings laid over the spec (ApplySimulateOverrides,
// SetSampleRateFromFlag), the checks of the output targets, and the campaign or the single trace
// simulated in memory and written (CSV, gzip, ULog or DataFlash, each marked as simulated) with
// its truth JSON (simulate_truth.cc). The spec is read by simulate_spec.cc.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/gzip.h"
#include "base/option_check.h"
#include "base/text_format.h"
#include "base/units.h"
#include "base/user_error.h"
#include "pendulum/model.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/commands/simulate_spec_steps.h"
#include "pipeline/logs/dataflash.h"
#include "pipeline/logs/dataflash_writer.h"
#include "pipeline/logs/simulated_log.h"
#include "pipeline/logs/ulog_writer.h"

namespace bifilar {
namespace {

// The footer of a log that ends like the Crazyflie logs: a blank line, then summary rows whose
// time column is numeric again (smaller than the last time) and whose last column is text.
std::string Footer(const SimulatedTrace& trace, const ImuFormat& format, const std::string& eol) {
  const char d = format.delimiter;
  const int columns = format.has_accel() ? 7 : 4;
  const double time_scale = 1.0 / ToSi(format.time_unit);
  auto row = [&](const std::string& time, const std::string& middle, const std::string& text) {
    std::string r = time;
    for (int c = 1; c < columns - 1; ++c) (r += d) += middle;
    (r += d) += text;
    return r + eol;
  };
  char release[64];
  std::snprintf(release, sizeof(release), "%.6g",
                (trace.truth.t_release_s - trace.truth.start_time_s) * time_scale);
  return eol + row("", "", "Rollout Completed: swing logged") + row(release, "0", "Flip Data") +
         row("0", "0", "Impact Data");
}

// Every log simulate writes carries the mark of a simulated log with its seed
// (pipeline/logs/simulated_log.h): the CSV's first line, a ULog information message, or a
// DataFlash MSG message.
void WriteTrace(const std::string& path, const SimulatedTrace& trace, const SimulateSpec& spec) {
  const std::string origin = SimulatedLogOrigin(spec.seed);
  if (NamedLikeDataflash(path)) {  // pipeline/logs/dataflash_writer.h
    ImuData imu = trace.imu;
    if (!spec.options.sensor.accelerometer) imu.accel_in_imu.clear();
    return WriteImuDataflash(path, imu, origin);
  }
  if (spec.ulog || path.find(".ulg") != std::string::npos) {  // pipeline/logs/ulog_writer.h
    ImuData imu = trace.imu;
    if (!spec.options.sensor.accelerometer) imu.accel_in_imu.clear();
    return WriteImuUlog(path, imu, origin);
  }
  ImuFormat format = spec.format;
  if (!spec.options.sensor.accelerometer) format.accel_columns = {"", "", ""};
  std::string text = SimulatedCsvMarkerLine(origin) + spec.write.line_end +
                     FormatImuLog(trace.imu, format, spec.write);
  if (spec.footer) text += Footer(trace, format, spec.write.line_end);
  const bool gzip = path.size() > 3 && path.compare(path.size() - 3, 3, ".gz") == 0;
  WriteFileAtomically(path, gzip ? GzipCompress(text) : text);
}

}  // namespace

double DefaultTimeJitterSigmaS(double sample_rate_hz) {
  const double fallback = SensorOptions().time_jitter_sigma_s;  // 1 ms
  return 0.1 / sample_rate_hz < fallback ? 0.1 / sample_rate_hz : fallback;
}

void ApplySimulateOverrides(const SimulateOverrides& o, bool single_trace, SimulateSpec* spec) {
  if (o.seed) spec->seed = *o.seed;
  if (o.no_accel) spec->options.sensor.accelerometer = false;
  if (o.duration_s) spec->options.timeline.free_s = {*o.duration_s, *o.duration_s};
  if (!single_trace) {
    if (o.length_m) spec->campaign.filar_length_m = *o.length_m;
    if (o.separation_m) spec->campaign.filar_separation_m = *o.separation_m;
    if (o.gravity_mps2) spec->campaign.gravity_mps2 = *o.gravity_mps2;
    return;
  }
  TraceRequest& t = spec->trace;
  if (o.inertia_kg_m2) t.inertia_kg_m2 = *o.inertia_kg_m2;
  if (o.mass_kg) t.mass_kg = *o.mass_kg;
  if (o.length_m) t.filar_length_m = *o.length_m;
  if (o.separation_m) t.filar_separation_m = *o.separation_m;
  if (o.gravity_mps2) t.gravity_mps2 = *o.gravity_mps2;
  if (o.amplitude_deg) t.amplitude_deg = *o.amplitude_deg;
  if (o.pitch_deg) t.pitch_deg = *o.pitch_deg;
}

SimulateCommandResult RunSimulate(const SimulateCommandOptions& a) {
  const SimulateOverrides& o = a.o;
  const SimulateSettingNames& n = a.names;
  auto positive = [](const std::optional<double>& v, const std::string& name) {
    if (v && !(*v > 0)) throw UserError(CheckMessage(name, *v, "> 0"));
  };
  positive(o.duration_s, n.duration);
  positive(a.sample_rate, n.sample_rate);
  positive(o.inertia_kg_m2, n.inertia);
  positive(o.mass_kg, n.mass);
  positive(o.length_m, n.length);
  positive(o.separation_m, n.separation);
  positive(o.gravity_mps2, n.gravity);
  if (!a.trace_csv.empty() && !a.out_dir.empty()) {
    throw UserError("give either " + n.out + " or " + n.trace + ", not both");
  }
  SimulateSpec spec =
      a.spec_file.empty() ? ParseSimulateSpec("{}", "<defaults>") : ReadSimulateSpec(a.spec_file);
  if (a.spec_file.empty()) spec.file.clear();
  if (!a.model.empty() && !ParsePendulumModel(a.model, &spec.options.model)) {
    throw UserError(n.model + ": unknown model '" + a.model + "'; allowed " +
                    PendulumModelAllowedValues());
  }
  if (a.sample_rate) SetSampleRateFromFlag(&spec, *a.sample_rate, n.sample_rate);
  if (!a.trace_csv.empty()) {
    if (spec.has_campaign) {
      throw UserError(a.spec_file +
                      ": has campaign sections (aircraft, rig, campaign); simulate "
                      "it with " +
                      n.out + ", or use a spec without them with " + n.trace);
    }
    ApplySimulateOverrides(o, true, &spec);
    const TraceRequest& t = spec.trace;
    for (const auto& [value, name] :
         {std::make_pair(&t.inertia_kg_m2, &n.inertia), std::make_pair(&t.mass_kg, &n.mass),
          std::make_pair(&t.filar_length_m, &n.length),
          std::make_pair(&t.filar_separation_m, &n.separation)}) {
      if (!*value) throw UserError("give " + *name + " (or its spec key) for a single trace");
    }
    std::string why;
    if (!spec.options.Check(&why)) throw UserError(why);
    return {RunSimulateTrace(spec, a.trace_csv, a.truth_json, a.force), a.trace_csv, spec.format};
  }
  if (a.out_dir.empty()) {
    throw UserError("nothing to do: give SPEC.yaml and " + n.out + " (campaign) or " + n.trace +
                    " (one trace); see bifilar simulate --help");
  }
  if (a.spec_file.empty()) throw UserError(n.out + " needs a campaign spec file SPEC.yaml");
  if (o.inertia_kg_m2 || o.mass_kg || o.amplitude_deg || o.pitch_deg || !a.truth_json.empty()) {
    throw UserError(n.inertia + ", " + n.mass + ", " + n.amplitude + ", " + n.pitch + " and " +
                    n.truth + " apply to " + n.trace +
                    " only; a campaign takes them from the spec");
  }
  ApplySimulateOverrides(o, false, &spec);
  std::string why;
  if (!spec.campaign.Check(&why) || !spec.options.Check(&why)) throw UserError(why);
  return {RunSimulateCampaign(spec, a.out_dir, a.force), a.out_dir, spec.format};
}

void SetSampleRateFromFlag(SimulateSpec* spec, double rate_hz, const std::string& flag) {
  if (!(rate_hz > 0 && rate_hz <= 100000)) {
    throw UserError(CheckMessage(flag, rate_hz, "in (0, 100000]"));
  }
  SensorOptions& s = spec->options.sensor;
  const std::string from = spec->file.empty() ? std::string("the spec") : spec->file;
  if (!spec->time_jitter_given) {
    s.time_jitter_sigma_s = DefaultTimeJitterSigmaS(rate_hz);
  } else if (s.time_jitter_sigma_s > 1.0 / rate_hz) {
    throw UserError(flag + " " + Fmt("%g", rate_hz) + ": 'sensor.time_jitter_sigma_s' = " +
                    Fmt("%g", s.time_jitter_sigma_s) + " s in " + from +
                    " is more than one sample period at that rate (" + Fmt("%g", 1.0 / rate_hz) +
                    " s); lower it in the spec (or remove it: the default follows the rate), or "
                    "lower " +
                    flag);
  }
  if (s.rocking_frequency_hz > rate_hz / 4) {
    throw UserError(flag + " " + Fmt("%g", rate_hz) + ": 'sensor.rocking_frequency_hz' = " +
                    Fmt("%g", s.rocking_frequency_hz) + " Hz in " + from +
                    " is above a quarter of that rate; raise " + flag + " to at least " +
                    Fmt("%g", 4 * s.rocking_frequency_hz) + " or lower the rocking frequency");
  }
  s.sample_rate_hz = rate_hz;
}

void CheckOutputFileTarget(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);  // follows symlinks
  if (fs::exists(status)) {
    if (fs::is_directory(status)) {
      throw UserError(what + " " + path + ": is a folder, expected a file name");
    }
    if (!fs::is_regular_file(status)) {
      throw UserError(what + " " + path +
                      ": exists and is not a regular file (a device, FIFO or socket); "
                      "simulate only writes regular files: choose another path");
    }
  }
  try {
    CheckFileTarget(path);  // a symbolic link, a name too long (base/atomic_file.h)
  } catch (const UserError& e) {
    throw UserError(what + " " + e.what());
  }
  if (fs::exists(status)) return;
  // A missing file: its nearest existing ancestor must be a folder.
  for (fs::path parent = fs::path(path).parent_path(); !parent.empty();
       parent = parent.parent_path()) {
    const fs::file_status ps = fs::status(parent, ec);
    if (fs::exists(ps)) {
      if (!fs::is_directory(ps)) {
        throw UserError(what + " " + path + ": " + parent.string() + " exists and is not a folder");
      }
      break;
    }
    if (parent == parent.parent_path()) break;
  }
}

std::string SimulateRunSummary::BriefReport() const {
  std::ostringstream os;
  os << files_written << " log" << (files_written == 1 ? "" : "s") << ", " << samples_written
     << " samples (" << samples_dropped << " dropped), truth in " << truth_path;
  return os.str();
}

SimulateRunSummary RunSimulateCampaign(const SimulateSpec& spec, const std::string& out_dir,
                                       bool force) {
  namespace fs = std::filesystem;
  if (!spec.has_campaign) {
    throw UserError((spec.file.empty() ? std::string("spec") : spec.file) +
                    ": a campaign needs the 'aircraft', 'rig' and 'campaign' sections");
  }
  if (out_dir.empty()) throw UserError("--out: empty output folder name");
  std::error_code ec;
  if (fs::exists(out_dir, ec) && !fs::is_directory(out_dir, ec)) {
    throw UserError(out_dir + ": output path exists and is not a folder");
  }
  CheckOutputFileTarget((fs::path(out_dir) / "truth.json").string(), "--out");  // fail early
  RefuseToReplace((fs::path(out_dir) / "truth.json").string(), "simulate --out", force);
  std::vector<CampaignTrace> traces;
  std::string why;
  if (!SimulateCampaign(spec.campaign, spec.options, spec.seed, &traces, &why)) {
    throw UserError((spec.file.empty() ? std::string("simulate") : spec.file) + ": " + why);
  }
  if (spec.ulog) {
    for (auto& ct : traces) ct.relative_path.replace(ct.relative_path.size() - 4, 4, ".ulg");
  }
  if (spec.gzip) {
    for (auto& ct : traces) ct.relative_path += ".gz";
  }
  const std::string truth = CampaignTruthJson(spec, traces);
  // Every target is checked before the first file is written: a regular file or nothing, and
  // nothing at all without --force (issue 23: the logs of a real campaign in OUT/pitch_0/).
  std::vector<std::string> targets;
  for (const auto& ct : traces) targets.push_back((fs::path(out_dir) / ct.relative_path).string());
  targets.push_back((fs::path(out_dir) / "truth.json").string());
  for (const std::string& target : targets) CheckOutputFileTarget(target, "--out");
  if (!force) {
    int existing = 0;
    std::string first;
    for (const std::string& target : targets) {
      if (fs::exists(fs::symlink_status(target, ec))) {
        if (existing++ == 0) first = target;
      }
    }
    if (existing > 0) {
      throw UserError("simulate --out: " + first + " exists" +
                      (existing > 1 ? " (and " + std::to_string(existing - 1) +
                                          " more of the files this campaign writes)"
                                    : std::string()) +
                      "; simulate writes over no file without --force: choose another "
                      "folder, or add --force to overwrite them");
    }
  }
  SimulateRunSummary summary;
  for (const auto& ct : traces) {
    WriteTrace((fs::path(out_dir) / ct.relative_path).string(), ct.trace, spec);
    ++summary.files_written;
    summary.samples_written += static_cast<long>(ct.trace.imu.size());
    summary.samples_dropped += ct.trace.truth.samples_dropped;
  }
  summary.truth_path = (fs::path(out_dir) / "truth.json").string();
  WriteFileAtomically(summary.truth_path, truth);
  return summary;
}

SimulateRunSummary RunSimulateTrace(const SimulateSpec& spec, const std::string& csv_path,
                                    const std::string& truth_path_in, bool force) {
  const TraceRequest& r = spec.trace;
  auto need = [](const std::optional<double>& v, const char* name, const char* flag) {
    if (!v) {
      throw UserError(std::string("missing ") + name + ": give " + flag +
                      " (or the spec key) for a single trace");
    }
    return *v;
  };
  const double inertia = need(r.inertia_kg_m2, "the whole suspended inertia", "--inertia-kg-m2");
  const double mass = need(r.mass_kg, "the whole suspended mass", "--mass-kg");
  const double length = need(r.filar_length_m, "the filar length L", "-L/--filar-length-m");
  const double separation =
      need(r.filar_separation_m, "the filar separation D", "-D/--filar-separation-m");
  if (csv_path.empty()) throw UserError("--trace: empty output file name");
  std::string truth_path = truth_path_in;
  if (truth_path.empty()) {
    truth_path = csv_path;
    const std::string ext = ".csv";
    if (truth_path.size() > ext.size() &&
        truth_path.compare(truth_path.size() - ext.size(), ext.size(), ext) == 0) {
      truth_path.resize(truth_path.size() - ext.size());
    }
    truth_path += ".truth.json";
  }
  {
    namespace fs = std::filesystem;
    CheckOutputFileTarget(csv_path, "--trace");
    CheckOutputFileTarget(truth_path, "--truth");
    RefuseToReplace(csv_path, "simulate --trace", force);
    RefuseToReplace(truth_path, "simulate --truth", force);
    // The same file under two spellings: compare normalised absolute paths (symlinks resolved
    // where they exist), then, when both exist, the files themselves (hard links).
    std::error_code ec;
    auto normal = [&ec](const std::string& p) {
      return fs::weakly_canonical(fs::absolute(p, ec), ec).lexically_normal();
    };
    const bool same = normal(csv_path) == normal(truth_path) ||
                      (fs::exists(csv_path, ec) && fs::exists(truth_path, ec) &&
                       fs::equivalent(csv_path, truth_path, ec));
    if (same) {
      throw UserError("--truth " + truth_path + " and --trace " + csv_path +
                      " are the same file; give the truth JSON another name (default: the CSV "
                      "name with .truth.json)");
    }
  }
  CampaignTrace ct;
  ct.relative_path = std::filesystem::path(csv_path).filename().string();
  ct.nominal_pitch_deg = ct.true_pitch_deg = r.pitch_deg;
  ct.trial = 1;
  TraceSetup& s = ct.setup;
  s.geometry.filar_length_m = length;
  s.geometry.filar_separation_m = separation;
  s.geometry.mass_kg = mass;
  s.geometry.gravity_mps2 = r.gravity_mps2;
  s.params.inertia_kg_m2 = inertia;
  s.params.drag_coeff_kg_m2 = r.drag_coeff_kg_m2;
  s.params.viscous_coeff_kg_m2_per_s = r.viscous_coeff_kg_m2_per_s;
  s.pitch_rad = r.pitch_deg * kRadPerDeg;
  s.amplitude_rad = r.amplitude_deg * kRadPerDeg;
  s.imu_offset_in_body_m = r.imu_offset_m;
  s.body_from_imu = MountingFromRollPitchYawDeg(
      r.imu_mounting_rpy_deg[0], r.imu_mounting_rpy_deg[1], r.imu_mounting_rpy_deg[2]);
  ct.inertia_aircraft_kg_m2 = 0.0;
  ct.inertia_rig_kg_m2 = 0.0;
  std::string why;
  if (!SimulateTrace(s, spec.options, spec.seed, &ct.trace, &why)) {
    throw UserError("simulate: " + why);
  }
  WriteTrace(csv_path, ct.trace, spec);
  WriteFileAtomically(truth_path, TraceTruthJson(spec, ct, csv_path));
  SimulateRunSummary summary;
  summary.files_written = 1;
  summary.samples_written = static_cast<long>(ct.trace.imu.size());
  summary.samples_dropped = ct.trace.truth.samples_dropped;
  summary.truth_path = truth_path;
  return summary;
}

}  // namespace bifilar
