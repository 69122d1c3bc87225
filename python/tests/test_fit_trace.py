"""fit_trace and read_log against `bifilar fit --json` on the sample, and against known truth."""
import threading
import time

import numpy as np
import pytest

import bifilar
from conftest import SAMPLE_CONFIG, sample_log, without_timings

# Series arrays fit_trace adds to the CLI's record.
SERIES = ("t_s", "measured_rad_per_s", "fitted_rad_per_s", "residual_rad_per_s")
# Record fields that need the whole 3-axis log (accelerometer, other gyro axes), which a swing
# rate alone does not carry: read_log gives the pitch and the axis instead.
LOG_ONLY = ("pitch_measured_deg", "roll_measured_deg", "swing_axis_in_imu",
            "secondary_motion_ratio")


def python_fit(log, **settings):
    series = bifilar.read_log(log, SAMPLE_CONFIG)
    result = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, config=str(SAMPLE_CONFIG),
                               name=log, **settings)
    return series, result


@pytest.mark.parametrize("pitch", [10, -60, 90])
def test_fit_trace_gives_the_cli_numbers_exactly(pitch, cli_fit_json):
    log = sample_log(pitch)
    (cli_record,) = cli_fit_json(SAMPLE_CONFIG, [log])
    series, result = python_fit(log)
    python_record = {k: v for k, v in result.items() if k not in SERIES}
    assert set(python_record) == set(cli_record)  # same fields as `bifilar fit --json`
    assert series.pitch_measured_deg == cli_record["pitch_measured_deg"]
    assert series.roll_measured_deg == cli_record["roll_measured_deg"]
    assert python_record["pitch_measured_deg"] is None
    if "swing_axis_in_imu" in cli_record:
        assert series.axis_in_imu == cli_record["swing_axis_in_imu"]
    for key in LOG_ONLY:
        python_record.pop(key, None)
        cli_record.pop(key, None)
    # Same numbers to the last bit (JSON of a double round-trips exactly).
    assert without_timings(python_record) == without_timings(cli_record)
    assert cli_record["status"] == "ok"


def test_window_and_model_options_match_the_cli(cli_fit_json):
    log = sample_log(20, 2)
    (cli_record,) = cli_fit_json(SAMPLE_CONFIG, [log], "--window", "12:30", "--model", "jardin")
    _, result = python_fit(log, window=(12, 30), model="jardin")
    assert result.model == "jardin"
    assert result.window_s == cli_record["window_s"]
    assert result.inertia_total_kg_m2 == cli_record["inertia_total_kg_m2"]
    _, same = python_fit(log, window="12:30", model="jardin")
    assert same.inertia_total_kg_m2 == cli_record["inertia_total_kg_m2"]


def test_keywords_alone_match_the_config():
    log = sample_log(40)
    series, from_config = python_fit(log)
    # configs/prandtl_d.yaml: L 2.0, D 1.8, aircraft 5.5 kg + rig 1.25 kg, band up to 30 deg.
    from_keywords = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, length_m=2.0,
                                      separation_m=1.8, mass_kg=5.5 + 1.25, max_amplitude_deg=30)
    assert from_keywords.inertia_total_kg_m2 == from_config.inertia_total_kg_m2
    assert from_keywords.inertia_total_std_kg_m2 == from_config.inertia_total_std_kg_m2
    # No uncertainties given: the total counts the assumed +-1 mm on L and D, and says so.
    assert from_keywords.uncertainty["configured_inputs_assumed"]
    assert set(from_keywords.budget.keys()) == {"filar_length_kg_m2", "filar_separation_kg_m2",
                                                "total_kg_m2"}
    assert from_keywords.inertia_total_std_total_kg_m2 > from_keywords.inertia_total_std_kg_m2
    # Explicit zeros replace the assumption.
    zeros = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, length_m=2.0, separation_m=1.8,
                              mass_kg=5.5 + 1.25, max_amplitude_deg=30, length_std_m=0.0,
                              separation_std_m=0.0)
    assert zeros.budget.total_kg_m2 == 0.0
    assert zeros.inertia_total_std_total_kg_m2 == pytest.approx(zeros.inertia_total_std_kg_m2,
                                                                rel=1e-12)


