// `bifilar plan --rig`: the options of the rig plan on the `plan` subcommand (registered by
// RegisterEllipseCommands), parsed into RigPlanOptions and run by RunRigPlan
// (pipeline/commands/rig_plan.h). Printing and the files written live here.
#include <filesystem>
#include <iostream>
#include <system_error>

#include "base/atomic_file.h"
#include "base/text_format.h"
#include "base/units.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/rig_plan.h"

namespace bifilar {

struct RigPlanCli {
  bool rig = false;
  RigPlanOptions o;
  std::string plot, write_config;
  bool force = false;                  // --force: replace an existing file (never a link)
  std::vector<CLI::Option*> rig_only;  // options that mean nothing without --rig
};

std::shared_ptr<RigPlanCli> AddRigPlanOptions(CLI::App* plan) {
  auto r = std::make_shared<RigPlanCli>();
  RigPlanOptions& o = r->o;
  plan->add_flag("--rig", r->rig,
                 "design the rig: choose wire length L, separation D, release amplitude, swing "
                 "length and repeats for a target total std of I (needs --mass --inertia "
                 "--max-length --max-separation --target-percent)");
  const auto only = [&](CLI::Option* opt) {
    opt->check(FiniteNumber());
    r->rig_only.push_back(opt);
  };
  only(plan->add_option("--mass", o.mass_kg, "with --rig: the aircraft's mass, kg"));
  only(plan->add_option("--cradle-mass", o.cradle_mass_kg,
                        "with --rig: cradle + IMU mass, kg (default 0: a thread rig)"));
  only(plan->add_option("--inertia", o.inertia_kg_m2,
                        "with --rig: the expected inertia of all that swings, kg m^2 (the low "
                        "end with --inertia-max)"));
  only(plan->add_option("--radius-of-gyration", o.radius_of_gyration_m,
                        "with --rig: instead of --inertia, the radius of gyration r, m: I = "
                        "(mass + cradle) r^2"));
  only(plan->add_option("--inertia-max", o.inertia_max_kg_m2,
                        "with --rig: upper end of the expected inertia, kg m^2"));
  only(plan->add_option("--max-length", o.max_length_m, "with --rig: the longest L, m"));
  only(plan->add_option("--max-separation", o.max_separation_m, "with --rig: the widest D, m"));
  only(plan->add_option("--min-length", o.min_length_m, "with --rig: the shortest L, m (0.1)"));
  only(plan->add_option("--min-separation", o.min_separation_m,
                        "with --rig: the narrowest D, m (0.01)"));
  only(plan->add_option("--min-period", o.min_period_s, "with --rig: shortest period, s (0.5)"));
  only(plan->add_option("--max-period", o.max_period_s, "with --rig: longest period, s (6)"));
  only(plan->add_option("--length-std", o.length_std_m, "with --rig: 1-sigma of L, m (0.001)"));
  only(plan->add_option("--separation-std", o.separation_std_m,
                        "with --rig: 1-sigma of D, m (0.001)"));
  only(plan->add_option("--mass-std", o.mass_std_kg,
                        "with --rig: 1-sigma of the suspended mass, kg (0.1 % of it)"));
  only(plan->add_option("--gravity", o.gravity_mps2,
                        Fmt("with --rig: local g, m/s^2 (%g)", kStandardGravityMps2)));
  only(plan->add_option("--gravity-std", o.gravity_std_mps2, "with --rig: 1-sigma of g (0)"));
  only(plan->add_option("--imu-rate", o.imu_rate_hz, "with --rig: IMU sample rate, Hz (100)"));
  only(plan->add_option("--gyro-noise", o.gyro_noise_deg_per_s,
                        "with --rig: gyro noise per sample, deg/s (0.25)"));
  only(plan->add_option("--repeat-scatter", o.repeat_scatter_percent,
                        "with --rig: scatter between repeats of one set-up, % (0.25)"));
  only(plan->add_option("--rig-departure", o.rig_departure_percent,
                        "with --rig: how far a real rig departs from the model at 30 deg, % of "
                        "I (3)"));
  only(plan->add_option("--target-percent", o.target_percent,
                        "with --rig: the target total std of I, %"));
  auto* plot = plan->add_option("--plot", r->plot,
                                "with --rig: write the figure of the total std over (D, L) "
                                "(.png or .svg)");
  auto* config = plan->add_option("--write-config", r->write_config,
                                  "with --rig: write a starting config (bifilar init's format)");
  auto* force = plan->add_flag("--force", r->force,
                               "with --rig: replace an existing --write-config or --plot file "
                               "(never a symbolic link)");
  auto* mc = plan->add_option("--monte-carlo", o.monte_carlo_swings,
                              "with --rig: check the prediction on N simulated swings")
                 ->group("");  // hidden: a check, not a design input
  r->rig_only.insert(r->rig_only.end(), {plot, config, force, mc});
  return r;
}

bool RigPlanRequested(const RigPlanCli& r) {
  if (r.rig) return true;
  for (const CLI::Option* opt : r.rig_only) {
    if (opt->count() > 0) {
      throw UserError("plan: " + opt->get_name() + " belongs to the rig plan: add --rig");
    }
  }
  return false;
}

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The same file under two spellings: normalised absolute paths, links in the folders resolved.
bool SamePath(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path pa = fs::weakly_canonical(fs::absolute(a), ec);
  const fs::path pb = fs::weakly_canonical(fs::absolute(b), ec);
  return ec ? fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal() : pa == pb;
}

// Before the plan runs: the files it will write are named (not empty), do not replace a file
// without --force nor a link ever (base/atomic_file.h), are not one file twice, and the figure's
// folder exists or is made (as --write-config's is), so PLplot never meets a path it cannot open.
void CheckRigPlanOutputs(const RigPlanCli& r, bool config, bool plot) {
  if (config) RefuseToReplace(r.write_config, "plan --rig --write-config", r.force);
  if (plot) {
    RefuseToReplace(r.plot, "plan --rig --plot", r.force);
    if (!EndsWith(r.plot, ".png") && !EndsWith(r.plot, ".svg")) {
      throw UserError("plan --rig --plot " + r.plot +
                      ": the figure's name must end in .png or .svg");
    }
  }
  if (config && plot && SamePath(r.write_config, r.plot)) {
    throw UserError("plan --rig: --write-config and --plot name the same file (" + r.plot +
                    "); give each its own");
  }
  if (plot) {
    const std::filesystem::path folder = std::filesystem::path(r.plot).parent_path();
    std::error_code ec;
    if (!folder.empty()) std::filesystem::create_directories(folder, ec);
    if (!folder.empty() && !std::filesystem::is_directory(folder)) {
      throw UserError("plan --rig --plot " + r.plot + ": cannot create the folder " +
                      folder.string() + (ec ? " (" + ec.message() + ")" : ""));
    }
  }
}

}  // namespace

