#include "pipeline/records/trace_record.h"

#include <algorithm>
#include <cctype>
#include <vector>

#include "base/enum_names.h"

namespace bifilar {

namespace {

// The one table of each enumeration (Ceres types.h style): results.json, the cache, reports.
constexpr EnumName<TraceStatus> kTraceStatusNames[] = {
    {TraceStatus::kOk, "ok"}, {TraceStatus::kRejected, "rejected"}, {TraceStatus::kError, "error"}};
constexpr EnumName<TraceRole> kTraceRoleNames[] = {{TraceRole::kAircraft, "aircraft"},
                                                   {TraceRole::kTare, "tare"},
                                                   {TraceRole::kCalibration, "calibration"}};

}  // namespace

namespace {

// The verbs a warning's action starts with (WarningAction's, and those of clauses that carry
// an action without being the warning's last one).
constexpr const char* kActionVerbs[] = {
    "raise",   "lower",    "set",       "swing",   "check", "give",    "rerun",    "use",
    "add",     "remove",   "release",   "hang",    "fix",   "measure", "increase", "decrease",
    "shorten", "lengthen", "reprocess", "replace", "move",  "weigh",   "repeat",   "steady",
    "log",     "fit",      "look",      "start",   "end",   "name"};

// True when `clause` (after an optional "and " or "or ") starts with an action verb.
bool StartsWithAction(std::string clause) {
  for (const char* joint : {"and ", "or "}) {
    if (clause.rfind(joint, 0) == 0) clause.erase(0, std::string(joint).size());
  }
  std::string word = clause.substr(0, clause.find(' '));
  std::transform(word.begin(), word.end(), word.begin(), ::tolower);
  for (const char* verb : kActionVerbs) {
    if (word == verb) return true;
  }
  return false;
}

}  // namespace

std::string WarningSummary(const std::string& warning, size_t max_chars) {
  std::string summary = warning;
  for (size_t k = 0; k + 2 < warning.size(); ++k) {
    if ((warning[k] == '.' || warning[k] == '?') && warning[k + 1] == ' ' &&
        std::isupper(static_cast<unsigned char>(warning[k + 2]))) {
      summary = warning.substr(0, warning[k] == '.' ? k : k + 1);
      break;
    }
  }
  if (summary.size() <= max_chars || max_chars < 8) return summary;
  size_t cut = summary.rfind(' ', max_chars - 4);
  if (cut == std::string::npos || cut < max_chars / 2) cut = max_chars - 4;
  // Never an action cut mid-sentence ("steady the rig before release, and swing ..."): a cut
  // inside a clause that says what to do moves to that clause's start.
  size_t clause = std::string::npos;
  for (const char* mark : {", ", "; ", ": "}) {
    const size_t at = summary.rfind(mark, cut);
    if (at != std::string::npos && (clause == std::string::npos || at > clause)) clause = at;
  }
  if (clause != std::string::npos && clause >= max_chars / 4 &&
      StartsWithAction(summary.substr(clause + 2, cut - clause - 2))) {
    cut = clause;
  }
  return summary.substr(0, cut) + " ...";
}

namespace {

// A warning's clauses, split at ". " and "; ".
std::vector<std::string> Clauses(const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = std::min(text.find(". ", start), text.find("; ", start));
    if (end == std::string::npos) end = text.size();
    out.push_back(text.substr(start, end - start));
    start = end + 2;
  }
  return out;
}

}  // namespace

std::string WarningAction(const std::string& warning) {
  static const char* const kVerbs[] = {
      "raise",   "lower",    "set",       "swing",   "check", "give",    "rerun",    "use",
      "add",     "remove",   "release",   "hang",    "fix",   "measure", "increase", "decrease",
      "shorten", "lengthen", "reprocess", "replace", "move",  "weigh",   "repeat"};
  std::string action;
  for (const std::string& clause : Clauses(warning)) {
    std::string word = clause.substr(0, clause.find(' '));
    std::transform(word.begin(), word.end(), word.begin(), ::tolower);
    for (const char* verb : kVerbs) {
      if (word == verb) action = clause;
    }
  }
  return action;
}

std::string WarningLine::Text() const {
  return action.empty() ? summary : summary + " -> " + action;
}

WarningLine LineOfWarning(const std::string& warning, size_t max_chars) {
  WarningLine line;
  line.summary = WarningSummary(warning, max_chars);
  const std::string action = WarningAction(warning);
  if (!action.empty() && line.summary.find(action) == std::string::npos) {
    // Room for " -> action", the summary keeping at least its first 60 characters.
    constexpr size_t kSeparator = 4, kShortest = 60;
    const size_t room = max_chars > action.size() + kSeparator + kShortest
                            ? max_chars - action.size() - kSeparator
                            : kShortest;
    line.summary = WarningSummary(warning, room);
    line.action = action;
  }
  line.folded = line.summary.size() < warning.size();
  return line;
}

const char* ToString(TraceStatus status) {
  return EnumToString(kTraceStatusNames, status, "error");
}
bool ParseTraceStatus(const std::string& name, TraceStatus* status) {
  return ParseEnum(kTraceStatusNames, name, status);
}
std::string TraceStatusAllowedValues() { return EnumAllowedValues(kTraceStatusNames); }

const char* ToString(TraceRole role) { return EnumToString(kTraceRoleNames, role, "aircraft"); }
bool ParseTraceRole(const std::string& name, TraceRole* role) {
  return ParseEnum(kTraceRoleNames, name, role);
}
std::string TraceRoleAllowedValues() { return EnumAllowedValues(kTraceRoleNames); }

RigGeometry GeometryForRole(const CampaignConfig& config, TraceRole role) {
  switch (role) {
    case TraceRole::kTare:
      return config.TareGeometry();
    case TraceRole::kCalibration:
      return config.CalibrationGeometry();
    case TraceRole::kAircraft:
      break;
  }
  return config.AircraftGeometry();
}

}  // namespace bifilar
