// `bifilar simulate`'s truth writer: the truth.json of a campaign (geometry, aircraft and its
// tensor, rig, campaign plan, options, every trace's true values) and of a single trace, the
// numbers a fit of the simulated logs is scored against.
#include <Eigen/Eigenvalues>
#include <cmath>

#include <nlohmann/json.hpp>

#include "base/units.h"
#include "base/version.h"
#include "pendulum/model.h"
#include "pipeline/commands/simulate_spec.h"
#include "pipeline/commands/simulate_spec_steps.h"

namespace bifilar {
namespace {

nlohmann::json Vec(const Eigen::Vector3d& v, double scale = 1.0) {
  return nlohmann::json::array({v[0] * scale, v[1] * scale, v[2] * scale});
}

nlohmann::json Range(const UniformRange& r) { return nlohmann::json::array({r.min, r.max}); }

nlohmann::json OptionsJson(const SimulateSpec& spec) {
  const SimulationOptions& o = spec.options;
  const TimelineOptions& t = o.timeline;
  const SensorOptions& s = o.sensor;
  nlohmann::json j;
  j["model"] = ToString(o.model);
  j["integrator"] = ToString(o.integrator.method);
  j["integrator_rel_tol"] = o.integrator.rel_tol;
  j["integrator_abs_tol"] = o.integrator.abs_tol;
  j["sway_coupling_percent_at_60deg"] = 100.0 * o.sway_coupling_at_60deg;
  j["negative_amplitude_probability"] = o.negative_amplitude_probability;
  j["timeline"] = {{"rest_before_s", Range(t.rest_before_s)},
                   {"twist_s", Range(t.twist_s)},
                   {"hold_s", Range(t.hold_s)},
                   {"tremor_deg", t.tremor_deg},
                   {"tremor_hz", Range(t.tremor_hz)},
                   {"release_rate_sigma_deg_per_s", t.release_rate_sigma_deg_per_s},
                   {"free_s", Range(t.free_s)},
                   {"stop_probability", t.stop_probability},
                   {"stop_time_constant_s", t.stop_time_constant_s},
                   {"rest_after_s", Range(t.rest_after_s)}};
  j["sensor"] = {{"sample_rate_hz", s.sample_rate_hz},
                 {"time_jitter_sigma_s", s.time_jitter_sigma_s},
                 {"drop_fraction", s.drop_fraction},
                 {"drop_burst_probability", s.drop_burst_probability},
                 {"drop_burst_max_samples", s.drop_burst_max_samples},
                 {"start_time_s", Range(s.start_time_s)},
                 {"gyro_noise_sigma_deg_per_s", s.gyro_noise_sigma_deg_per_s},
                 {"gyro_bias_sigma_deg_per_s", s.gyro_bias_sigma_deg_per_s},
                 {"gyro_scale_error_sigma", s.gyro_scale_error_sigma},
                 {"accelerometer", s.accelerometer},
                 {"accel_noise_sigma_mps2", s.accel_noise_sigma_mps2},
                 {"accel_bias_sigma_mps2", s.accel_bias_sigma_mps2},
                 {"rocking_max_deg", s.rocking_max_deg},
                 {"rocking_frequency_hz", s.rocking_frequency_hz},
                 {"rocking_decay_s", s.rocking_decay_s}};
  // Realism settings are recorded when they are on (absent = off), so that a spec without them
  // gives the same truth.json bytes as before they existed.
  const SensorOptions off;
  if (s.sample_steps != off.sample_steps) {
    j["sensor"]["sample_steps"] = ToString(s.sample_steps);
    j["sensor"]["step_median_s"] = 1.0 / s.sample_rate_hz;
    j["sensor"]["step_log_sigma"] = s.step_log_sigma;
    j["sensor"]["step_range_s"] = Range(s.step_range_s);
  }
  if (s.gyro_noise_ar1_phi != off.gyro_noise_ar1_phi) {
    j["sensor"]["gyro_noise_ar1_phi"] = s.gyro_noise_ar1_phi;
  }
  if (s.gyro_bias_walk_deg_per_s_per_sqrt_s != off.gyro_bias_walk_deg_per_s_per_sqrt_s) {
    j["sensor"]["gyro_bias_walk_deg_per_s_per_sqrt_s"] = s.gyro_bias_walk_deg_per_s_per_sqrt_s;
  }
  if (s.spike_count != off.spike_count) {
    j["sensor"]["spike_count"] = s.spike_count;
    j["sensor"]["spike_rate_rad_per_s"] = s.spike_rate_rad_per_s;
  }
  if (s.accelerometer && s.accel_gravity_removed) {
    j["sensor"]["accelerometer"] = "gravity_removed";
    j["sensor"]["gravity_removal_error_deg"] = Range(s.gravity_removal_error_deg);
  }
  if (o.softening_at_30deg > 0) {
    j["softening_percent_at_30deg"] = 100.0 * o.softening_at_30deg;
    j["softening_exponent"] = o.softening_exponent;
    j["softening_k_per_rad_p"] = SofteningCoefficient(o.softening_at_30deg, o.softening_exponent);
    j["softening_harmonic_constant"] = SofteningHarmonicConstant(o.softening_exponent);
  }
  const ImuFormat& f = spec.format;
  j["format"] = {
      {"time_column", f.time_column},
      {"time_unit", ToString(f.time_unit)},
      {"gyro_columns", f.gyro_columns},
      {"gyro_unit", ToString(f.gyro_unit)},
      {"accel_columns", f.has_accel() && s.accelerometer ? nlohmann::json(f.accel_columns)
                                                         : nlohmann::json::array()},
      {"accel_unit", ToString(f.accel_unit)},
      {"delimiter", std::string(1, f.delimiter)},
      {"significant_digits", spec.write.significant_digits},
      {"gzip", spec.gzip}};
  if (spec.footer) j["format"]["footer"] = true;
  return j;
}

nlohmann::json TraceJson(const CampaignTrace& ct, const SimulateSpec& spec) {
  const TraceTruth& t = ct.trace.truth;
  const TraceSetup& s = ct.setup;
  const SensorOptions& so = spec.options.sensor;
  nlohmann::json j;
  j["file"] = ct.relative_path;
  j["kind"] = ct.is_calibration ? "calibration" : ct.is_tare ? "tare" : "aircraft";
  if (ct.is_calibration) j["inertia_reference_kg_m2"] = ct.inertia_reference_kg_m2;
  j["trial"] = ct.trial;
  j["nominal_pitch_deg"] = ct.nominal_pitch_deg;
  j["true_pitch_deg"] = ct.true_pitch_deg;
  if (!spec.campaign.attitudes_deg.empty()) {
    j["nominal_roll_deg"] = ct.nominal_roll_deg;
    j["true_roll_deg"] = ct.true_roll_deg;
    const double p = ct.true_pitch_deg * kRadPerDeg, r = ct.true_roll_deg * kRadPerDeg;
    j["swing_axis_in_body"] =
        Vec(Eigen::Vector3d(-std::sin(p), std::sin(r) * std::cos(p), std::cos(r) * std::cos(p)));
  }
  j["mass_kg"] = s.geometry.mass_kg;
  j["inertia_total_kg_m2"] = s.params.inertia_kg_m2;
  j["inertia_aircraft_kg_m2"] = ct.inertia_aircraft_kg_m2;
  j["inertia_rig_kg_m2"] = ct.inertia_rig_kg_m2;
  j["drag_coeff_kg_m2"] = s.params.drag_coeff_kg_m2;
  j["viscous_coeff_kg_m2_per_s"] = s.params.viscous_coeff_kg_m2_per_s;
  j["small_angle_period_s"] = SmallAnglePeriod(s.geometry, s.params.inertia_kg_m2);
  j["amplitude_deg"] = t.amplitude_rad / kRadPerDeg;
  j["release_rate_deg_per_s"] = t.release_rate_rad_per_s / kRadPerDeg;
  j["amplitude_at_end_deg"] = t.amplitude_at_stop_rad / kRadPerDeg;
  j["start_time_s"] = t.start_time_s;
  j["t_twist_s"] = t.t_twist_s;
  j["t_release_s"] = t.t_release_s;
  j["stopped_by_hand"] = t.stopped;
  j["t_stop_s"] = t.stopped ? nlohmann::json(t.t_stop_s) : nlohmann::json(nullptr);
  j["t_free_end_s"] = t.t_stop_s;
  j["t_end_s"] = t.t_end_s;
  j["samples"] = ct.trace.imu.size();
  j["samples_nominal"] = t.samples_nominal;
  j["samples_dropped"] = t.samples_dropped;
  j["free_samples"] = t.free_samples;
  j["swing_axis_in_imu"] = Vec(t.swing_axis_in_imu);
  j["gyro_bias_deg_per_s"] = Vec(t.gyro_bias_rad_per_s, 1.0 / kRadPerDeg);
  j["gyro_scale_error"] = Vec(t.gyro_scale_error);
  j["gyro_noise_sigma_deg_per_s"] = so.gyro_noise_sigma_deg_per_s;
  if (so.accelerometer) {
    j["accel_bias_mps2"] = Vec(t.accel_bias_mps2);
    j["accel_noise_sigma_mps2"] = so.accel_noise_sigma_mps2;
  }
  j["rocking_amplitude_deg"] = t.rocking_amplitude_rad / kRadPerDeg;
  j["rocking_frequency_hz"] = t.rocking_frequency_hz;
  j["rocking_axis_in_body"] = Vec(t.rocking_axis_in_body);
  // Realism, recorded when on (see OptionsJson).
  if (so.gyro_bias_walk_deg_per_s_per_sqrt_s > 0) {
    j["gyro_bias_end_deg_per_s"] = Vec(t.gyro_bias_end_rad_per_s, 1.0 / kRadPerDeg);
  }
  if (so.gyro_noise_ar1_phi > 0) j["gyro_noise_ar1_phi"] = so.gyro_noise_ar1_phi;
  if (so.accelerometer && so.accel_gravity_removed) {
    j["accelerometer"] = "gravity_removed";
    j["gravity_removal_error_deg"] = t.gravity_removal_error_rad / kRadPerDeg;
  }
  if (!t.spikes.empty()) {
    nlohmann::json spikes = nlohmann::json::array();
    for (const auto& spike : t.spikes) {
      spikes.push_back({{"sample", spike.sample},
                        {"t_s", spike.t_s},
                        {"axis", std::string(1, "xyz"[spike.axis])},
                        {"column", spec.format.gyro_columns[spike.axis]},
                        {"rate_rad_per_s", spike.rate_rad_per_s}});
    }
    j["spikes"] = spikes;
  }
  if (t.softening_k > 0) {
    // What a fit of the ideal model would find at the release amplitude (harmonic balance); the
    // true inertia stays inertia_total_kg_m2 (the small-amplitude limit).
    const double p = spec.options.softening_exponent;
    j["softening_k_per_rad_p"] = t.softening_k;
    j["apparent_inertia_excess_at_release"] =
        ApparentInertiaExcess(t.softening_k, p, t.amplitude_rad);
    j["apparent_inertia_at_release_kg_m2"] =
        s.params.inertia_kg_m2 * (1.0 + ApparentInertiaExcess(t.softening_k, p, t.amplitude_rad));
  }
  if (spec.footer) j["footer_rows"] = kSimulateFooterRows;
  return j;
}

}  // namespace

std::string CampaignTruthJson(const SimulateSpec& spec, const std::vector<CampaignTrace>& traces) {
  const CampaignSpec& c = spec.campaign;
  nlohmann::json j;
  j["generator"] = std::string("bifilar simulate ") + ProgramVersion();
  j["seed"] = spec.seed;
  j["spec"] = spec.file;
  j["geometry"] = {{"filar_length_m", c.filar_length_m},
                   {"filar_separation_m", c.filar_separation_m},
                   {"gravity_mps2", c.gravity_mps2}};
  // A mis-measured rig: the logs follow the true geometry, a user measured the one above.
  if (c.true_filar_length_m > 0 || c.true_filar_separation_m > 0) {
    j["geometry"]["true_filar_length_m"] = c.TrueLengthM();
    j["geometry"]["true_filar_separation_m"] = c.TrueSeparationM();
    j["geometry"]["true_d2_over_l_factor"] =
        (c.TrueSeparationM() * c.TrueSeparationM() / c.TrueLengthM()) /
        (c.filar_separation_m * c.filar_separation_m / c.filar_length_m);
  }
  if (c.calibration_logs > 0) {
    j["calibration"] = {{"logs", c.calibration_logs},
                        {"reference_inertia_kg_m2", c.reference_inertia_kg_m2},
                        {"reference_mass_kg", c.reference_mass_kg},
                        {"rig_pitch_deg", c.tare_pitch_deg},
                        {"amplitude_deg", Range(c.calibration_amplitude_deg)}};
  }
  const double tau = c.aircraft.PrincipalInclinationRad();
  j["aircraft"] = {{"mass_kg", c.aircraft.mass_kg},
                   {"ix_kg_m2", c.aircraft.ix_kg_m2},
                   {"iz_kg_m2", c.aircraft.iz_kg_m2},
                   {"ixz_kg_m2", c.aircraft.ixz_kg_m2},
                   {"tau_deg", tau / kRadPerDeg},
                   {"ix_slug_ft2", c.aircraft.ix_kg_m2 / kKgM2PerSlugFt2},
                   {"iz_slug_ft2", c.aircraft.iz_kg_m2 / kKgM2PerSlugFt2},
                   {"ixz_slug_ft2", c.aircraft.ixz_kg_m2 / kKgM2PerSlugFt2}};
  // Principal moments: I(theta) at theta = tau (z principal) and tau + 90 deg (x principal).
  j["aircraft"]["izp_kg_m2"] = c.aircraft.InertiaAtPitch(tau);
  j["aircraft"]["ixp_kg_m2"] = c.aircraft.InertiaAtPitch(tau + kPi / 2);
  nlohmann::json rig = {{"mass_kg", c.rig.mass_kg},
                        {"imu_mass_kg", c.rig.imu_mass_kg},
                        {"imu_offset_m", Vec(c.rig.imu_offset_in_body_m)},
                        {"tare_logs", c.tare_logs},
                        {"tare_pitch_deg", c.tare_pitch_deg},
                        {"tare_damping_scale", c.tare_damping_scale}};
  if (c.rig.inertia_by_pitch_kg_m2.empty()) {
    rig["inertia_kg_m2"] = c.rig.inertia_kg_m2;
  } else {
    nlohmann::json table = nlohmann::json::object();
    for (const auto& e : c.rig.inertia_by_pitch_kg_m2) table[FormatPitchDeg(e.first)] = e.second;
    rig["inertia_by_pitch_kg_m2"] = table;
  }
  nlohmann::json mounting = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    mounting.push_back(
        {c.rig.body_from_imu(r, 0), c.rig.body_from_imu(r, 1), c.rig.body_from_imu(r, 2)});
  }
  rig["body_from_imu"] = mounting;
  j["rig"] = rig;
  if (c.aircraft.HasTensor()) {
    // The whole tensor (docs/physics.md §3.5; products positive, the tensor holds -Ixy ...).
    const Eigen::Matrix3d tensor = c.aircraft.Tensor();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(tensor);
    nlohmann::json axes = nlohmann::json::array();
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d axis = eig.eigenvectors().col(k);
      int largest = 0;
      axis.cwiseAbs().maxCoeff(&largest);
      if (axis(largest) < 0) axis = -axis;
      axes.push_back(Vec(axis));
    }
    j["aircraft"]["iy_kg_m2"] = c.aircraft.iy_kg_m2;
    j["aircraft"]["ixy_kg_m2"] = c.aircraft.ixy_kg_m2;
    j["aircraft"]["iyz_kg_m2"] = c.aircraft.iyz_kg_m2;
    j["aircraft"]["tensor"] = {{"Ixx_kg_m2", c.aircraft.ix_kg_m2},
                               {"Iyy_kg_m2", c.aircraft.iy_kg_m2},
                               {"Izz_kg_m2", c.aircraft.iz_kg_m2},
                               {"Ixy_kg_m2", c.aircraft.ixy_kg_m2},
                               {"Ixz_kg_m2", c.aircraft.ixz_kg_m2},
                               {"Iyz_kg_m2", c.aircraft.iyz_kg_m2},
                               {"tensor_kg_m2",
                                {Vec(tensor.row(0).transpose()), Vec(tensor.row(1).transpose()),
                                 Vec(tensor.row(2).transpose())}},
                               {"principal_moments_kg_m2", Vec(eig.eigenvalues())},
                               {"principal_axes", axes}};
  }
  j["campaign"] = {{"pitch_deg", c.pitch_deg},
                   {"trials_per_pitch", c.trials_per_pitch},
                   {"pitch_error_sigma_deg", c.pitch_error_sigma_deg},
                   {"amplitude_deg", Range(c.amplitude_deg)},
                   {"drag_coeff_kg_m2", Range(c.drag_coeff_kg_m2)},
                   {"viscous_coeff_kg_m2_per_s", Range(c.viscous_coeff_kg_m2_per_s)}};
  if (!c.attitudes_deg.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& a : c.attitudes_deg) list.push_back({a[0], a[1]});
    j["campaign"]["attitudes_deg"] = list;
    j["campaign"]["roll_error_sigma_deg"] = c.roll_error_sigma_deg;
  }
  j["options"] = OptionsJson(spec);
  nlohmann::json list = nlohmann::json::array();
  for (const auto& ct : traces) list.push_back(TraceJson(ct, spec));
  j["traces"] = list;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string TraceTruthJson(const SimulateSpec& spec, const CampaignTrace& ct,
                           const std::string& csv_path) {
  const TraceRequest& r = spec.trace;
  nlohmann::json j;
  j["generator"] = std::string("bifilar simulate ") + ProgramVersion();
  j["seed"] = spec.seed;
  j["spec"] = spec.file;
  j["geometry"] = {{"filar_length_m", *r.filar_length_m},
                   {"filar_separation_m", *r.filar_separation_m},
                   {"gravity_mps2", r.gravity_mps2}};
  j["imu_offset_m"] = Vec(r.imu_offset_m);
  j["imu_mounting_rpy_deg"] = Vec(r.imu_mounting_rpy_deg);
  j["options"] = OptionsJson(spec);
  nlohmann::json trace = TraceJson(ct, spec);
  trace.erase("inertia_aircraft_kg_m2");
  trace.erase("inertia_rig_kg_m2");
  trace.erase("kind");
  trace["file"] = csv_path;
  j["traces"] = nlohmann::json::array({trace});
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace bifilar
