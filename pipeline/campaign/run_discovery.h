// Run discovery: which logs a campaign processes, with the nominal pitch of each.
// runs.pattern (or runs.table) finds the aircraft logs under runs.root, rig.inertia.tare.logs the
// tare logs; the pattern rules are those of configs/README.md (`runs`): `/`-separated
// components, `*` and `?` within one component (fnmatch(3), which also matches names starting
// with '.'), `{pitch_deg}` once capturing the pitch, no `..` (refused by the config loader).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/config/config.h"
#include "pipeline/records/trace_record.h"

namespace bifilar {

// One log found by discovery. A file that was found but cannot be used (pitch not readable from
// its path, listed in the table but missing, same content as an earlier log) carries `error`.
struct RunFile {
  std::string path;     // absolute
  std::string display;  // relative to the config folder
  TraceRole role = TraceRole::kAircraft;
  std::optional<double> pitch_nominal_deg;  // from the path pattern or the table
  std::optional<double> roll_nominal_deg;   // {roll_deg} in the pattern, roll_deg in the table
  std::string error;                        // non-empty: becomes an error row
  std::string group;  // runs.table's optional `group` column: the set-up it names ("" none)
};

// Aircraft runs (runs.pattern or runs.table), then tare logs, then the reference swings of
// rig.calibration, sorted by path within each. Throws UserError when runs.root (or the table)
// does not exist or nothing at all is found.
std::vector<RunFile> DiscoverRuns(const CampaignConfig& config);

// The logs of rig.inertia.tare.logs (role kTare) or rig.calibration.logs (kCalibration): each
// pattern's matches sorted by path; a plain file name that does not exist is a RunFile with an
// error. Throws UserError naming the key when a pattern's folder does not exist or it matches
// nothing.
std::vector<RunFile> DiscoverListedLogs(const CampaignConfig& config,
                                        const std::vector<std::string>& patterns, TraceRole role);

// A runs table read for the groups it names (`fit --repeats --runs-table FILE`): each row's
// path (column `path` or `file`) and its group: the `group` column, else the attitude of its
// `roll_deg` and `pitch_deg` columns ("roll 90 pitch 0"), as `process` groups them. Throws
// UserError naming the file and line (no path column, neither group nor pitch_deg).
struct RunsTableGroups {
  std::string source;               // "FILE (its group column)" or "(its roll_deg/pitch_deg)"
  std::vector<std::string> paths;   // as written in the table
  std::vector<std::string> groups;  // one per row
};
RunsTableGroups ReadRunsTableGroups(const std::string& table);

// For each log, the group of the table row naming it, "" when no row does: a row names a log
// when the row's path, folder by folder, is the end of the log's path (the table's paths are
// relative to runs.root, the logs are given as they are found).
std::vector<std::string> GroupsOfLogs(const std::vector<std::string>& logs,
                                      const RunsTableGroups& table);

}  // namespace bifilar
