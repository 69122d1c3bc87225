#include "pipeline/commands/tensor_plan_command.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "base/json_number.h"
#include "base/option_check.h"
#include "base/text_format.h"
#include "base/user_error.h"
#include "fit/tensor.h"

namespace bifilar {
namespace {

using nlohmann::json;

// The flag that sets a TensorPlanOptions field, for its messages ("" when no flag sets it).
std::string FlagOfPlanField(const std::string& field) {
  static const std::pair<const char*, const char*> kFlags[] = {
      {"roll_min_deg", "--roll"},
      {"roll_max_deg", "--roll"},
      {"pitch_min_deg", "--pitch"},
      {"pitch_max_deg", "--pitch"},
      {"grid_step_deg", "--grid-step"},
      {"n_orientations", "--orientations"},
      {"sigma_kg_m2", "--sigma"},
      {"sigma_relative", "--sigma-rel"},
      {"attitude_std_deg", "--attitude-std"},
      {"target_std_kg_m2", "--target"}};
  for (const auto& [name, flag] : kFlags) {
    if (field.rfind(name, 0) == 0) return flag;  // also "target_std_kg_m2 (0: none)"
  }
  // "guess_kg_m2 Ixx", "smallest principal moment of guess_kg_m2"
  if (field.find("guess_kg_m2") != std::string::npos) return "--ixx ... --iyz";
  return "";
}

// No "-0.000" in a table.
double Clean(double v) { return std::fabs(v) < 5e-7 ? 0.0 : v; }

// The largest principal moment of the guessed tensor (kg m^2).
double LargestPrincipal(const std::array<double, kTensorComponents>& c) {
  Eigen::Matrix3d j;
  j << c[0], -c[3], -c[4], -c[3], c[1], -c[5], -c[4], -c[5], c[2];
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(j).eigenvalues()[2];
}

}  // namespace

json TensorPlanToJson(const TensorPlan& p, const TensorPlanOptions& o) {
  json j;
  j["rig"] = {{"roll_min_deg", o.roll_min_deg},
              {"roll_max_deg", o.roll_max_deg},
              {"pitch_min_deg", o.pitch_min_deg},
              {"pitch_max_deg", o.pitch_max_deg},
              {"grid_step_deg", o.grid_step_deg}};
  j["trials_per_orientation"] = o.trials_per_orientation;
  j["sigma_kg_m2"] = o.sigma_kg_m2;
  j["sigma_relative"] = o.sigma_relative;
  j["attitude_std_deg"] = o.attitude_std_deg;
  if (o.guess_given) {
    json g;
    for (int k = 0; k < kTensorComponents; ++k) {
      g[std::string(TensorComponentName(k)) + "_kg_m2"] = o.guess_kg_m2[k];
    }
    j["guess"] = g;
  } else {
    j["guess"] = nullptr;
  }
  j["target_std_kg_m2"] = o.target_std_kg_m2 > 0 ? json(o.target_std_kg_m2) : json(nullptr);
  j["n_candidates"] = p.n_candidates;
  j["n_points"] = p.n_points;
  j["rank"] = p.rank;
  j["condition_number"] = JsonNumber(p.condition_number);
  j["log_det_information"] = JsonNumber(p.log_det_information);
  j["exchange_sweeps"] = p.exchange_sweeps;
  json orientations = json::array();
  for (const TensorPlanOrientation& x : p.orientations) {
    orientations.push_back({{"roll_deg", x.roll_deg},
                            {"pitch_deg", x.pitch_deg},
                            {"axis_in_body", x.axis_in_body},
                            {"inertia_kg_m2", JsonNumber(x.inertia_kg_m2)},
                            {"swing_std_kg_m2", JsonNumber(x.swing_std_kg_m2)},
                            {"mean_std_kg_m2", JsonNumber(x.mean_std_kg_m2)}});
  }
  j["orientations"] = orientations;
  json components;
  for (int k = 0; k < kTensorComponents; ++k) {
    const bool obs = p.observable[k];
    components[TensorComponentName(k)] = {
        {"observable", obs},
        {"std_kg_m2", obs ? JsonNumber(p.std_kg_m2[k]) : json(nullptr)},
        {"floor_std_kg_m2", obs ? JsonNumber(p.floor_std_kg_m2[k]) : json(nullptr)},
        {"trials_needed", obs && o.target_std_kg_m2 > 0 && p.trials_needed[k] > 0
                              ? json(p.trials_needed[k])
                              : json(nullptr)}};
  }
  j["components"] = components;
  j["unobservable"] = p.unobservable;
  j["n_combinations"] = p.n_combinations;
  j["trials_needed_all"] =
      o.target_std_kg_m2 > 0 && p.trials_needed_all > 0 ? json(p.trials_needed_all) : json(nullptr);
  j["target_reachable"] = o.target_std_kg_m2 > 0 ? json(p.trials_needed_all > 0) : json(nullptr);
  j["warnings"] = p.warnings;
  j["note"] =
      "stds assume independent swing noise and, when attitude_std_deg > 0, an attitude error "
      "per orientation shared by its trials; other errors shared by orientations (rig tare, "
      "calibration) add to them";
  return j;
}

TensorPlanCommandResult RunTensorPlan(const TensorPlanCommandOptions& options) {
  const double to_si = InertiaToSi(options.units);
  TensorPlanOptions o = options.plan;
  o.sigma_kg_m2 = options.sigma * to_si;
  o.guess_given = options.guess_given;
  for (int k = 0; k < kTensorComponents; ++k) o.guess_kg_m2[k] = options.guess[k] * to_si;
  if (options.target > 0 && options.target_relative > 0) {
    throw UserError("plan --tensor: give --target or --target-rel, not both");
  }
  if (!(options.target >= 0) || !(options.target_relative >= 0) || !std::isfinite(options.target) ||
      !std::isfinite(options.target_relative)) {
    throw UserError("plan --tensor: --target and --target-rel must be > 0");
  }
  o.target_std_kg_m2 = options.target * to_si;
  if ((o.sigma_relative > 0 || o.attitude_std_deg > 0) && !options.guess_given) {
    throw UserError(
        "plan --tensor: --sigma-rel and --attitude-std need a guess of the tensor: "
        "give --ixx, --iyy, --izz (and --ixy, --ixz, --iyz when known)");
  }
  CheckFailure failure;
  if (!o.Check(&failure)) {
    const std::string flag = FlagOfPlanField(failure.field);
    throw UserError("plan --tensor: " + (flag.empty() ? "" : flag + ": ") + failure.Message());
  }
  if (options.target_relative > 0) {
    if (!options.guess_given) {
      throw UserError(
          "plan --tensor: --target-rel is a fraction of the largest principal moment "
          "of the guess: give --ixx, --iyy, --izz");
    }
    o.target_std_kg_m2 = options.target_relative * LargestPrincipal(o.guess_kg_m2);
  }
  TensorPlanCommandResult result;
  std::string why;
  if (!PlanTensor(o, &result.plan, &why)) throw UserError("plan --tensor: " + why);
  result.options = o;
  return result;
}

void PrintTensorPlan(const TensorPlanCommandResult& result, DisplayUnits units, bool json,
                     std::ostream& out) {
  const TensorPlan& plan = result.plan;
  const TensorPlanOptions& o = result.options;
  if (json) {
    out << TensorPlanToJson(plan, o).dump(2, ' ', false, json::error_handler_t::replace) << "\n";
    return;
  }
  const double k = 1.0 / InertiaToSi(units);
  const std::string u = InertiaUnitName(units);
  out << "Tensor plan: " << plan.orientations.size() << " orientation(s) x "
      << o.trials_per_orientation << " trial(s) = " << plan.n_points << " swings, chosen "
      << "D-optimally from " << plan.n_candidates << " distinct reachable swing axes (roll "
      << Fmt("%g", o.roll_min_deg) << ".." << Fmt("%g", o.roll_max_deg) << " deg, pitch "
      << Fmt("%g", o.pitch_min_deg) << ".." << Fmt("%g", o.pitch_max_deg) << " deg, "
      << Fmt("%g", o.grid_step_deg) << " deg grid)\n";
  out << "Per-swing std: ";
  if (o.sigma_kg_m2 > 0) out << Fmt("%.4g ", o.sigma_kg_m2 * k) << u;
  if (o.sigma_kg_m2 > 0 && o.sigma_relative > 0) out << " (+) ";
  if (o.sigma_relative > 0) out << Fmt("%.4g %%", 100 * o.sigma_relative) << " of the moment";
  if (o.attitude_std_deg > 0) {
    out << "; attitude error " << Fmt("%.3g deg", o.attitude_std_deg)
        << " per tilt axis, shared by an orientation's trials";
  }
  out << "\n";
  if (o.guess_given) {
    out << "Assumed tensor (" << u << "): ";
    for (int c = 0; c < kTensorComponents; ++c) {
      out << (c ? ", " : "") << TensorComponentName(c) << " " << Fmt("%.5g", o.guess_kg_m2[c] * k);
    }
    out << "\n";
  }
  out << "\nSwing the aircraft at these attitudes (roll right-wing-down, pitch nose-up):\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %3s %9s %9s   %-26s %s\n", "#", "roll_deg", "pitch_deg",
                "swing axis in body (x,y,z)", ("std of mean [" + u + "]").c_str());
  out << line;
  for (size_t i = 0; i < plan.orientations.size(); ++i) {
    const TensorPlanOrientation& x = plan.orientations[i];
    std::snprintf(line, sizeof line, "  %3zu %9g %9g   (%6.3f, %6.3f, %6.3f)     %.4g\n", i + 1,
                  Clean(x.roll_deg), Clean(x.pitch_deg), Clean(x.axis_in_body[0]),
                  Clean(x.axis_in_body[1]), Clean(x.axis_in_body[2]), x.mean_std_kg_m2 * k);
    out << line;
  }
  const bool target = o.target_std_kg_m2 > 0;
  out << "\nExpected standard errors (" << u << ")"
      << (target ? ", and the trials per orientation to reach " +
                       Fmt("%.4g ", o.target_std_kg_m2 * k) + u
                 : std::string())
      << ":\n";
  for (int c = 0; c < kTensorComponents; ++c) {
    out << "  " << TensorComponentName(c) << "  ";
    if (!plan.observable[c]) {
      out << "not observable from the reachable attitudes\n";
      continue;
    }
    out << Fmt("%-11.4g", plan.std_kg_m2[c] * k);
    if (o.attitude_std_deg > 0) {
      out << " (floor from the attitude error " << Fmt("%.4g", plan.floor_std_kg_m2[c] * k) << ")";
    }
    if (target) {
      out << (plan.trials_needed[c] > 0
                  ? "  trials needed: " + std::to_string(plan.trials_needed[c])
                  : std::string("  target not reachable by more trials"));
    }
    out << "\n";
  }
  if (target) {
    if (plan.trials_needed_all > 0) {
      out << "Trials per orientation for every component to reach the target: "
          << plan.trials_needed_all << " (" << plan.trials_needed_all * plan.orientations.size()
          << " swings)\n";
    } else {
      out << "The target cannot be reached by more trials at these attitudes: the attitude error "
             "sets a floor; set the attitudes more precisely (or measure them: runs.pitch_source: "
             "measured) or widen the rig's range\n";
    }
  }
  out << "Design: rank " << plan.rank << " of 6, condition number "
      << Fmt("%.3g", plan.condition_number) << "\n";
  if (plan.n_combinations > 0) {
    out << "The design also determines " << plan.n_combinations
        << " combination(s) of the unobservable components.\n";
  }
  for (const std::string& w : plan.warnings) out << "warning: " << w << "\n";
  out << "These stds assume independent swing noise"
      << (o.attitude_std_deg > 0 ? " and the stated attitude error" : "")
      << "; errors shared by all orientations (rig tare, calibration) add to them.\n";
}

}  // namespace bifilar
