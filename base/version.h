// The program version, stamped into results.json, cache keys and simulated logs, and printed by
// `bifilar --version`. Only base/version.cc is compiled with BIFILAR_VERSION. And the schema
// version of the files bifilar writes to read back later.
#pragma once

namespace bifilar {

// Program version stamped into results and cache keys.
const char* ProgramVersion();

// The schema of results.json and of a cache entry (its record is results.json's trace record):
// the "schema_version" both write. Raised by one when a key is removed or renamed or its
// meaning or unit changes (a key added that older readers may ignore does not raise it), and
// CHANGELOG.md says so. Readers check it: `report` and `export` refuse a results.json of a newer
// schema, naming the file and both numbers, and read an older one as before (a key it lacks is
// named); the cache refits an entry of an older schema and refuses one of a newer. Files written
// before the number existed (bifilar 0.3.0 and earlier) have none: schema 0.
constexpr int kResultsSchemaVersion = 1;

}  // namespace bifilar
