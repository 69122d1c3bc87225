// The `bifilar` command line: parses, validates and calls the typed Run... functions of the
// library. Exit codes: 0 all well, 1 some traces failed or were rejected, 2 config or usage error.
#pragma once

namespace bifilar {

int RunCommandLine(int argc, char** argv);

}  // namespace bifilar
