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

#include "base/text_format.h"
#include "base/units.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/simulate_spec.h"

namespace bifilar {
namespace {

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

}  // namespace

void RegisterSimulateCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<SimulateCommandOptions>();
  auto raw = std::make_shared<RawArgs>();
  auto* sub = app.add_subcommand(
      "simulate",
      "Write realistic IMU logs (CSV, or PX4 ULog with `ulog: true` in the spec or a --trace "
      "name ending in .ulg) plus a JSON truth file: a campaign from a spec (SPEC.yaml --out DIR) "
      "or one trace (--trace OUT.csv|OUT.ulg --inertia-kg-m2 --mass-kg -L -D)");
  sub->add_option("spec", args->spec_file,
                  "simulation spec (YAML); see configs/simulate_prandtl_d.yaml")
      ->check(CLI::ExistingFile);
  sub->add_option("--out", args->out_dir,
                  "campaign output folder (pitch_*/trial_*.csv, tare/, truth.json)");
  sub->add_option("--trace", args->trace_csv,
                  "simulate one trace into this file: CSV, PX4 ULog when it ends in .ulg, "
                  "ArduPilot DataFlash when it ends in .bin");
  sub->add_option("--truth", args->truth_json, "truth JSON of --trace (default OUT.truth.json)");
  raw->o_seed = sub->add_option("--seed", raw->seed,
                                "random seed, an integer in [0, 2^64 - 1] (overrides the spec's "
                                "`seed`; default 1)");
  raw->o_inertia = sub->add_option("--inertia-kg-m2", raw->inertia,
                                   "--trace: whole suspended inertia I (kg m^2)");
  raw->o_mass = sub->add_option("--mass-kg", raw->mass, "--trace: whole suspended mass m (kg)");
  raw->o_length =
      sub->add_option("-L,--filar-length-m", raw->length, "filar (wire) length L (m), > D");
  raw->o_separation =
      sub->add_option("-D,--filar-separation-m", raw->separation, "filar separation D (m), > 0");
  raw->o_gravity = sub->add_option("--gravity-mps2", raw->gravity,
                                   Fmt("local gravity (m/s^2), default %g", kStandardGravityMps2));
  raw->o_amplitude = sub->add_option("--amplitude-deg", raw->amplitude,
                                     "--trace: psi at release (deg), default 20");
  raw->o_pitch = sub->add_option("--pitch-deg", raw->pitch,
                                 "--trace: true pitch of the body (deg), default 0");
  raw->o_duration = sub->add_option("--duration-s", raw->duration, "free-oscillation duration (s)");
  raw->o_sample_rate =
      sub->add_option("--sample-rate-hz", raw->sample_rate, "IMU sample rate (Hz), default 100");
  for (CLI::Option* option :
       {raw->o_inertia, raw->o_mass, raw->o_length, raw->o_separation, raw->o_gravity,
        raw->o_amplitude, raw->o_pitch, raw->o_duration, raw->o_sample_rate}) {
    option->check(FiniteNumber());
  }
  sub->add_option("--model", args->model,
                  "truth model: " + PendulumModelAllowedValues() + " (default " +
                      ToString(SimulationOptions().model) + ")");
  sub->add_flag("--no-accel", args->o.no_accel, "write no accelerometer columns");
  sub->add_flag("--force", args->force,
                "overwrite files that exist (--trace, --truth, or the logs and truth.json of "
                "--out); without it simulate refuses, naming the file");
  sub->callback([args, raw, exit_code] {
    SimulateCommandOptions& a = *args;
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
    const SimulateCommandResult result = RunSimulate(a);
    std::cout << "wrote " << result.written << ": " << result.summary.BriefReport() << "\n";
    *exit_code = 0;
  });
}

}  // namespace bifilar
