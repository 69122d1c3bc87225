// Internal to the CLI: each subcommand lives in its own cli_<name>.cc and registers itself here.
// A command's callback stores its exit code in *exit_code; user errors may throw
// bifilar::UserError, which the dispatcher prints as one line and turns into exit code 2.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "base/units.h"
#include "base/user_error.h"
#include "pipeline/commands/tensor_plan_command.h"

namespace bifilar {

// A check for every numeric flag: the text must be a finite number (CLI11 reads "nan" and "inf"
// as doubles, and CLI::Range lets NaN through).
CLI::Validator FiniteNumber();

// A check for a file or folder flag: an empty name is refused (it would silently write nothing).
CLI::Validator NonEmptyName();

// A seed flag, read strictly: a decimal integer in [0, max]; anything else (-1, 2^64, 1e23, 1.5)
// is a UserError naming the flag and the range, never a saturated or wrapped seed.
uint64_t ParseSeed(const std::string& text, const std::string& flag, uint64_t max);

void RegisterSimulateCommand(CLI::App& app, int* exit_code);
void RegisterFitCommand(CLI::App& app, int* exit_code);
void RegisterEllipseCommands(CLI::App& app, int* exit_code);  // `ellipse` and `plan`
void RegisterProcessCommands(CLI::App& app, int* exit_code);  // `process` and `report`
void RegisterInspectCommands(CLI::App& app, int* exit_code);  // `inspect` and `init`
void RegisterExportCommand(CLI::App& app, int* exit_code);    // `export`
void RegisterWatchCommand(CLI::App& app, int* exit_code);     // `watch`

// `plan --tensor` (pipeline/cli/cli_plan_tensor.cc): its options on the `plan` subcommand, whether
// it was asked for (throws UserError when a tensor-only option comes without --tensor), and the
// typed options of RunTensorPlan (pipeline/commands/tensor_plan_command.h), given the options it
// shares with the pitch-plane plan.
struct TensorPlanCli;
std::shared_ptr<TensorPlanCli> AddTensorPlanOptions(CLI::App* plan);
bool TensorPlanRequested(const TensorPlanCli& tensor_plan);
TensorPlanCommandOptions TensorPlanOptionsFromCli(const TensorPlanCli& tensor_plan,
                                                  const CLI::App& plan, int trials, double sigma,
                                                  double ixz, bool ixz_given, DisplayUnits units,
                                                  bool json);

// `plan --rig` (pipeline/cli/cli_plan_rig.cc): its options on the `plan` subcommand, whether it
// was asked for (throws UserError when a rig-only option comes without --rig), and the run.
struct RigPlanCli;
std::shared_ptr<RigPlanCli> AddRigPlanOptions(CLI::App* plan);
bool RigPlanRequested(const RigPlanCli& rig_plan);
int RunRigPlanCli(const RigPlanCli& rig_plan, const CLI::App& plan, bool json);

}  // namespace bifilar
