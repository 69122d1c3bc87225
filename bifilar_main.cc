#include "pipeline/cli/cli.h"

int main(int argc, char** argv) { return bifilar::RunCommandLine(argc, argv); }
