// `bifilar init`: a commented starting config. The rig (L, D, mass) comes from the caller
// (`--rig L,D,MASS` or questions on a terminal); the log format from a log as `inspect` guesses
// it (pipeline/commands/log_inspect.h), or the defaults. The text it writes is accepted by `bifilar
// fit` as it stands, and names, commented out, the sections a campaign (`bifilar process`) adds.
#pragma once

#include <optional>
#include <string>

#include "base/units.h"
#include "pipeline/logs/imu_format.h"

namespace bifilar {
struct CampaignConfig;
}  // namespace bifilar

namespace bifilar {

struct StartingConfigOptions {
  double filar_length_m = 0.0;      // L (m); > D
  double filar_separation_m = 0.0;  // D (m); > 0
  double mass_kg = 0.0;             // everything that hangs (rig + aircraft) for a first fit (kg)
  double gravity_mps2 = kStandardGravityMps2;  // local gravity (m/s^2)
  // The format of the logs; none: the reader's defaults (t, gx/gy/gz rad/s, ax/ay/az m/s^2).
  std::optional<ImuFormat> format;
  bool ulog = false;          // the format is a ULog topic, not CSV columns
  std::string format_source;  // the log the format was guessed from, quoted in a comment

  bool Check(std::string* why) const;
};

// The YAML text of the starting config. Every string in it (column, topic and field names, the
// log's name) is a double-quoted YAML scalar with anything that could end it or start a line
// escaped, so no name can add a key (issue 23).
std::string StartingConfigText(const StartingConfigOptions& options);

// The config init writes at `path`, checked before anything is written: the text is loaded with
// the loader `fit` uses (LoadCampaignConfigText, pipeline/config/config.h: one set of bounds), and
// the log format read back must be the one meant (a name no YAML scalar carries intact is refused).
// Names are bounded (kMaxStartingConfigNameBytes: a 4 MB header cell would make a config over the
// loader's size cap). Throws UserError "init: <path>: the config it would write is one `bifilar
// fit` rejects: <the loader's message>". `loaded` (optional) receives the config read back.
std::string CheckedStartingConfigText(const StartingConfigOptions& options, const std::string& path,
                                      CampaignConfig* loaded = nullptr);

// The longest column, topic or field name init writes (bytes). Loggers name columns in a few
// dozen bytes; a longer cell is a broken header, refused with its length.
constexpr size_t kMaxStartingConfigNameBytes = 256;

// Parses "L,D,MASS" (m, m, kg) as given to `--rig`; false with *why otherwise.
bool ParseRigSpec(const std::string& text, StartingConfigOptions* options, std::string* why);

}  // namespace bifilar
