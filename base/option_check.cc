#include "base/option_check.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace bifilar {

std::string FormatCheckValue(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  if (value == std::floor(value) && std::fabs(value) < 1e15) {
    std::snprintf(buffer, sizeof(buffer), "%.0f", value == 0.0 ? 0.0 : value);  // no "-0"
    return buffer;
  }
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, r.ptr);
}

std::string CheckMessage(const std::string& name, double value, const std::string& allowed) {
  return name + " = " + FormatCheckValue(value) + "; must be " + allowed;
}

std::string CheckFailure::Message() const {
  if (text) return field + " = \"" + value_text + "\"; must be " + allowed;
  return CheckMessage(field, value, allowed);
}

bool FailWith(const CheckFailure& failure, std::string* why, const std::string& context) {
  if (why != nullptr) *why = context + failure.Message();
  return false;
}

bool SetWhy(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

bool CheckFail(const std::string& field, double value, const std::string& allowed,
               CheckFailure* failure) {
  if (failure != nullptr) *failure = CheckFailure{field, value, allowed, "", false};
  return false;
}

bool CheckFailText(const std::string& field, const std::string& value, const std::string& allowed,
                   CheckFailure* failure) {
  if (failure != nullptr) *failure = CheckFailure{field, NAN, allowed, value, true};
  return false;
}

namespace {

std::string OpBoundText(const char* op, double bound) {
  return std::string(op) + FormatCheckValue(bound);
}

std::string OpFieldText(const char* op, const std::string& bound_field, double bound) {
  return op + bound_field + " = " + FormatCheckValue(bound);
}

}  // namespace

bool CheckGt(const std::string& field, double value, double bound, CheckFailure* failure) {
  return value > bound || CheckFail(field, value, OpBoundText("> ", bound), failure);
}
bool CheckGe(const std::string& field, double value, double bound, CheckFailure* failure) {
  return value >= bound || CheckFail(field, value, OpBoundText(">= ", bound), failure);
}
bool CheckLt(const std::string& field, double value, double bound, CheckFailure* failure) {
  return value < bound || CheckFail(field, value, OpBoundText("< ", bound), failure);
}
bool CheckLe(const std::string& field, double value, double bound, CheckFailure* failure) {
  return value <= bound || CheckFail(field, value, OpBoundText("<= ", bound), failure);
}

bool CheckFiniteGt(const std::string& field, double value, double bound, CheckFailure* failure) {
  return (std::isfinite(value) && value > bound) ||
         CheckFail(field, value, OpBoundText("finite and > ", bound), failure);
}
bool CheckFiniteGe(const std::string& field, double value, double bound, CheckFailure* failure) {
  return (std::isfinite(value) && value >= bound) ||
         CheckFail(field, value, OpBoundText("finite and >= ", bound), failure);
}
bool CheckFinite(const std::string& field, double value, CheckFailure* failure) {
  return std::isfinite(value) || CheckFail(field, value, "finite", failure);
}

bool CheckGt(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure) {
  return value > bound || CheckFail(field, value, OpFieldText("> ", bound_field, bound), failure);
}
bool CheckGe(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure) {
  return value >= bound || CheckFail(field, value, OpFieldText(">= ", bound_field, bound), failure);
}
bool CheckLt(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure) {
  return value < bound || CheckFail(field, value, OpFieldText("< ", bound_field, bound), failure);
}
bool CheckLe(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure) {
  return value <= bound || CheckFail(field, value, OpFieldText("<= ", bound_field, bound), failure);
}

std::string IntervalText(double lo, double hi, Ends ends) {
  const bool lo_open = ends == Ends::kOpen || ends == Ends::kOpenClosed;
  const bool hi_open = ends == Ends::kOpen || ends == Ends::kClosedOpen;
  return std::string(lo_open ? "(" : "[") + FormatCheckValue(lo) + ", " + FormatCheckValue(hi) +
         (hi_open ? ")" : "]");
}

bool CheckIn(const std::string& field, double value, double lo, double hi, Ends ends,
             CheckFailure* failure) {
  const bool lo_open = ends == Ends::kOpen || ends == Ends::kOpenClosed;
  const bool hi_open = ends == Ends::kOpen || ends == Ends::kClosedOpen;
  const bool ok = (lo_open ? value > lo : value >= lo) && (hi_open ? value < hi : value <= hi);
  return ok || CheckFail(field, value, "in " + IntervalText(lo, hi, ends), failure);
}

}  // namespace bifilar
