#include <iostream>

#include "pipeline/cli_commands.h"

namespace bifilar {

// Placeholder until the command lands.
void RegisterEllipseCommands(CLI::App& app, int* exit_code) {
  auto* sub = app.add_subcommand("ellipse", "(not implemented yet)");
  sub->callback([exit_code] {
    std::cerr << "bifilar: error: 'ellipse' is not implemented yet\n";
    *exit_code = 2;
  });
}

}  // namespace bifilar
