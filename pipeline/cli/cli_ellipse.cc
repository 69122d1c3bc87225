// `bifilar ellipse TABLE.csv` and `bifilar plan`: parse options, call RunEllipse /
// RunPlan (pipeline/commands/ellipse_command.h).
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include "base/csv.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/commands/ellipse_command.h"
#include "pipeline/commands/tensor_plan_command.h"

namespace bifilar {
namespace {

double ParseAngle(const std::string& text, const std::string& list) {
  double v = 0;
  if (!ParseNumber(text, &v)) {  // base/csv.h: the whole text, finite
    throw UserError("--angles '" + list + "': '" + text + "' is not a number");
  }
  return v;
}

// "0,30,60,90" or ranges "first:last:step" (inclusive), mixed: "-80:90:10,45".
std::vector<double> ParseAngleList(const std::string& list) {
  std::vector<double> angles;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::vector<std::string> parts;
    std::istringstream pin(item);
    std::string part;
    while (std::getline(pin, part, ':')) parts.push_back(part);
    if (parts.size() == 1) {
      angles.push_back(ParseAngle(parts[0], list));
    } else if (parts.size() == 3) {
      const double a = ParseAngle(parts[0], list), b = ParseAngle(parts[1], list),
                   s = ParseAngle(parts[2], list);
      if (!(s > 0) || b < a || (b - a) / s > 10000) {
        throw UserError("--angles '" + list + "': range '" + item +
                        "' must be first:last:step with step > 0 and first <= last");
      }
      for (int i = 0; a + i * s <= b + 1e-9 * s; ++i) angles.push_back(a + i * s);
    } else {
      throw UserError("--angles '" + list + "': '" + item +
                      "' is neither a number nor first:last:step");
    }
  }
  if (angles.empty()) throw UserError("--angles is empty");
  return angles;
}

DisplayUnits Units(const std::string& name) {
  DisplayUnits units;
  if (!ParseDisplayUnits(name, &units)) {
    throw UserError("--units must be " + DisplayUnitsAllowedValues() + ", got '" + name + "'");
  }
  return units;
}

}  // namespace

