#include "pipeline/records/trace_record.h"

#include <cctype>
#include <vector>

#include "base/enum_names.h"

namespace bifilar {

namespace {

// The one table of each enumeration (Ceres types.h style): results.json, the cache, reports.
struct TraceStatusRow {
  TraceStatus status;
  const char* name;
};
constexpr TraceStatusRow kTraceStatusTable[] = {
    {TraceStatus::kOk, "ok"}, {TraceStatus::kRejected, "rejected"}, {TraceStatus::kError, "error"}};

struct TraceRoleRow {
  TraceRole role;
  const char* name;
};
constexpr TraceRoleRow kTraceRoleTable[] = {{TraceRole::kAircraft, "aircraft"},
                                            {TraceRole::kTare, "tare"},
                                            {TraceRole::kCalibration, "calibration"}};

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
  return summary.substr(0, cut) + " ...";
}

const char* ToString(TraceStatus status) {
  for (const TraceStatusRow& row : kTraceStatusTable) {
    if (row.status == status) return row.name;
  }
  return "error";
}

bool ParseTraceStatus(const std::string& name, TraceStatus* status) {
  for (const TraceStatusRow& row : kTraceStatusTable) {
    if (name == row.name) {
      *status = row.status;
      return true;
    }
  }
  return false;
}

std::string TraceStatusAllowedValues() {
  std::vector<std::string> names;
  for (const TraceStatusRow& row : kTraceStatusTable) names.push_back(row.name);
  return JoinAllowedValues(names);
}

const char* ToString(TraceRole role) {
  for (const TraceRoleRow& row : kTraceRoleTable) {
    if (row.role == role) return row.name;
  }
  return "aircraft";
}

bool ParseTraceRole(const std::string& name, TraceRole* role) {
  for (const TraceRoleRow& row : kTraceRoleTable) {
    if (name == row.name) {
      *role = row.role;
      return true;
    }
  }
  return false;
}

std::string TraceRoleAllowedValues() {
  std::vector<std::string> names;
  for (const TraceRoleRow& row : kTraceRoleTable) names.push_back(row.name);
  return JoinAllowedValues(names);
}

RigGeometry GeometryForRole(const CampaignConfig& config, TraceRole role) {
  switch (role) {
    case TraceRole::kTare: return config.TareGeometry();
    case TraceRole::kCalibration: return config.CalibrationGeometry();
    case TraceRole::kAircraft: break;
  }
  return config.AircraftGeometry();
}

}  // namespace bifilar
