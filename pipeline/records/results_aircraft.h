// Reading results.json's `aircraft` section (written by ResultsToJson, results_json.cc), apart
// from results_json.h so that readers (export) need no campaign or fit types.
#pragma once

#include <nlohmann/json.hpp>

namespace bifilar {

// The aircraft mass that ResultsToJson writes (`aircraft`: {mass_kg, mass_std_kg}, null without
// an `aircraft` section; mass_std_kg null when the config did not give it). Returns false when
// the file has no `aircraft` key (written before it existed: read the stored config instead);
// otherwise true with the values, NaN where null.
bool AircraftMassFromResultsJson(const nlohmann::json& results, double* mass_kg,
                                 double* mass_std_kg);

}  // namespace bifilar
