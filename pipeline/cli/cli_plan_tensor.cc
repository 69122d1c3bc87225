// `bifilar plan --tensor`: the options of the tensor plan on the `plan` subcommand (registered by
// RegisterEllipseCommands), parsed into TensorPlanCommandOptions and run by RunTensorPlan
// (pipeline/commands/tensor_plan_command.h).

#include <cmath>
#include <iostream>
#include <sstream>

#include "base/csv.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/tensor_plan_command.h"

namespace bifilar {
namespace {

double ParseDeg(const std::string& text, const std::string& option, const std::string& whole) {
  double v = 0;
  if (!ParseNumber(text, &v)) {  // base/csv.h: the whole text, finite
    throw UserError(option + " '" + whole + "': '" + text + "' is not a number");
  }
  return v;
}

// "MIN:MAX" or one value (the angle held fixed), deg.
void ParseRange(const std::string& text, const std::string& option, double* lo, double* hi) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos) {
    *lo = *hi = ParseDeg(text, option, text);
  } else {
    *lo = ParseDeg(text.substr(0, colon), option, text);
    *hi = ParseDeg(text.substr(colon + 1), option, text);
  }
  if (*lo > *hi) throw UserError(option + " '" + text + "': MIN must not exceed MAX");
}

}  // namespace

struct TensorPlanCli {
  bool tensor = false;
  std::string roll = "0", pitch = "-90:90";
  double grid_step_deg = 5.0;
  int orientations = 12;
  double sigma_rel = 0.0, attitude_std_deg = 0.0, target = 0.0, target_rel = 0.0;
  double ixx = NAN, iyy = NAN, izz = NAN, ixy = 0.0, iyz = 0.0;
  std::vector<CLI::Option*> tensor_only;  // options that mean nothing without --tensor
};

std::shared_ptr<TensorPlanCli> AddTensorPlanOptions(CLI::App* plan) {
  auto t = std::make_shared<TensorPlanCli>();
  plan->add_flag("--tensor", t->tensor,
                 "plan the full inertia tensor: choose the attitudes (roll, pitch) to swing within "
                 "the rig's range and predict the std of Ixx, Iyy, Izz, Ixy, Ixz, Iyz");
  const auto only = [&](CLI::Option* o) { t->tensor_only.push_back(o); };
  only(plan->add_option("--roll", t->roll,
                        "with --tensor: the rig's reachable roll (right wing down), deg: MIN:MAX "
                        "or one value held fixed (default 0; use '=' when it starts with '-')"));
  only(plan->add_option("--pitch", t->pitch,
                        "with --tensor: the rig's reachable pitch (nose up), deg, within -90..90: "
                        "MIN:MAX or one value (default -90:90)"));
  only(plan->add_option("--grid-step", t->grid_step_deg,
                        "with --tensor: spacing of the candidate attitudes, deg (default 5)")
           ->check(CLI::Range(0.5, 90.0)));
  only(plan->add_option("--orientations", t->orientations,
                        "with --tensor: how many attitudes to choose, 6..12 (default 12)")
           ->check(CLI::Range(6, 12)));
  only(plan->add_option("--sigma-rel", t->sigma_rel,
                        "with --tensor: per-swing std as a fraction of the moment (e.g. 0.002), "
                        "in quadrature with --sigma; needs --ixx --iyy --izz"));
  only(plan->add_option("--attitude-std", t->attitude_std_deg,
                        "with --tensor: std of each attitude as set, deg per tilt axis, shared by "
                        "its trials (default 0); needs --ixx --iyy --izz"));
  only(plan->add_option("--target", t->target,
                        "with --tensor: target std of every component, in --units: prints the "
                        "trials per orientation needed"));
  only(plan->add_option("--target-rel", t->target_rel,
                        "with --tensor: target std as a fraction of the largest principal moment "
                        "of the guess (e.g. 0.002)"));
  only(plan->add_option("--ixx", t->ixx, "with --tensor: guessed Ixx, in --units"));
  only(plan->add_option("--iyy", t->iyy, "with --tensor: guessed Iyy, in --units"));
  only(plan->add_option("--izz", t->izz, "with --tensor: guessed Izz, in --units"));
  only(plan->add_option("--ixy", t->ixy,
                        "with --tensor: guessed Ixy = integral x y dm, in --units (default 0)"));
  only(plan->add_option("--iyz", t->iyz,
                        "with --tensor: guessed Iyz = integral y z dm, in --units (default 0)"));
  // NaN or inf is refused like every numeric flag (a NaN guess would read as "not given").
  for (const char* name : {"--grid-step", "--sigma-rel", "--attitude-std", "--target",
                           "--target-rel", "--ixx", "--iyy", "--izz", "--ixy", "--iyz"}) {
    plan->get_option(name)->check(FiniteNumber());
  }
  return t;
}

bool TensorPlanRequested(const TensorPlanCli& t) {
  if (t.tensor) return true;
  for (const CLI::Option* o : t.tensor_only) {
    if (o->count() > 0) {
      throw UserError("plan: " + o->get_name() +
                      " belongs to the tensor plan: add --tensor (the pitch-plane plan takes "
                      "--angles, --sigma, --ix, --iz, --ixz)");
    }
  }
  return false;
}

TensorPlanCommandOptions TensorPlanOptionsFromCli(const TensorPlanCli& t, const CLI::App& plan,
                                                  int trials, double sigma, double ixz,
                                                  bool ixz_given, DisplayUnits units, bool json) {
  for (const char* name : {"--angles", "--ix", "--iz"}) {
    if (plan.count(name) > 0) {
      throw UserError(std::string("plan --tensor: ") + name +
                      " belongs to the pitch-plane plan; give the rig's range with --roll and "
                      "--pitch and the guess with --ixx --iyy --izz [--ixy --ixz --iyz]");
    }
  }
  TensorPlanCommandOptions o;
  ParseRange(t.roll, "--roll", &o.plan.roll_min_deg, &o.plan.roll_max_deg);
  ParseRange(t.pitch, "--pitch", &o.plan.pitch_min_deg, &o.plan.pitch_max_deg);
  o.plan.grid_step_deg = t.grid_step_deg;
  o.plan.n_orientations = t.orientations;
  o.plan.trials_per_orientation = trials;
  o.plan.sigma_relative = t.sigma_rel;
  o.plan.attitude_std_deg = t.attitude_std_deg;
  o.sigma = sigma;
  o.target = t.target;
  o.target_relative = t.target_rel;
  const int moments_given = !std::isnan(t.ixx) + !std::isnan(t.iyy) + !std::isnan(t.izz);
  if (moments_given != 0 && moments_given != 3) {
    throw UserError("plan --tensor: give all of --ixx, --iyy, --izz, or none");
  }
  o.guess_given = moments_given == 3;
  if (!o.guess_given && (ixz_given || plan.count("--ixy") > 0 || plan.count("--iyz") > 0)) {
    throw UserError(
        "plan --tensor: a guessed product (--ixy, --ixz, --iyz) needs --ixx, --iyy, "
        "--izz too");
  }
  o.guess = {o.guess_given ? t.ixx : 0.0,
             o.guess_given ? t.iyy : 0.0,
             o.guess_given ? t.izz : 0.0,
             t.ixy,
             ixz,
             t.iyz};
  o.units = units;
  o.json = json;
  return o;
}

}  // namespace bifilar
