// `bifilar plan --rig`: the console text, the JSON, the starting config and the figure of a
// RigPlan (rig_plan.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "base/text_format.h"
#include "base/user_error.h"
#include "pipeline/commands/rig_plan.h"
#include "pipeline/config/config.h"
#include "pipeline/config/config_template.h"
#include "pipeline/figures/figure.h"
#include "pipeline/figures/rig_plan_plot.h"

namespace bifilar {
namespace {

std::string Pct(double fraction) { return Fmt("%.3g %%", 100.0 * fraction); }

std::string TermsLine(const RigPlanTerms& t) {
  std::string s = "stat " + Pct(t.statistical) + ", between-repeat " + Pct(t.between_repeat) +
                  " (per swing, / sqrt(" + std::to_string(t.repeats) + "))";
  if (t.calibration > 0.0)
    s += ", calibration " + Pct(t.calibration);
  else
    s += ", L " + Pct(t.filar_length) + ", D " + Pct(t.filar_separation);
  s += ", mass " + Pct(t.mass) + ", g " + Pct(t.gravity);
  return s;
}

nlohmann::json TermsJson(const RigPlanTerms& t) {
  return {{"statistical_percent", 100.0 * t.statistical},
          {"between_repeat_percent", 100.0 * t.between_repeat},
          {"filar_length_percent", 100.0 * t.filar_length},
          {"filar_separation_percent", 100.0 * t.filar_separation},
          {"mass_percent", 100.0 * t.mass},
          {"gravity_percent", 100.0 * t.gravity},
          {"calibration_percent", 100.0 * t.calibration},
          {"repeats", t.repeats},
          {"total_std_percent", 100.0 * t.Total()},
          {"single_swing_std_percent", 100.0 * t.SingleSwing()}};
}

nlohmann::json Nullable(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

std::string Defaults(const RigPlanOptions& o) {
  std::ostringstream s;
  s << "  assumed (flags): --cradle-mass " << o.cradle_mass_kg << " kg, --mass-std "
    << Fmt("%.3g", o.mass_std_kg) << " kg, --length-std " << o.length_std_m
    << " m, --separation-std " << o.separation_std_m << " m, --gravity-std " << o.gravity_std_mps2
    << " m/s^2, --imu-rate " << o.imu_rate_hz << " Hz, --gyro-noise " << o.gyro_noise_deg_per_s
    << " deg/s, --min-period " << o.min_period_s << " s, --max-period " << o.max_period_s
    << " s, --min-length " << o.min_length_m << " m, --min-separation " << o.min_separation_m
    << " m, --repeat-scatter " << o.repeat_scatter_percent << " %, --rig-departure "
    << o.rig_departure_percent << " % at 30 deg; the swing's amplitude "
    << "falls to 1/e in " << o.decay_periods << " periods\n";
  return s.str();
}

// The first line under the title: met, or why not (no rig in the period window; a target below
// the floor no rig lowers; the constraints), with the binding flag.
std::string Headline(const RigPlan& p) {
  const RigPlanOptions& o = p.options;
  const std::string total = Fmt("%.3g", 100.0 * p.recommended.terms.Total()) + " %";
  if (p.target_met) return "  target met: expected total std " + total;
  if (p.period_window_missed) {
    return "  NO RIG FITS THE PERIOD WINDOW [" + Fmt("%g", o.min_period_s) + ", " +
           Fmt("%g", o.max_period_s) + "] s within the constraints (binding: " + p.binding +
           "); the rig shown, outside it, would give " + total;
  }
  if (p.below_floor) {
    return "  TARGET UNREACHABLE: " + Fmt("%g", o.target_percent) + " % is below the floor of " +
           Fmt("%.3g", 100.0 * p.floor.rel_std) + " % set by the " + p.floor.term +
           " term (binding: " + p.binding + "); the best within the constraints is " + total;
  }
  return "  TARGET NOT MET within the constraints: expected total std " + total +
         " is the best possible; binding: " + p.binding;
}

// Console lines of at most kMaxLine characters (issue 32 item 8): a longer line is broken after
// its last "; " (else ", ", else a space) that fits, the rest indented 4 more than the line.
constexpr size_t kMaxLine = 160;
std::string WrapLines(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    const std::string indent(
        line.find_first_not_of(' ') == std::string::npos ? 0 : line.find_first_not_of(' ') + 4,
        ' ');
    while (line.size() > kMaxLine) {
      size_t at = std::string::npos;
      for (const char* sep : {"; ", ", ", " "}) {
        const size_t k = line.rfind(sep, kMaxLine - std::string(sep).size());
        if (k != std::string::npos && k > indent.size()) {
          at = k + std::string(sep).size() - 1;  // keep ';' or ',' on the first line
          break;
        }
      }
      if (at == std::string::npos) break;  // one long word: left as it is
      out += line.substr(0, at) + "\n";
      line = indent + line.substr(at + 1);
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace

std::string RigPlanText(const RigPlan& p) {
  const RigPlanOptions& o = p.options;
  const RigCandidate& r = p.recommended;
  std::ostringstream s;
  s << "rig plan for " << Fmt("%.4g", o.mass_kg) << " kg";
  if (o.cradle_mass_kg > 0) s << " + cradle " << Fmt("%.4g", o.cradle_mass_kg) << " kg";
  s << ", I " << Fmt("%.4g", o.inertia_kg_m2);
  if (std::isfinite(o.inertia_max_kg_m2)) s << " to " << Fmt("%.4g", o.inertia_max_kg_m2);
  s << " kg m^2, target " << o.target_percent << " %\n";
  s << Headline(p) << "\n";
  if (!p.advice.empty()) s << "  " << p.advice << "\n";
  s << "  recommended: L " << Fmt("%.3f", r.length_m) << " m, D " << Fmt("%.4f", r.separation_m)
    << " m, period " << Fmt("%.3g", r.period_s) << " s\n";
  s << "  terms: " << TermsLine(r.terms) << "\n";
  s << "  release at <= " << Fmt("%.3g", p.release_amplitude_deg)
    << " deg: a rig departing from the model like the simulator's non-ideal preset ("
    << o.rig_departure_percent
    << " % at 30 deg) then moves I by <= " << Fmt("%.2g", 100 * p.departure_fraction_of_target)
    << " % of the target (the fit's full "
    << "model covers the ideal pendulum at any amplitude; the small-angle formula would be "
    << Fmt("%.2g", p.small_angle_excess_percent) << " % high there)\n";
  s << "  log " << Fmt("%.0f", p.swing_s) << " s of free swing, " << r.terms.repeats
    << " repeats per set-up (fit them with --repeats)\n";
  if (p.simulated_rate_hz < o.imu_rate_hz) {
    s << "  note: the swings were simulated at " << Fmt("%.3g", p.simulated_rate_hz)
      << " Hz with the noise of the fit's block means (the same information as "
      << Fmt("%g", o.imu_rate_hz) << " Hz), which bounds the plan's time and memory\n";
  }
  for (const RigCandidate& a : p.alternatives) {
    s << "  alternative (" << a.label << "): L " << Fmt("%.3f", a.length_m) << " m, D "
      << Fmt("%.4f", a.separation_m) << " m, period " << Fmt("%.3g", a.period_s) << " s, total "
      << Fmt("%.3g", 100.0 * a.terms.Total()) << " %\n";
  }
  if (std::isfinite(p.separation_for_target_m) && !p.target_met) {
    s << "  to meet the target without a reference object: D >= "
      << Fmt("%.3f", p.separation_for_target_m) << " m on L " << Fmt("%.3f", p.length_for_target_m)
      << " m\n";
  }
  const ReferenceBar& b = p.reference;
  if (!b.buildable) {
    s << "  reference object "
      << (b.needed ? "NEEDED, but none buildable: " : "not needed (none buildable: ") << b.why_not
      << (b.needed ? "\n" : ")\n");
  } else {
    s << "  reference object " << (b.needed ? "NEEDED" : "not needed") << ": "
      << (b.material == "aluminium" ? "an " : "a ") << b.material << " bar "
      << Fmt("%.1f", b.length_m * 1e3) << " x " << Fmt("%.1f", b.width_m * 1e3) << " x "
      << Fmt("%.1f", b.thickness_m * 1e3) << " mm, " << Fmt("%.4g", b.mass_kg)
      << " kg, swung flat: I "
      << "= M (a^2 + b^2)/12 = " << Fmt("%.4g", b.inertia_kg_m2) << " kg m^2 +- "
      << Pct(b.inertia_rel_std) << " (+-" << Fmt("%.2g", b.tolerance_m * 1e3)
      << " mm on a and b, weighed to 0.02 %), " << b.swings << " swings -> total "
      << Fmt("%.3g", 100.0 * p.calibrated.Total()) << " % (" << TermsLine(p.calibrated) << ")\n";
  }
  if (p.monte_carlo.swings > 0) {
    const RigMonteCarlo& m = p.monte_carlo;
    s << "  Monte-Carlo: " << m.usable << "/" << m.swings << " swings fitted, scatter of I "
      << Fmt("%.3g", 100.0 * m.scatter_rel_std) << " % against one swing's predicted "
      << Fmt("%.3g", 100.0 * m.predicted_rel_std) << " % (ratio " << Fmt("%.3f", m.ratio) << ")\n";
  }
  s << Defaults(o);
  s << "  planned in " << Fmt("%.2f", p.plan_seconds) << " s\n";
  return WrapLines(s.str());
}

std::string RigPlanJson(const RigPlan& p) {
  const RigCandidate& r = p.recommended;
  nlohmann::json j;
  j["target_percent"] = p.options.target_percent;
  j["target_met"] = p.target_met;
  j["exit_code"] = RigPlanExitCode(p);
  j["period_window_missed"] = p.period_window_missed;
  j["periods_possible_s"] = {Nullable(p.periods_possible_s[0]), Nullable(p.periods_possible_s[1])};
  j["below_floor"] = p.below_floor;
  j["floor"] = {{"std_percent", 100.0 * p.floor.rel_std},
                {"term", p.floor.term},
                {"flag", p.floor.flag},
                {"lift", p.floor.lift},
                {"parts", p.floor.parts}};
  j["simulated_rate_hz"] = p.simulated_rate_hz;
  j["binding_constraint"] = p.binding.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.binding);
  j["advice"] = p.advice;
  j["best_std_percent"] = p.best_std_percent;
  j["length_m"] = r.length_m;
  j["separation_m"] = r.separation_m;
  j["period_s"] = r.period_s;
  j["total_std_percent"] = 100.0 * r.terms.Total();
  j["terms"] = TermsJson(r.terms);
  j["release_amplitude_deg"] = p.release_amplitude_deg;
  j["small_angle_excess_percent"] = p.small_angle_excess_percent;
  j["swing_s"] = p.swing_s;
  j["repeats"] = r.terms.repeats;
  j["separation_for_target_m"] = Nullable(p.separation_for_target_m);
  j["length_for_target_m"] = Nullable(p.length_for_target_m);
  nlohmann::json alts = nlohmann::json::array();
  for (const RigCandidate& a : p.alternatives) {
    alts.push_back({{"label", a.label},
                    {"length_m", a.length_m},
                    {"separation_m", a.separation_m},
                    {"period_s", a.period_s},
                    {"total_std_percent", 100.0 * a.terms.Total()},
                    {"terms", TermsJson(a.terms)}});
  }
  j["alternatives"] = alts;
  const ReferenceBar& b = p.reference;
  j["reference_object"] = {{"needed", b.needed},
                           {"buildable", b.buildable},
                           {"why_not", b.why_not},
                           {"material", b.material},
                           {"length_m", b.length_m},
                           {"width_m", b.width_m},
                           {"thickness_m", b.thickness_m},
                           {"mass_kg", b.mass_kg},
                           {"inertia_kg_m2", b.inertia_kg_m2},
                           {"inertia_rel_std", b.inertia_rel_std},
                           {"swings", b.swings},
                           {"total_std_percent", 100.0 * p.calibrated.Total()},
                           {"terms", TermsJson(p.calibrated)}};
  const RigPlanOptions& o = p.options;
  j["inputs"] = {{"mass_kg", o.mass_kg},
                 {"cradle_mass_kg", o.cradle_mass_kg},
                 {"inertia_kg_m2", o.inertia_kg_m2},
                 {"inertia_max_kg_m2", Nullable(o.inertia_max_kg_m2)},
                 {"max_length_m", o.max_length_m},
                 {"max_separation_m", o.max_separation_m},
                 {"min_length_m", o.min_length_m},
                 {"min_separation_m", o.min_separation_m},
                 {"min_period_s", o.min_period_s},
                 {"max_period_s", o.max_period_s},
                 {"length_std_m", o.length_std_m},
                 {"separation_std_m", o.separation_std_m},
                 {"mass_std_kg", o.mass_std_kg},
                 {"gravity_mps2", o.gravity_mps2},
                 {"gravity_std_mps2", o.gravity_std_mps2},
                 {"imu_rate_hz", o.imu_rate_hz},
                 {"gyro_noise_deg_per_s", o.gyro_noise_deg_per_s},
                 {"repeat_scatter_percent", o.repeat_scatter_percent},
                 {"rig_departure_percent_at_30deg", o.rig_departure_percent},
                 {"decay_periods", o.decay_periods}};
  if (p.monte_carlo.swings > 0) {
    j["monte_carlo"] = {{"swings", p.monte_carlo.swings},
                        {"usable", p.monte_carlo.usable},
                        {"predicted_std_percent", 100.0 * p.monte_carlo.predicted_rel_std},
                        {"scatter_std_percent", 100.0 * p.monte_carlo.scatter_rel_std},
                        {"ratio", p.monte_carlo.ratio}};
  }
  j["plan_seconds"] = p.plan_seconds;
  return j.dump(2) + "\n";
}

namespace {

// The rig's own lines after `  mass_kg: ...` of the rig section that init writes.
std::string RigLines(const RigPlan& p, bool cradle) {
  const RigPlanOptions& o = p.options;
  std::ostringstream y;
  y << "  # Written by `bifilar plan --rig`: the stds the plan assumed (1 sigma); replace them by\n"
       "  # what you measured. The mass std stands for everything that hangs.\n"
       "  uncertainties:\n"
       "    filar_length_std_m: "
    << Fmt("%.6g", o.length_std_m)
    << "\n    filar_separation_std_m: " << Fmt("%.6g", o.separation_std_m)
    << "\n    mass_std_kg: " << Fmt("%.6g", cradle ? 0.0 : o.mass_std_kg)
    << "\n    gravity_std_mps2: " << Fmt("%.6g", o.gravity_std_mps2) << "\n";
  if (p.reference.needed && p.reference.buildable) {
    const ReferenceBar& b = p.reference;
    y << "  # The rig alone (cradle, thread, clips): weigh it for rig.mass_kg; its inertia here "
         "is\n"
         "  # a guess to replace (or use tare: {logs: tare/*.csv}).\n"
         "  inertia:\n"
         "    inertia_kg_m2: 0\n"
         "    inertia_std_kg_m2: 0\n"
         "  # The reference object the plan chose: a "
      << b.material << " bar " << Fmt("%.1f", b.length_m * 1e3) << " x "
      << Fmt("%.1f", b.width_m * 1e3) << " x " << Fmt("%.1f", b.thickness_m * 1e3)
      << " mm swung flat; write the inertia of the bar as made\n"
         "  # (M (a^2 + b^2)/12 from its drawing and weighing) and swing it "
      << b.swings
      << " times at the aircraft's amplitude.\n"
         "  calibration:\n"
         "    logs: calibration/*.csv\n"
         "    reference_inertia_kg_m2: "
      << Fmt("%.6g", b.inertia_kg_m2)
      << "\n    reference_inertia_std_kg_m2: " << Fmt("%.3g", b.inertia_rel_std * b.inertia_kg_m2)
      << "\n    reference_mass_kg: " << Fmt("%.6g", b.mass_kg) << "\n";
  }
  return y.str();
}

}  // namespace

std::string RigPlanConfigText(const RigPlan& p, const std::string& path) {
  const RigPlanOptions& o = p.options;
  // A thread rig (no cradle) without a reference object: everything that hangs is rig.mass_kg
  // (as configs/crazyflie_basemodel.yaml). With a cradle, or a reference object (whose swings
  // need a rig of its own), the aircraft has its own section.
  const bool split = o.cradle_mass_kg > 0.0 || (p.reference.needed && p.reference.buildable);
  StartingConfigOptions start;
  start.filar_length_m = p.recommended.length_m;
  start.filar_separation_m = p.recommended.separation_m;
  // A reference object needs a rig mass of its own; a thread rig's is the thread (0.1 g).
  start.mass_kg = split ? std::max(o.cradle_mass_kg, 1e-4) : o.mass_kg;
  start.gravity_mps2 = o.gravity_mps2;
  std::string text = StartingConfigText(start);
  const std::string key = "\n  mass_kg: ";
  const size_t at = text.find(key);
  const size_t eol = at == std::string::npos ? at : text.find('\n', at + key.size());
  if (eol == std::string::npos) {
    throw UserError("plan --rig: --write-config " + path + ": the init template has no rig mass");
  }
  text.insert(eol + 1, RigLines(p, split));
  if (split) {
    text +=
        "\n# Written by `bifilar plan --rig`: the aircraft (kg) and its std.\naircraft:\n"
        "  mass_kg: " +
        Fmt("%.6g", o.mass_kg) + "\n  mass_std_kg: " + Fmt("%.6g", o.mass_std_kg) + "\n";
  }
  ConfigLoadOptions load;
  load.require_runs = false;
  try {
    LoadCampaignConfigText(text, path, load);
  } catch (const UserError& e) {
    throw UserError("plan --rig: --write-config " + path +
                    ": the config it would write is rejected: " + e.what());
  }
  return text;
}

bool WriteRigPlanPlot(const RigPlan& p, const std::string& path, std::string* why) {
  RigPlanFigure f;
  f.separation_m = p.grid.separation_m;
  f.length_m = p.grid.length_m;
  f.total_percent = p.grid.total_percent;
  f.feasible = p.grid.feasible;
  f.target_percent = p.options.target_percent;
  f.chosen_separation_m = p.recommended.separation_m;
  f.chosen_length_m = p.recommended.length_m;
  f.chosen_total_percent = 100.0 * p.recommended.terms.Total();
  f.title = "bifilar plan --rig: " + Fmt("%.4g", p.options.mass_kg) + " kg, I " +
            Fmt("%.3g", p.options.inertia_kg_m2) + " " + InertiaUnitPlotLabel(DisplayUnits::kSi) +
            ", target " + Fmt("%g", p.options.target_percent) + " %";
  return WriteRigPlanFigure(f, path, why);
}

}  // namespace bifilar
