// `bifilar export RESULTS --format urdf|sdf|jsbsim|csv|mjcf|ardupilot [--out FILE | --into MODEL
// --link NAME]`: parse options, call RunExport (pipeline/report/export.h).

#include <cmath>
#include <iostream>

#include "base/csv.h"
#include "pipeline/cli/cli_commands.h"
#include "pipeline/report/export.h"

namespace bifilar {

void RegisterExportCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand(
      "export",
      "Write the inertia of a results.json for a simulator: URDF or SDF <inertial>, JSBSim "
      "<mass_balance>, MuJoCo <body>, ArduPilot SITL frame JSON, or a flat CSV, each in its own "
      "frame and sign convention; or rewrite one link's inertial in a model file (--into)");
  auto opts = std::make_shared<ExportOptions>();
  auto format = std::make_shared<std::string>();
  auto frame = std::make_shared<std::string>("flu");
  auto sets = std::make_shared<std::vector<std::string>>();
  cmd->add_option("results", opts->results_path,
                  "results.json written by `bifilar process` (or its output folder)")
      ->required();
  cmd->add_option("--format", *format, ExportFormatAllowedValues())->required();
  cmd->add_option("--out", opts->out_path, "write this file (default: print to stdout)");
  cmd->add_option("--into", opts->into_path,
                  "rewrite the inertial block of --link in this URDF, SDF or MJCF model, every "
                  "other byte unchanged; the file as it was is kept as MODEL.bak (or .bak.N)");
  cmd->add_option("--link", opts->link_name,
                  "with --into: the link (URDF, SDF) or body (MJCF) whose inertial is rewritten");
  auto* frame_option = cmd->add_option(
      "--frame", *frame,
      "urdf/sdf/mjcf: flu (x forward, y left, z up: ROS REP 103, Gazebo; default) or frd (the "
      "body axes as measured, x forward, y right, z down)");
  cmd->add_option("--mass-kg", opts->mass_kg,
                  "mass to write (default: aircraft.mass_kg of the config stored in the result)")
      ->check(FiniteNumber());
  cmd->add_option("--set", *sets,
                  "NAME=VALUE: a component the result does not hold, in kg m^2, body axes, "
                  "products positive (I_xy = integral x y dm), e.g. --set Iyy=0.42; repeatable");
  cmd->add_flag("--force", opts->force,
                "replace an --out file that export did not write, rewrite an --into inertial "
                "export did not write, and write a simulator file of a tensor that is not "
                "physical (the warning stays)");
  cmd->add_flag("--symmetric", opts->symmetric,
                "take Ixy = Iyz = 0 when the result does not hold them (aircraft symmetric about "
                "its x-z plane)");
  cmd->callback([opts, format, frame, frame_option, sets, exit_code] {
    if (!ParseExportFormat(*format, &opts->format)) {
      throw UserError("export: --format must be " + ExportFormatAllowedValues() + ", got '" +
                      *format + "'");
    }
    if (!ParseExportFrame(*frame, &opts->frame)) {
      throw UserError("export: --frame must be " + ExportFrameAllowedValues() + ", got '" + *frame +
                      "'");
    }
    opts->frame_given = frame_option->count() > 0;
    for (const std::string& s : *sets) {
      const size_t eq = s.find('=');
      double v = 0.0;
      // base/csv.h; infinity and NaN pass here, as before, and the export's check names them.
      if (eq == std::string::npos ||
          !ParseNumber(std::string_view(s).substr(eq + 1), &v, NonFinite::kAccept)) {
        throw UserError("export: --set '" + s + "': expected NAME=VALUE, e.g. Iyy=0.42");
      }
      const std::string name = s.substr(0, eq);
      if (!opts->set_kg_m2.emplace(name, v).second) {
        throw UserError("export: --set " + name + " given twice");
      }
    }
    *exit_code = RunExport(*opts, std::cout, std::cerr);
  });
}

}  // namespace bifilar
