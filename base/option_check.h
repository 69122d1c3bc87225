// Validation of options structs, the Ceres way (`OPTION_GT(field, bound)` in solver.cc) and
// COLMAP's (`CHECK_OPTION_GE`): every failing bound names the field, its value and the bound, in
// one format for the whole project:
//
//   <field> = <value>; must be <allowed>         e.g. "min_period_s = -1; must be > 0"
//
// (a NaN value reads "nan", infinities "inf" and "-inf"). A struct's `Check(std::string* why)`
// may put its context in front ("window: min_period_s = -1; must be > 0"). Each helper returns
// true when the bound holds; otherwise it fills *failure (when not null) and returns false, so a
// Check is a chain of `&&`. Every comparison fails for NaN. A cross-field bound names both
// fields and both values: "max_period_s = 1; must be > min_period_s = 2".
#pragma once

#include <string>

namespace bifilar {

// A value outside its bound: the options field, its value and what is allowed. The config layer
// maps `field` to its YAML key with a table (pipeline/config/config.cc), never by reading text.
struct CheckFailure {
  std::string field;    // the options struct's field, e.g. "quality.whiteness_lags"
  double value = 0.0;   // its value
  std::string allowed;  // the bound, e.g. "in [1, 1000]", "> min_period_s = 2"
  // When the value is not a number (a name, a path, a choice): shown quoted instead of `value`.
  std::string value_text = std::string();
  bool text = false;  // value_text is the value

  // "<field> = <value>; must be <allowed>".
  std::string Message() const;
};

// A number as a Check message shows it: integers exactly (below 1e15), others in the shortest
// form that reads back to the same double; "nan", "inf", "-inf".
std::string FormatCheckValue(double value);
// The one message format: "<name> = <value>; must be <allowed>" (value formatted as above).
std::string CheckMessage(const std::string& name, double value, const std::string& allowed);

// *why = `context` + failure.Message() (context e.g. "window: "; why may be null); returns false.
bool FailWith(const CheckFailure& failure, std::string* why, const std::string& context = "");

// *why = message (why may be null); returns false. For failures that are not a bound (an
// integration that diverged), so that a file needs no `Fail` helper of its own.
bool SetWhy(std::string* why, const std::string& message);

// A failure with any bound text ("a rotation matrix"): fills *failure, returns false.
bool CheckFail(const std::string& field, double value, const std::string& allowed,
               CheckFailure* failure);
// The same for a value that is not a number (shown quoted): `out_dir = ""; must be set`.
bool CheckFailText(const std::string& field, const std::string& value, const std::string& allowed,
                   CheckFailure* failure);

// value > bound, value >= bound, value < bound, value <= bound.
bool CheckGt(const std::string& field, double value, double bound, CheckFailure* failure);
bool CheckGe(const std::string& field, double value, double bound, CheckFailure* failure);
bool CheckLt(const std::string& field, double value, double bound, CheckFailure* failure);
bool CheckLe(const std::string& field, double value, double bound, CheckFailure* failure);
// The same, and the value finite: "finite and > 0".
bool CheckFiniteGt(const std::string& field, double value, double bound, CheckFailure* failure);
bool CheckFiniteGe(const std::string& field, double value, double bound, CheckFailure* failure);
// The value finite: "finite".
bool CheckFinite(const std::string& field, double value, CheckFailure* failure);

// Cross-field bounds: value against another field's value, e.g.
// CheckGt("max_period_s", max, "min_period_s", min, f) -> "... must be > min_period_s = 2".
bool CheckGt(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure);
bool CheckGe(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure);
bool CheckLt(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure);
bool CheckLe(const std::string& field, double value, const std::string& bound_field, double bound,
             CheckFailure* failure);

// Which ends of an interval belong to it: [lo, hi], (lo, hi), (lo, hi], [lo, hi).
enum class Ends { kClosed, kOpen, kOpenClosed, kClosedOpen };
// lo <= value <= hi (or the open variants): "in [lo, hi]". An infinite end reads "inf".
bool CheckIn(const std::string& field, double value, double lo, double hi, Ends ends,
             CheckFailure* failure);
// "[lo, hi]", "(lo, hi)", ...: the interval text CheckIn puts in `allowed`.
std::string IntervalText(double lo, double hi, Ends ends);

}  // namespace bifilar
