"""Python as users expect (issue 18 item 7): FileNotFoundError for missing files, short reprs,
the residual's sign as the figures draw it, read_log without a config."""
import errno
import json

import numpy as np
import pytest

import bifilar
from conftest import REPO, SAMPLE_CONFIG, real_data, sample_log

GEOMETRY = dict(length_m=2.0, separation_m=0.9, mass_kg=6.0)


def _missing_raises(call, path):
    """call() raises FileNotFoundError for `path`, naming it; returns the message."""
    with pytest.raises(FileNotFoundError) as error:
        call()
    assert error.value.errno == errno.ENOENT
    assert error.value.filename == str(path)
    assert str(path) in str(error.value)
    assert isinstance(error.value, ValueError)  # `except ValueError` written before still works
    return str(error.value)


def test_every_function_taking_a_path_raises_file_not_found(tmp_path, cli_fit_json):
    missing = tmp_path / "missing.csv"
    message = _missing_raises(lambda: bifilar.read_log(missing, SAMPLE_CONFIG), missing)
    (cli_record,) = cli_fit_json(SAMPLE_CONFIG, [missing])
    assert message == cli_record["message"]  # the command line's words
    _missing_raises(lambda: bifilar.read_log(missing), missing)
    no_config = tmp_path / "none.yaml"
    log = sample_log(10)
    _missing_raises(lambda: bifilar.read_log(log, no_config), no_config)
    _missing_raises(lambda: bifilar.fit_trace([0.0, 1.0], [0.0, 0.0], config=no_config),
                    no_config)
    _missing_raises(lambda: bifilar.process(no_config, out=tmp_path / "out"), no_config)
    _missing_raises(lambda: bifilar.simulate(no_config, out=tmp_path / "sim"), no_config)
    assert not (tmp_path / "out").exists() and not (tmp_path / "sim").exists()


def test_existing_but_bad_files_stay_value_errors(tmp_path):
    broken = tmp_path / "broken.csv"
    broken.write_text("t,gx,gy,gz\n0,0,0,0\n0.01,0,zero,0\n0.02,0,0,0\n")
    with pytest.raises(ValueError) as error:
        bifilar.read_log(broken, SAMPLE_CONFIG)
    assert not isinstance(error.value, FileNotFoundError)
    assert str(broken) in str(error.value)


def test_record_repr_is_a_short_summary():
    log = sample_log(10)
    series = bifilar.read_log(log, SAMPLE_CONFIG)
    result = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, config=str(SAMPLE_CONFIG),
                               name=log)
    text = repr(result)
    # The full record prints every key with nested records and arrays; the summary is a few
    # lines: at most _SUMMARY_CHARS (500) of entries plus the "+N more keys: ..." tail.
    assert len(text) < 700 < len(str(dict(result))), text
    assert text.startswith("Record(file=%r, status='ok', message='', warnings=[], "
                           "inertia_total_kg_m2=" % log), text
    # The whole uncertainty comes before the fit's statistical part alone.
    whole = "inertia_total_std_total_kg_m2=%.6g" % result.inertia_total_std_total_kg_m2
    assert whole in text
    assert text.index(whole) < text.index("inertia_total_std_kg_m2=")
    assert "more keys:" in text
    # Arrays are abbreviated to their shape wherever they appear.
    assert "<array %d>" % series.t_s.size in repr(series)
    assert len(repr(series)) < 700
    assert "[" not in repr(series).split("t_s=")[-1][:20]
    # Nested records and lists are sizes.
    assert "budget={" in text or "budget=" not in text
    # Small records are shown whole.
    assert repr(bifilar.Record(a=1, b="x")) == "Record(a=1, b='x')"


