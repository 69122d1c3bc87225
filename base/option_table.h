// An options struct's fields as one table, the way COLMAP's OptionManager registers each option
// once (`AddAndRegisterDefaultOption("Mapper.min_num_matches", &mapper->min_num_matches)`): a
// row holds the field's key in a config file, its C++ name, the member, its bound and what it
// means. From that one table come
//   - the struct's bounds: CheckOptionFields, called by the struct's Check (base/option_check.h
//     messages, naming the C++ field; cross-field bounds stay in the Check's own code);
//   - reading a config section (pipeline/config/config_load.cc: one key per row, the struct's
//     default when the key is absent, unknown keys still refused by the reader);
//   - the config's messages (the row maps a failing field to its key);
//   - a canonical text of the values (SerialiseOptionFields), which the cache key is built from
//     (pipeline/store/cache.cc), so a field added to the table cannot be left out of the key.
// The defaults stay where C++ readers look for them: the members' initialisers.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "base/option_check.h"

namespace bifilar {

// The bound of one field, as base/option_check.h words it.
struct OptionRange {
  enum class Kind { kAny, kIn, kFiniteGt, kFiniteGe };
  Kind kind = Kind::kAny;
  double lo = 0.0, hi = 0.0;
  Ends ends = Ends::kClosed;
};
// lo..hi with the given ends: "in [lo, hi]".
constexpr OptionRange RangeIn(double lo, double hi, Ends ends) {
  return {OptionRange::Kind::kIn, lo, hi, ends};
}
constexpr OptionRange RangeFiniteGt(double lo) {
  return {OptionRange::Kind::kFiniteGt, lo, 0.0, Ends::kOpen};
}
constexpr OptionRange RangeFiniteGe(double lo) {
  return {OptionRange::Kind::kFiniteGe, lo, 0.0, Ends::kClosed};
}
constexpr OptionRange kAnyValue = {};  // no bound of its own (a flag, or a cross-field bound only)

// One field of an options struct `Options`: a double, int or bool member.
template <class Options>
struct OptionField {
  const char* key;    // its key in the struct's config section, e.g. "max_bands"
  const char* field;  // the member's name, as Check names it, e.g. "sweep_max_bands"
  double Options::*real = nullptr;
  int Options::*whole = nullptr;
  bool Options::*flag = nullptr;
  OptionRange range;
  const char* doc = "";  // unit and meaning, one line (the member's comment has the detail)

  OptionField(const char* k, const char* f, double Options::*m, OptionRange r, const char* d)
      : key(k), field(f), real(m), range(r), doc(d) {}
  OptionField(const char* k, const char* f, int Options::*m, OptionRange r, const char* d)
      : key(k), field(f), whole(m), range(r), doc(d) {}
  OptionField(const char* k, const char* f, bool Options::*m, const char* d)
      : key(k), field(f), flag(m), range(kAnyValue), doc(d) {}

  // The value as a double (a flag: 0 or 1).
  double Value(const Options& o) const {
    return real ? o.*real : whole ? static_cast<double>(o.*whole) : (o.*flag ? 1.0 : 0.0);
  }
};

template <class Options>
using OptionFields = std::vector<OptionField<Options>>;

// Every row's bound, in table order: false with the first failing field (its C++ name) in
// *failure.
template <class Options>
bool CheckOptionFields(const Options& o, const OptionFields<Options>& fields,
                       CheckFailure* failure) {
  for (const OptionField<Options>& row : fields) {
    const double v = row.Value(o);
    const OptionRange& r = row.range;
    bool ok = true;
    switch (r.kind) {
      case OptionRange::Kind::kAny:
        break;
      case OptionRange::Kind::kIn:
        ok = CheckIn(row.field, v, r.lo, r.hi, r.ends, failure);
        break;
      case OptionRange::Kind::kFiniteGt:
        ok = CheckFiniteGt(row.field, v, r.lo, failure);
        break;
      case OptionRange::Kind::kFiniteGe:
        ok = CheckFiniteGe(row.field, v, r.lo, failure);
        break;
    }
    if (!ok) return false;
  }
  return true;
}

// The row of C++ field `field`; nullptr when the table has none.
template <class Options>
const OptionField<Options>* FindOptionField(const OptionFields<Options>& fields,
                                            const std::string& field) {
  for (const OptionField<Options>& row : fields) {
    if (field == row.field) return &row;
  }
  return nullptr;
}

// "<section>.<key>=<value>;" for every row in table order: numbers with 17 significant digits
// (they read back to the same double), flags as true/false. Canonical: equal values, equal text.
template <class Options>
std::string SerialiseOptionFields(const std::string& section, const Options& o,
                                  const OptionFields<Options>& fields) {
  std::string out;
  for (const OptionField<Options>& row : fields) {
    char value[40];
    if (row.flag) {
      std::snprintf(value, sizeof(value), "%s", o.*row.flag ? "true" : "false");
    } else {
      std::snprintf(value, sizeof(value), "%.17g", row.Value(o));
    }
    out += section + "." + row.key + "=" + value + ";";
  }
  return out;
}

}  // namespace bifilar
