#include "pipeline/cli.h"

#include <exception>
#include <new>
#include <iostream>

#include "fit/solver_logging.h"
#include "pipeline/cli_commands.h"

namespace bifilar {

int RunCommandLine(int argc, char** argv) {
  QuietSolverLogging();  // fit/solver_logging.h: no glog preamble or solver chatter
  CLI::App app{"bifilar: aircraft mass properties from bifilar pendulum IMU logs"};
  app.set_version_flag("--version", std::string("bifilar ") + BIFILAR_VERSION);
  app.require_subcommand(1);
  int exit_code = 0;
  RegisterProcessCommands(app, &exit_code);
  RegisterFitCommand(app, &exit_code);
  RegisterEllipseCommands(app, &exit_code);
  RegisterSimulateCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "bifilar: error: out of memory: an input (a file, or a count in the config or "
                 "options) is far larger than this machine can hold; see the limits in "
                 "configs/README.md\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "bifilar: error: " << e.what() << "\n";
    return 2;
  }
  return exit_code;
}

}  // namespace bifilar
