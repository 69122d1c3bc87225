#include "pipeline/records/trace_record.h"

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

const char* ToString(TraceRole role) {
  switch (role) {
    case TraceRole::kAircraft: return "aircraft";
    case TraceRole::kTare: return "tare";
    case TraceRole::kCalibration: return "calibration";
  }
  return "aircraft";
}

bool ParseTraceRole(const std::string& name, TraceRole* role) {
  if (name == "aircraft") *role = TraceRole::kAircraft;
  else if (name == "tare") *role = TraceRole::kTare;
  else if (name == "calibration") *role = TraceRole::kCalibration;
  else return false;
  return true;
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
