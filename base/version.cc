#include "base/version.h"

#ifndef BIFILAR_VERSION
#define BIFILAR_VERSION "unknown"
#endif

namespace bifilar {

const char* ProgramVersion() { return BIFILAR_VERSION; }

}  // namespace bifilar
