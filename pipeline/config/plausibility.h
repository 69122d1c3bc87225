// Units and plausibility (issue 16 item 3): config values no lab rig can have are errors that name
// the key and the unit the value was probably written in; fits whose amplitude or radius of
// gyration does not fit the stated rig give warnings naming the keys to check; a log with "no
// oscillation found" is tried with its time scaled by 1000 and 1/1000 to suggest imu.time.unit.
// The bounds and their reasoning are in configs/README.md ("Plausibility bounds") and
// docs/method.md; the physics behind them in docs/physics.md §2.
//
// All values SI (m, kg, kg m^2, s, deg where the name says so).
#pragma once

#include <string>
#include <vector>

#include "fit/window.h"
#include "pipeline/logs/imu_format.h"

namespace bifilar {

// Wire length L (m). Rigs swing (with the radius of gyration near D/2, below) at about the period
// of a simple pendulum of length L, 2 pi sqrt(L/g); the window finder looks for periods in
// [0.3, 10] s (fit/window.h), i.e. L in [0.02, 25] m. 5 cm is shorter than any thread rig (the
// quadrotor's is 0.594 m); 20 m is above the hook height of a high-bay hangar.
constexpr double kMinFilarLengthM = 0.05, kMaxFilarLengthM = 20.0;
// Wire separation D (m): 5 mm (a thread rig for a few-gram body; the quadrotor's is 30 mm) to 5 m
// (a rig for a large aircraft spans ~its fuselage or wing root; D must also stay below L).
constexpr double kMinFilarSeparationM = 0.005, kMaxFilarSeparationM = 5.0;
// Suspended mass (kg), rig + aircraft: at least 0.1 g, where a thin thread's own torsional
// stiffness (G pi r^4 / 2L ~ 3e-7 N m/rad for 0.1 mm nylon on 0.6 m) reaches the bifilar's
// gravity stiffness m g D^2 / 4L for D = 30 mm; at most 1000 kg (each wire then holds ~5 kN;
// heavier aircraft go on mass-properties machines or compound pendulums, not a lab bifilar). Each
// of rig.mass_kg and aircraft.mass_kg is at most kMaxMassKg as well.
constexpr double kMinSuspendedMassKg = 1e-4, kMaxMassKg = 1000.0;
// Rig inertia (rig.inertia.inertia_kg_m2 and table values): the rig's radius of gyration
// sqrt(I_rig / m_rig) at most kMaxRigGyrationOverSeparation * D. A rig is about as wide as the
// aircraft it holds, and D about as wide as the rig; a uniform bar of length l has r = l/sqrt(12),
// so r = 5 D is a rig 17 times wider than its wires are apart.
constexpr double kMaxRigGyrationOverSeparation = 5.0;

// The fit's radius of gyration r = sqrt(I/m) against the wire half-separation D/2: warn outside
// [1/kGyrationFactor, kGyrationFactor]. From I = m g D^2 T^2 / (16 pi^2 L) (docs/physics.md §2),
// r / (D/2) = T / (2 pi sqrt(L/g)): the period over that of a simple pendulum of length L. D and m
// cancel, so the check tests L, g and the time base. Real rigs: 0.5-2.3 (quadrotor logs 1.4-2.3,
// the fixed-wing preset 1.1-1.5, the sample campaign 0.5-0.8); 5 is twice beyond them on each side.
constexpr double kGyrationFactor = 5.0;
// A largest fitted amplitude below this (deg) warns: hand releases are 5-60 deg, and a gyro that
// logs rad/s declared deg/s reads 57 times too small.
constexpr double kMinPlausibleAmplitudeDeg = 1.0;

// Empty when `value` (SI, named by `key`, e.g. "rig.filar_length_m") lies in [min, max];
// otherwise "'key': 594 m is longer than any lab rig (0.05-20 m): if this is in mm, write 0.594;
// if in cm, 5.94". `quantity` chooses the units tried: "length" (mm, cm, in, ft), "mass" (g, lb).
std::string ImplausibleValue(const std::string& key, const char* quantity, double value, double min,
                             double max);

// Empty when the rig inertia `inertia_kg_m2` (named by `key`) is plausible for the rig mass and
// separation (kMaxRigGyrationOverSeparation); otherwise the message with the likely unit (kg cm^2,
// kg mm^2, g cm^2, lb in^2, slug ft^2).
std::string ImplausibleRigInertia(const std::string& key, double inertia_kg_m2, double rig_mass_kg,
                                  double filar_separation_m);

// Empty when L > D; otherwise the message naming rig.filar_separation_m and, when D read in cm or
// mm would fit below L, that unit.
std::string SeparationNotBelowLength(double filar_length_m, double filar_separation_m);

// Warnings for a fitted trace: the largest amplitude below kMinPlausibleAmplitudeDeg (names
// imu.gyro.unit), sqrt(I/m) outside [1/kGyrationFactor, kGyrationFactor] x D/2 (names
// rig.filar_length_m and imu.time.unit). Empty when both are plausible.
std::vector<std::string> FitPlausibilityWarnings(double inertia_kg_m2, double mass_kg,
                                                 double filar_separation_m, double filar_length_m,
                                                 double amplitude_deg, RateUnit gyro_unit);

// A bifilar's wires cross at a twist of 180 deg, so no swing exceeds it: a larger amplitude read
// from the gyro (the largest extreme of the free-oscillation window, deg) is a gyro unit or
// column mistake. Returns the sentence naming imu.gyro.unit (with the amplitudes deg/s would
// give when rad/s was declared), or empty when `largest_amplitude_deg` <= kMaxSwingAmplitudeDeg.
constexpr double kMaxSwingAmplitudeDeg = 180.0;
std::string ImpossibleAmplitude(double largest_amplitude_deg, double smallest_amplitude_deg,
                                RateUnit gyro_unit);

// When no oscillation was found on (t_s, rate): whether one appears with the time scaled by 1000
// or by 1/1000, and if so the sentence suggesting imu.time.unit (the unit that would give that
// scale, from `declared`); empty otherwise.
std::string TimeUnitHint(const std::vector<double>& t_s, const std::vector<double>& rate_rad_per_s,
                         const WindowOptions& options, TimeUnit declared);

}  // namespace bifilar
