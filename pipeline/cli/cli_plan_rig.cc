// `bifilar plan --rig`: the options of the rig plan on the `plan` subcommand (registered by
// RegisterEllipseCommands), parsed into RigPlanOptions and run by RunRigPlan
// (pipeline/commands/rig_plan.h). Printing and the files written live here.
#include <iostream>

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
  auto* mc = plan->add_option("--monte-carlo", o.monte_carlo_swings,
                              "with --rig: check the prediction on N simulated swings")
                 ->group("");  // hidden: a check, not a design input
  r->rig_only.insert(r->rig_only.end(), {plot, config, mc});
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

int RunRigPlanCli(const RigPlanCli& r, const CLI::App& plan, bool json) {
  for (const char* name : {"--mass", "--max-length", "--max-separation", "--target-percent"}) {
    if (plan.count(name) == 0) throw UserError(std::string("plan --rig: ") + name + " is required");
  }
  for (const char* name : {"--angles", "--sigma", "--tensor"}) {
    if (plan.count(name) > 0) {
      throw UserError(std::string("plan --rig: ") + name + " belongs to another plan");
    }
  }
  const RigPlan p = RunRigPlan(r.o);
  std::cout << (json ? RigPlanJson(p) : RigPlanText(p));
  if (!r.write_config.empty()) {
    WriteFileAtomically(r.write_config, RigPlanConfigText(p, r.write_config));
    if (!json) std::cout << "  wrote " << r.write_config << "\n";
  }
  if (!r.plot.empty()) {
    std::string why;
    if (!WriteRigPlanPlot(p, r.plot, &why)) throw UserError("plan --rig: --plot: " + why);
    if (!json) std::cout << "  wrote " << r.plot << "\n";
  }
  return 0;
}

}  // namespace bifilar
