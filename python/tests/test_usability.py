"""Python as users expect (issue 18 item 7): FileNotFoundError for missing files, short reprs,
the residual's sign as the figures draw it, read_log without a config."""
import errno
import json

import numpy as np
import pytest

import bifilar
from conftest import REPO, SAMPLE_CONFIG, sample_log

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
