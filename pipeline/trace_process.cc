#include "pipeline/trace_process.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>

#include "pipeline/user_error.h"

namespace bifilar {

const char* ToString(TraceStatus status) {
  switch (status) {
    case TraceStatus::kOk: return "ok";
    case TraceStatus::kRejected: return "rejected";
    case TraceStatus::kError: return "error";
  }
  return "error";
}

bool ParseTraceStatus(const std::string& name, TraceStatus* status) {
  if (name == "ok") *status = TraceStatus::kOk;
  else if (name == "rejected") *status = TraceStatus::kRejected;
  else if (name == "error") *status = TraceStatus::kError;
  else return false;
  return true;
}

const char* ToString(TraceRole role) { return role == TraceRole::kTare ? "tare" : "aircraft"; }

std::optional<std::array<double, 2>> ConfigWindowFor(const CampaignConfig& config,
                                                     const std::string& path) {
  const std::string target = std::filesystem::path(path).lexically_normal().string();
  for (const auto& [key, window] : config.fit.windows_s) {
    if ((!config.runs.root.empty() && ResolvePath(config.runs.root, key) == target) ||
        ResolvePath(config.folder, key) == target) {
      return window;
    }
  }
  return std::nullopt;
}

TraceRecord ProcessTrace(const CampaignConfig& config, const std::string& path,
                         const TraceProcessOptions& options) {
  TraceRecord record;
  record.file = options.display_name.empty() ? path : options.display_name;
  record.role = options.role;
  record.model = ToString(config.fit.model);
  record.status = TraceStatus::kError;
  record.message = record.file + ": trace fit not available in this build yet";
  return record;
}

}  // namespace bifilar