int RunRigPlanCli(const RigPlanCli& r, const CLI::App& plan, bool json) {
  for (const char* name : {"--mass", "--max-length", "--max-separation", "--target-percent"}) {
    if (plan.count(name) == 0) throw UserError(std::string("plan --rig: ") + name + " is required");
  }
  for (const char* name : {"--angles", "--sigma", "--tensor"}) {
    if (plan.count(name) > 0) {
      throw UserError(std::string("plan --rig: ") + name + " belongs to another plan");
    }
  }
  const bool config = plan.count("--write-config") > 0, plot = plan.count("--plot") > 0;
  CheckRigPlanOutputs(r, config, plot);
  const RigPlan p = RunRigPlan(r.o);
  std::cout << (json ? RigPlanJson(p) : RigPlanText(p));
  if (config) {
    WriteFileAtomically(r.write_config, RigPlanConfigText(p, r.write_config));
    if (!json) std::cout << "  wrote " << r.write_config << "\n";
  }
  if (plot) {
    std::string why;
    if (!WriteRigPlanPlot(p, r.plot, &why)) throw UserError("plan --rig: --plot: " + why);
    if (!json) std::cout << "  wrote " << r.plot << "\n";
  }
  return RigPlanExitCode(p);
}

}  // namespace bifilar
