// `bifilar simulate`: realistic IMU logs with known truth (pipeline/commands/simulate_spec.h).
//   campaign:     bifilar simulate SPEC.yaml --out DIR [--seed N]
//   single trace: bifilar simulate --trace OUT.csv --inertia-kg-m2 I --mass-kg M -L L -D D
//                 [--amplitude-deg A] [--pitch-deg P] [--duration-s T] [--model M] [--seed N]
//                 [SPEC.yaml for sensor/timeline/format settings and defaults]
//   either: [--force] to overwrite files that exist (refused otherwise, naming the file). Every
//   log is marked as simulated, with its seed (pipeline/logs/simulated_log.h).
#include <iostream>
#include <limits>
#include <optional>

#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/simulate_spec.h"

namespace bifilar {
namespace {

struct SimulateArgs {
  std::string spec_file, out_dir, trace_csv, truth_json, model;
  SimulateOverrides o;  // --seed, --inertia-kg-m2, ..., --duration-s, --no-accel
  std::optional<double> sample_rate;
  bool force = false;  // replace files that exist (issue 23: never without being told)
};

// CLI11 2.1 binds plain values; an option given on the command line fills the std::optional.
struct RawArgs {
  std::string seed;
  double inertia = 0, mass = 0, length = 0, separation = 0, gravity = 0, amplitude = 0, pitch = 0,
         duration = 0, sample_rate = 0;
  CLI::Option *o_seed = nullptr, *o_inertia = nullptr, *o_mass = nullptr, *o_length = nullptr,
              *o_separation = nullptr, *o_gravity = nullptr, *o_amplitude = nullptr,
              *o_pitch = nullptr, *o_duration = nullptr, *o_sample_rate = nullptr;
};

template <typename T>
std::optional<T> Given(const CLI::Option* option, T value) {
  return option->count() > 0 ? std::optional<T>(value) : std::nullopt;
}

void Run(const SimulateArgs& a, int* exit_code) {
  const SimulateOverrides& o = a.o;
  auto positive = [](const std::optional<double>& v, const char* flag) {
    if (v && !(*v > 0)) {
      throw UserError(std::string(flag) + " = " + std::to_string(*v) + " is out of range; allowed > 0");
    }
  };
  positive(o.duration_s, "--duration-s");
  positive(a.sample_rate, "--sample-rate-hz");
  positive(o.inertia_kg_m2, "--inertia-kg-m2");
  positive(o.mass_kg, "--mass-kg");
  positive(o.length_m, "-L/--filar-length-m");
  positive(o.separation_m, "-D/--filar-separation-m");
  positive(o.gravity_mps2, "--gravity-mps2");
  SimulateSpec spec = a.spec_file.empty() ? ParseSimulateSpec("{}", "<defaults>")
                                          : ReadSimulateSpec(a.spec_file);
  if (a.spec_file.empty()) spec.file.clear();
  if (!a.model.empty() && !ParsePendulumModel(a.model, &spec.options.model)) {
    throw UserError("--model: unknown model '" + a.model + "'; allowed full, jardin, linear");
  }
  if (a.sample_rate) SetSampleRateFromFlag(&spec, *a.sample_rate);
  if (!a.trace_csv.empty()) {
    if (!a.out_dir.empty()) throw UserError("give either --trace FILE.csv or --out DIR, not both");
    if (spec.has_campaign) {
      throw UserError(a.spec_file + ": has campaign sections (aircraft, rig, campaign); simulate "
                      "it with --out DIR, or use a spec without them with --trace");
    }
    ApplySimulateOverrides(o, true, &spec);
    std::string why;
    if (!spec.options.Check(&why)) throw UserError(why);
    const SimulateRunSummary summary = RunSimulateTrace(spec, a.trace_csv, a.truth_json, a.force);
    std::cout << "wrote " << a.trace_csv << ": " << summary.BriefReport() << "\n";
    *exit_code = 0;
    return;
  }
  if (a.out_dir.empty()) {
    throw UserError("nothing to do: give SPEC.yaml --out DIR (campaign) or --trace FILE.csv "
                    "(one trace); see bifilar simulate --help");
  }
  if (a.spec_file.empty()) throw UserError("--out DIR needs a campaign spec file SPEC.yaml");
  if (o.inertia_kg_m2 || o.mass_kg || o.amplitude_deg || o.pitch_deg || !a.truth_json.empty()) {
    throw UserError("--inertia-kg-m2, --mass-kg, --amplitude-deg, --pitch-deg and --truth apply to "
                    "--trace only; a campaign takes them from the spec");
  }
  ApplySimulateOverrides(o, false, &spec);
  std::string why;
  if (!spec.campaign.Check(&why) || !spec.options.Check(&why)) throw UserError(why);
  const SimulateRunSummary summary = RunSimulateCampaign(spec, a.out_dir, a.force);
  std::cout << "wrote " << a.out_dir << ": " << summary.BriefReport() << "\n";
  *exit_code = 0;
}

}  // namespace

void RegisterSimulateCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<SimulateArgs>();
  auto raw = std::make_shared<RawArgs>();
  auto* sub = app.add_subcommand(
      "simulate",
      "Write realistic IMU logs (CSV, or PX4 ULog with `ulog: true` in the spec or a --trace "
      "name ending in .ulg) plus a JSON truth file: a campaign from a spec (SPEC.yaml --out DIR) "
      "or one trace (--trace OUT.csv|OUT.ulg --inertia-kg-m2 --mass-kg -L -D)");
  sub->add_option("spec", args->spec_file, "simulation spec (YAML); see configs/simulate_prandtl_d.yaml")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", args->out_dir, "campaign output folder (pitch_*/trial_*.csv, tare/, truth.json)");
  sub->add_option("--trace", args->trace_csv, "simulate one trace into this file: CSV, or PX4 ULog when it ends in .ulg");
  sub->add_option("--truth", args->truth_json, "truth JSON of --trace (default OUT.truth.json)");
  raw->o_seed = sub->add_option("--seed", raw->seed,
                                "random seed, an integer in [0, 2^64 - 1] (overrides the spec's "
                                "`seed`; default 1)");
  raw->o_inertia = sub->add_option("--inertia-kg-m2", raw->inertia, "--trace: whole suspended inertia I (kg m^2)");
  raw->o_mass = sub->add_option("--mass-kg", raw->mass, "--trace: whole suspended mass m (kg)");
  raw->o_length = sub->add_option("-L,--filar-length-m", raw->length, "filar (wire) length L (m), > D");
  raw->o_separation = sub->add_option("-D,--filar-separation-m", raw->separation, "filar separation D (m), > 0");
  raw->o_gravity = sub->add_option("--gravity-mps2", raw->gravity, "local gravity (m/s^2), default 9.80665");
  raw->o_amplitude = sub->add_option("--amplitude-deg", raw->amplitude, "--trace: psi at release (deg), default 20");
  raw->o_pitch = sub->add_option("--pitch-deg", raw->pitch, "--trace: true pitch of the body (deg), default 0");
  raw->o_duration = sub->add_option("--duration-s", raw->duration, "free-oscillation duration (s)");
  raw->o_sample_rate = sub->add_option("--sample-rate-hz", raw->sample_rate, "IMU sample rate (Hz), default 100");
  for (CLI::Option* option : {raw->o_inertia, raw->o_mass, raw->o_length, raw->o_separation,
                              raw->o_gravity, raw->o_amplitude, raw->o_pitch, raw->o_duration,
                              raw->o_sample_rate}) {
    option->check(FiniteNumber());
  }
  sub->add_option("--model", args->model, "truth model: full (default), jardin, linear");
  sub->add_flag("--no-accel", args->o.no_accel, "write no accelerometer columns");
  sub->add_flag("--force", args->force,
                "overwrite files that exist (--trace, --truth, or the logs and truth.json of "
                "--out); without it simulate refuses, naming the file");
  sub->callback([args, raw, exit_code] {
    SimulateArgs& a = *args;
    if (raw->o_seed->count() > 0) {
      a.o.seed = ParseSeed(raw->seed, "--seed", std::numeric_limits<uint64_t>::max());
    }
    a.o.inertia_kg_m2 = Given(raw->o_inertia, raw->inertia);
    a.o.mass_kg = Given(raw->o_mass, raw->mass);
    a.o.length_m = Given(raw->o_length, raw->length);
    a.o.separation_m = Given(raw->o_separation, raw->separation);
    a.o.gravity_mps2 = Given(raw->o_gravity, raw->gravity);
    a.o.amplitude_deg = Given(raw->o_amplitude, raw->amplitude);
    a.o.pitch_deg = Given(raw->o_pitch, raw->pitch);
    a.o.duration_s = Given(raw->o_duration, raw->duration);
    a.sample_rate = Given(raw->o_sample_rate, raw->sample_rate);
    Run(a, exit_code);
  });
}

}  // namespace bifilar