def test_residual_is_measured_minus_fitted_as_in_the_figure():
    # A clean simulated swing with one sample pushed up by 0.05 rad/s (10x the noise): the
    # fit barely moves, so the residual there is about +0.05 (measured above the fit), as
    # the figure's "meas. - fit" panel shows a spike upwards.
    sim = bifilar.simulate(inertia_kg_m2=2.5, mass_kg=6.0, length_m=2.0, separation_m=0.9,
                           amplitude_deg=15, duration_s=40, seed=3)
    t, rate = sim.t_s, sim.gyro_rad_per_s[:, 2].copy()
    clean = bifilar.fit_trace(t, rate, **GEOMETRY)
    inside = np.flatnonzero((t > clean.window_s[0]) & (t < clean.window_s[1]))
    k = inside[inside.size // 2]
    rate[k] += 0.05
    result = bifilar.fit_trace(t, rate, window=tuple(clean.window_s), **GEOMETRY)
    j = int(np.flatnonzero(result.t_s == t[k])[0])
    # The noise (~0.005 rad/s) and the fit's pull towards the spike (1/N of it) stay below
    # 0.02: the sign and size are the spike's.
    assert result.residual_rad_per_s[j] == pytest.approx(0.05, abs=0.02)
    np.testing.assert_allclose(result.residual_rad_per_s,
                               result.measured_rad_per_s - result.fitted_rad_per_s, atol=1e-15)


@pytest.mark.parametrize("pitch", [0, 30])
def test_read_log_without_config_guesses_as_inspect(pitch, cli):
    log = sample_log(pitch)
    with_config = bifilar.read_log(log, SAMPLE_CONFIG)
    guessed = bifilar.read_log(log)
    assert with_config.format_guessed is None
    inspect = json.loads(cli("inspect", log, "--json").stdout)
    inspect = inspect[0] if isinstance(inspect, list) else inspect
    assert guessed.format_guessed == inspect["format"]
    assert guessed.format_guessed.guesses  # says what it guessed
    # The sample config names the same columns and units the guess finds: the same series.
    np.testing.assert_array_equal(guessed.t_s, with_config.t_s)
    np.testing.assert_array_equal(guessed.gyro_rad_per_s, with_config.gyro_rad_per_s)
    np.testing.assert_allclose(np.abs(guessed.rate_rad_per_s),
                               np.abs(with_config.rate_rad_per_s), atol=1e-12)


def test_read_log_without_config_on_a_non_log_says_what_it_is(tmp_path):
    with pytest.raises(ValueError, match="config"):
        bifilar.read_log(SAMPLE_CONFIG)
    blob = tmp_path / "blob.csv"
    blob.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(ValueError, match="binary"):
        bifilar.read_log(blob)


def _inspect(cli, log):
    report = json.loads(cli("inspect", log, "--json").stdout)
    return report[0] if isinstance(report, list) else report


def test_read_log_without_config_reads_a_simulated_ulog_as_inspect(cli, tmp_path):
    spec = (REPO / "configs" / "simulate_prandtl_d.yaml").read_text()
    for old, new in [("pitch_deg: [-80, -70, -60, -50, -40, -30, -20, -10, 0, 10, 20, 30, 40, "
                      "50, 60, 70, 80, 90]", "pitch_deg: [30]"),
                     ("trials_per_pitch: 3", "trials_per_pitch: 1"),
                     ("tare_logs: 3", "tare_logs: 1"), ("free_s: [35, 45]", "free_s: [20, 20]"),
                     ("gzip: true", "gzip: false\n  ulog: true")]:
        assert old in spec, "sample spec changed: " + old
        spec = spec.replace(old, new)
    (tmp_path / "spec.yaml").write_text(spec)
    bifilar.simulate(str(tmp_path / "spec.yaml"), out=str(tmp_path / "sim"))
    (log,) = sorted((tmp_path / "sim").rglob("pitch_30/*.ulg"))
    guessed = bifilar.read_log(log)
    report = _inspect(cli, log)
    assert guessed.format_guessed == report["format"]
    assert guessed.t_s.size == report["samples"]
    # The simulated body pitch is 30 deg; the accelerometer at rest measures it, off by the
    # simulated IMU mounting tilt and noise (29.67 deg with this spec's seed): 1 deg is about
    # three times that error, and far below a wrong axis or unit guess (tens of degrees).
    assert guessed.pitch_measured_deg == pytest.approx(30, abs=1.0)


@pytest.mark.realdata
def test_read_log_without_config_reads_a_real_px4_ulog(cli):
    log = real_data("px4/sample_log_small.ulg")
    guessed = bifilar.read_log(log)
    report = _inspect(cli, log)
    assert guessed.format_guessed == report["format"]
    assert guessed.format_guessed.ulog_topic == "sensor_combined"
    assert guessed.t_s.size == report["samples"]