def test_series_are_the_fitted_window():
    log = sample_log(0)
    series, result = python_fit(log)
    t0, t1 = result.window_s
    inside = (series.t_s >= t0) & (series.t_s <= t1)
    np.testing.assert_array_equal(result.t_s, series.t_s[inside])
    np.testing.assert_array_equal(result.measured_rad_per_s, series.rate_rad_per_s[inside])
    # residual = fitted - measured; its RMS is the record's.
    np.testing.assert_allclose(result.residual_rad_per_s,
                               result.fitted_rad_per_s - result.measured_rad_per_s, atol=1e-15)
    rms = np.sqrt(np.mean(result.residual_rad_per_s ** 2))
    assert rms == pytest.approx(result.residual_rms_rad_per_s, rel=1e-9)


def test_known_inertia_from_a_simulated_trace():
    # Pitch 0 with the IMU axes on the body's: the swing rate is the z gyro.
    truth_inertia = 2.5
    sim = bifilar.simulate(inertia_kg_m2=truth_inertia, mass_kg=6.0, length_m=2.0,
                           separation_m=0.9, amplitude_deg=15, duration_s=40, seed=7)
    (truth,) = sim.truth.traces
    assert truth.inertia_total_kg_m2 == truth_inertia and truth.file is None
    result = bifilar.fit_trace(sim.t_s, sim.gyro_rad_per_s[:, 2], length_m=2.0,
                               separation_m=0.9, mass_kg=6.0)
    assert result.status == "ok", result.message
    # 5 sigma of the fit's own statistical std (0.25 deg/s white gyro noise, full model truth).
    assert abs(result.inertia_total_kg_m2 - truth_inertia) < 5 * result.inertia_total_std_kg_m2


def test_noise_alone_is_rejected_with_a_reason_not_an_exception():
    rng = np.random.default_rng(3)
    t = np.arange(3000) * 0.01
    result = bifilar.fit_trace(t, 0.004 * rng.standard_normal(t.size), length_m=2.0,
                               separation_m=0.9, mass_kg=6.0, name="noise.csv")
    assert result.status == "rejected"
    assert "noise.csv" in result.message
    assert result.inertia_total_kg_m2 is None  # never NaN
    assert result.fitted_rad_per_s.size == 0


def test_the_gil_is_released_during_the_fit():
    # A long trace (~0.1 s fit). With the GIL held by the fit, the main thread could only run
    # after it returned; released, it runs while the fit is still going. Three tries absorb a
    # machine too busy to schedule the main thread within the fit.
    sim = bifilar.simulate(inertia_kg_m2=2.5, mass_kg=6.0, length_m=2.0, separation_m=0.9,
                           amplitude_deg=15, duration_s=240, seed=2)
    rate = sim.gyro_rad_per_s[:, 2]
    for _ in range(3):
        started, times = threading.Event(), {}

        def work():
            started.set()
            bifilar.fit_trace(sim.t_s, rate, length_m=2.0, separation_m=0.9, mass_kg=6.0)
            times["fit_end"] = time.perf_counter()

        worker = threading.Thread(target=work)
        worker.start()
        started.wait()
        times["main"] = time.perf_counter()
        worker.join()
        if times["main"] < times["fit_end"] - 0.01:
            return
    pytest.fail("the main thread never ran while fit_trace worked: the GIL is held")


def test_concurrent_fits_give_the_same_numbers():
    log = sample_log(30)
    series, reference = python_fit(log)
    results = [None] * 4

    def work(i):
        results[i] = bifilar.fit_trace(series.t_s, series.rate_rad_per_s,
                                       config=str(SAMPLE_CONFIG), name=log)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for result in results:
        assert result.inertia_total_kg_m2 == reference.inertia_total_kg_m2