void RegisterEllipseCommands(CLI::App& app, int* exit_code) {
  // ellipse
  auto* ellipse = app.add_subcommand(
      "ellipse",
      "Fit the ellipse of inertia to moments measured at several pitch angles: I_x, I_z, I_xz, "
      "tau with uncertainty (table columns pitch_deg, inertia[, std])");
  auto opts = std::make_shared<EllipseCommandOptions>();
  auto units = std::make_shared<std::string>("si");
  auto covariance = std::make_shared<std::string>("auto");
  ellipse->add_option("table", opts->table_path, "CSV table: pitch_deg, inertia, optional std")
      ->required();
  ellipse->add_option("--units", *units,
                      "units of the table's inertia/std and of the console output: si (kg m^2, "
                      "default) or imperial (slug ft^2); JSON is always SI");
  ellipse->add_flag("--json", opts->json, "print the result as JSON (SI)");
  ellipse
      ->add_option("--plot", opts->plot_dir,
                   "write ellipse_moments and ellipse_polar figures (.png, .svg) here")
      ->check(NonEmptyName());
  ellipse->add_flag("--force", opts->force,
                    "with --plot: replace files of the figures' names that bifilar did not write "
                    "(never a symbolic link)");
  auto seed = std::make_shared<std::string>();
  ellipse->add_option("--seed", *seed, "bootstrap seed, an integer in [0, 2^64 - 1] (default 1)");
  ellipse
      ->add_option("--bootstrap", opts->fit.bootstrap_replicates,
                   "parametric bootstrap replicates for the 95% intervals; 0 = t intervals "
                   "(default 2000)")
      ->check(CLI::Range(0, kMaxBootstrapReplicates));
  ellipse->add_option("--covariance", *covariance,
                      "auto (default), points, angle_means or absolute (trust the std column)");
  ellipse
      ->add_option("--outlier-threshold", opts->fit.outlier_threshold,
                   "flag trials with |studentized residual| above this (default 3)")
      ->check(FiniteNumber());
  ellipse->callback([opts, units, covariance, seed, exit_code] {
    opts->units = Units(*units);
    if (!seed->empty()) {
      opts->fit.seed = ParseSeed(*seed, "--seed", std::numeric_limits<uint64_t>::max());
    }
    if (!ParseEllipseCovariance(*covariance, &opts->fit.covariance)) {
      throw UserError("--covariance must be " + EllipseCovarianceAllowedValues() + ", got '" +
                      *covariance + "'");
    }
    const EllipseCommandResult result = RunEllipse(*opts);
    PrintEllipseCommand(*opts, result, std::cout);
    *exit_code = EllipseExitCode(result);
  });

  // plan
  auto* plan = app.add_subcommand(
      "plan",
      "Predict the standard errors of I_xz and tau for a proposed set of pitch angles, before "
      "building a rig; with --tensor, choose the attitudes for the full inertia tensor");
  auto plan_opts = std::make_shared<PlanCommandOptions>();
  auto angles = std::make_shared<std::string>();
  auto plan_units = std::make_shared<std::string>("si");
  auto ix = std::make_shared<double>(NAN), iz = std::make_shared<double>(NAN),
       ixz = std::make_shared<double>(0.0);
  plan->add_option("--angles", *angles,
                   "pitch angles in deg: a list and/or ranges first:last:step, e.g. "
                   "--angles=-80:90:10 (use '=' when the list starts with '-'); required "
                   "without --tensor");
  plan->add_option("--trials", plan_opts->trials_per_angle, "trials per angle (default 3)")
      ->check(CLI::Range(1, 1000000));
  plan->add_option("--sigma", plan_opts->sigma,
                   "per-trial standard deviation of a moment, in --units (required without "
                   "--tensor)")
      ->check(FiniteNumber());
  plan->add_option("--ix", *ix, "guess of I_x in --units (default: the paper's PRANDTL-D)")
      ->check(FiniteNumber());
  plan->add_option("--iz", *iz, "guess of I_z in --units (default: the paper's PRANDTL-D)")
      ->check(FiniteNumber());
  auto* ixz_option =
      plan->add_option("--ixz", *ixz, "guess of I_xz in --units (default 0 when --ix/--iz given)")
          ->check(FiniteNumber());
  plan->add_option("--units", *plan_units, "si (kg m^2, default) or imperial (slug ft^2)");
  plan->add_flag("--json", plan_opts->json, "print JSON (SI)");
  // `plan --tensor`: pipeline/cli/cli_plan_tensor.cc
  auto tensor_plan = AddTensorPlanOptions(plan);
  auto rig_plan = AddRigPlanOptions(plan);  // `plan --rig`: pipeline/cli/cli_plan_rig.cc
  plan->callback([plan, plan_opts, angles, plan_units, ix, iz, ixz, ixz_option, tensor_plan,
                  rig_plan, exit_code] {
    plan_opts->units = Units(*plan_units);
    if (RigPlanRequested(*rig_plan)) {
      *exit_code = RunRigPlanCli(*rig_plan, *plan, plan_opts->json);
      return;
    }
    if (TensorPlanRequested(*tensor_plan)) {
      const TensorPlanCommandOptions tensor_opts = TensorPlanOptionsFromCli(
          *tensor_plan, *plan, plan_opts->trials_per_angle, plan_opts->sigma, *ixz,
          ixz_option->count() > 0, plan_opts->units, plan_opts->json);
      PrintTensorPlan(RunTensorPlan(tensor_opts), tensor_opts.units, tensor_opts.json, std::cout);
      return;
    }
    if (angles->empty()) throw UserError("plan: --angles is required (or --tensor)");
    if (plan->count("--sigma") == 0) throw UserError("plan: --sigma is required");
    plan_opts->pitch_deg = ParseAngleList(*angles);
    if (std::isnan(*ix) != std::isnan(*iz)) {
      throw UserError("plan: give both --ix and --iz, or neither (the paper's aircraft)");
    }
    plan_opts->guesses_given = !std::isnan(*ix);
    if (!plan_opts->guesses_given && ixz_option->count() > 0) {
      throw UserError("plan: --ixz needs --ix and --iz too");
    }
    plan_opts->ix = *ix;
    plan_opts->iz = *iz;
    plan_opts->ixz = *ixz;
    PrintPlan(*plan_opts, RunPlan(*plan_opts), std::cout);
  });
}

}  // namespace bifilar
