// TraceFitOptionsFor (pipeline/trace/trace_process.h): the one mapping of a campaign config to
// the trace fit's settings, per trace role.
#include <cmath>

#include <gtest/gtest.h>

#include "pipeline/trace/trace_process.h"

namespace bifilar {
namespace {

CampaignConfig Configured() {
  CampaignConfig config;
  config.uncertainties.configured = true;
  config.uncertainties.filar_length_std_m = 0.002;
  config.uncertainties.filar_separation_std_m = 0.0005;
  config.uncertainties.mass_std_kg = 0.003;
  config.uncertainties.gravity_std_mps2 = 0.01;
  config.aircraft_mass_std_kg = 0.004;
  config.imu.gyro_scale_std = 0.002;
  config.fit.quality.min_periods = 7.0;
  config.fit.sweep.sweep_max_bands = 5;
  config.fit.max_amplitude_deg = 25.0;
  config.fit.min_amplitude_deg = 3.0;
  return config;
}

TEST(TraceFitOptionsFor, CarriesTheConfigsThresholdsBandAndInputStds) {
  const CampaignConfig config = Configured();
  const TraceFitOptions o = TraceFitOptionsFor(config, TraceRole::kTare);
  EXPECT_EQ(o.model, config.fit.model);
  EXPECT_EQ(o.min_periods, 7.0);
  EXPECT_EQ(o.sweep_max_bands, 5);
  EXPECT_EQ(o.max_amplitude_deg, 25.0);
  EXPECT_EQ(o.min_amplitude_deg, std::fmin(TraceFitOptions().min_amplitude_deg, 3.0));
  EXPECT_EQ(o.filar_length_std_m, 0.002);
  EXPECT_EQ(o.filar_separation_std_m, 0.0005);
  EXPECT_EQ(o.gravity_std_mps2, 0.01);
  EXPECT_EQ(o.mass_std_kg, 0.003);  // the rig's alone: a tare swings no aircraft
  EXPECT_EQ(o.gyro_scale_std, 0.002);
  EXPECT_EQ(o.interrupt, nullptr);
}

TEST(TraceFitOptionsFor, AnAircraftTraceAddsTheAircraftsMassStd) {
  const TraceFitOptions o = TraceFitOptionsFor(Configured(), TraceRole::kAircraft);
  EXPECT_EQ(o.mass_std_kg, std::hypot(0.003, 0.004));
}

TEST(TraceFitOptionsFor, ACalibratedGeometryDropsTheLengthSeparationAndGravityStds) {
  CampaignConfig config = Configured();
  config.geometry_calibration.applied = true;
  const TraceFitOptions o = TraceFitOptionsFor(config, TraceRole::kAircraft);
  EXPECT_EQ(o.filar_length_std_m, 0.0);
  EXPECT_EQ(o.filar_separation_std_m, 0.0);
  EXPECT_EQ(o.gravity_std_mps2, 0.0);
  EXPECT_EQ(o.mass_std_kg, std::hypot(0.003, 0.004));  // the masses are not in k
}

TEST(TraceFitOptionsFor, WithoutUncertaintiesTheAssumedMillimetreOnLAndD) {
  CampaignConfig config;
  const TraceFitOptions o = TraceFitOptionsFor(config, TraceRole::kAircraft);
  EXPECT_EQ(o.filar_length_std_m, kAssumedLengthStdM);
  EXPECT_EQ(o.filar_separation_std_m, kAssumedLengthStdM);
  EXPECT_EQ(o.max_amplitude_deg, kDefaultMaxAmplitudeDeg);
}

}  // namespace
}  // namespace bifilar
