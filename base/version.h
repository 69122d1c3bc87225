// The program version, stamped into results.json, cache keys and simulated logs, and printed by
// `bifilar --version`. Only base/version.cc is compiled with BIFILAR_VERSION.
#pragma once

namespace bifilar {

// Program version stamped into results and cache keys.
const char* ProgramVersion();

}  // namespace bifilar
