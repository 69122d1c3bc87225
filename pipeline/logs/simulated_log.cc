#include "pipeline/logs/simulated_log.h"

#include "base/version.h"

namespace bifilar {
namespace {

constexpr std::string_view kCsvPrefix = "# simulated by ";
constexpr std::string_view kCsvSuffix = ": not a measurement";
constexpr std::string_view kWarningPrefix = "simulated by ";

}  // namespace

std::string SimulatedLogOrigin(uint64_t seed) {
  return std::string("bifilar ") + ProgramVersion() + " simulate, seed " + std::to_string(seed);
}

std::string SimulatedCsvMarkerLine(const std::string& origin) {
  return std::string(kCsvPrefix) + origin + std::string(kCsvSuffix);
}

std::string SimulatedLogWarning(std::string_view origin) {
  std::string clean;
  for (char c : origin.substr(0, 120)) clean += (c >= 32 && c < 127) ? c : '?';
  return std::string(kWarningPrefix) + clean + std::string(kCsvSuffix);
}

bool ParseSimulatedCsvMarker(std::string_view line, std::string* warning) {
  while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) {
    line.remove_suffix(1);
  }
  if (line.substr(0, kCsvPrefix.size()) != kCsvPrefix || line.size() < kCsvSuffix.size() ||
      line.substr(line.size() - kCsvSuffix.size()) != kCsvSuffix) {
    return false;
  }
  std::string_view origin = line.substr(kCsvPrefix.size());
  origin.remove_suffix(kCsvSuffix.size());
  if (origin.substr(0, 8) != "bifilar ") return false;
  *warning = SimulatedLogWarning(origin);
  return true;
}

bool IsSimulatedLogWarning(std::string_view warning) {
  return warning.substr(0, kWarningPrefix.size() + 8) == "simulated by bifilar " &&
         warning.size() >= kCsvSuffix.size() &&
         warning.substr(warning.size() - kCsvSuffix.size()) == kCsvSuffix;
}

}  // namespace bifilar
