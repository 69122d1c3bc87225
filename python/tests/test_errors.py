"""Bad input: ValueError naming the argument, or the command line's own message; no crash."""
import json

import numpy as np
import pytest

import bifilar
from conftest import REPO, SAMPLE_CONFIG, sample_log

GEOMETRY = dict(length_m=2.0, separation_m=0.9, mass_kg=6.0)


def cli_error(done):
    """The message `bifilar` prints for a usage or config error (exit code 2)."""
    assert done.returncode == 2, done.stdout + done.stderr
    prefix = "bifilar: error: "
    assert done.stderr.startswith(prefix)
    return done.stderr[len(prefix):].strip()


def test_arrays_of_different_lengths_name_both():
    with pytest.raises(ValueError, match=r"t and rate have different lengths \(10 and 9\)"):
        bifilar.fit_trace(np.arange(10.0), np.zeros(9), **GEOMETRY)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_names_the_argument_and_index(bad):
    rate = np.zeros(10)
    rate[4] = bad
    with pytest.raises(ValueError, match=r"rate\[4\] is (nan|inf)"):
        bifilar.fit_trace(np.arange(10.0), rate, **GEOMETRY)
    with pytest.raises(ValueError, match=r"t\[4\] is"):
        bifilar.fit_trace(np.where(np.arange(10) == 4, bad, np.arange(10.0)), np.zeros(10),
                          **GEOMETRY)


@pytest.mark.parametrize("t", [[0, 1, 2, 2, 3], [0, 1, 3, 2, 4]])
def test_non_increasing_time_names_t(t):
    with pytest.raises(ValueError, match=r"t must be strictly increasing; t\[3\]"):
        bifilar.fit_trace(np.array(t, float), np.zeros(5), **GEOMETRY)


def test_shapes_and_types():
    with pytest.raises(ValueError, match="rate must be one-dimensional"):
        bifilar.fit_trace(np.arange(4.0), np.zeros((4, 3)), **GEOMETRY)
    with pytest.raises(ValueError, match="t must be an array of numbers"):
        bifilar.fit_trace(["a", "b"], [0.0, 1.0], **GEOMETRY)
    with pytest.raises(ValueError, match="give length_m, separation_m and mass_kg"):
        bifilar.fit_trace(np.arange(4.0), np.zeros(4))
    with pytest.raises(ValueError, match="model 'quadratic'"):
        bifilar.fit_trace(np.arange(4.0), np.zeros(4), model="quadratic", **GEOMETRY)
    with pytest.raises(ValueError, match="filar_length"):
        bifilar.fit_trace(np.arange(4.0), np.zeros(4), length_m=-2.0, separation_m=0.9,
                          mass_kg=6.0)
    with pytest.raises(ValueError, match="window"):
        bifilar.fit_trace(np.arange(4.0), np.zeros(4), window="12:", **GEOMETRY)


def test_window_outside_the_log_gives_the_cli_message(cli_fit_json):
    log = sample_log(10)
    (cli_record,) = cli_fit_json(SAMPLE_CONFIG, [log], "--window", "500:600")
    assert cli_record["status"] == "error"
    series = bifilar.read_log(log, SAMPLE_CONFIG)
    with pytest.raises(ValueError) as error:
        bifilar.fit_trace(series.t_s, series.rate_rad_per_s, config=str(SAMPLE_CONFIG),
                          name=log, window=(500, 600))
    assert str(error.value) == cli_record["message"]


def test_unreadable_log_gives_the_cli_message(cli_fit_json, tmp_path):
    broken = tmp_path / "broken.csv"
    broken.write_text("t,gx,gy,gz\n0,0,0,0\n0.01,0,zero,0\n0.02,0,0,0\n")
    missing = tmp_path / "missing.csv"
    for log in (broken, missing):
        (cli_record,) = cli_fit_json(SAMPLE_CONFIG, [log])
        with pytest.raises(ValueError) as error:
            bifilar.read_log(log, SAMPLE_CONFIG)
        assert str(error.value) == cli_record["message"]
        assert str(log) in str(error.value)


def test_bad_config_gives_the_cli_message(cli, tmp_path):
    config = tmp_path / "bad.yaml"
    config.write_text(SAMPLE_CONFIG.read_text().replace("filar_length_m: 2.0",
                                                        "filar_lenght_m: 2.0"))
    log = sample_log(10)
    expected = cli_error(cli("fit", config, log, check=False))
    with pytest.raises(ValueError) as error:
        bifilar.read_log(log, config)
    assert str(error.value) == expected
    with pytest.raises(ValueError) as error:
        bifilar.fit_trace([0.0, 1.0], [0.0, 0.0], config=str(config))
    assert str(error.value) == expected
    assert cli_error(cli("process", tmp_path / "none.yaml", check=False)) == _message(
        lambda: bifilar.process(tmp_path / "none.yaml"))


def _message(call):
    with pytest.raises(ValueError) as error:
        call()
    return str(error.value)


def test_ellipse_input_errors():
    with pytest.raises(ValueError, match=r"pitch_deg and inertia have different lengths"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, 1.1])
    with pytest.raises(ValueError, match=r"inertia\[1\] is nan"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, np.nan, 1.2])
    with pytest.raises(ValueError, match=r"pitch_deg and std have different lengths"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, 1.1, 1.2], std=[0.1])
    with pytest.raises(ValueError, match="angle"):
        bifilar.fit_ellipse([0, 0, 30], [1.0, 1.1, 1.2])
    with pytest.raises(ValueError, match="ellipse options"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, 1.1, 1.2], confidence=2.0)


def test_simulate_errors():
    with pytest.raises(ValueError, match="inertia_kg_m2 = -1 is out of range"):
        bifilar.simulate(inertia_kg_m2=-1, mass_kg=6, length_m=2, separation_m=0.9)
    with pytest.raises(ValueError, match="give inertia_kg_m2"):
        bifilar.simulate(mass_kg=6, length_m=2, separation_m=0.9)
    with pytest.raises(ValueError, match="either out= or trace="):
        bifilar.simulate(out="a", trace="b.csv")


def test_settings_of_the_wrong_type_name_the_argument():
    t = np.arange(100) * 0.01
    with pytest.raises(ValueError, match="fit_trace: length_m must be a number, got 'abc'"):
        bifilar.fit_trace(t, np.zeros(100), length_m="abc", separation_m=0.9, mass_kg=6.0)
    with pytest.raises(ValueError, match="whiteness_lags must be a whole number"):
        bifilar.fit_trace(t, np.zeros(100), whiteness_lags=2.5, **GEOMETRY)
    with pytest.raises(ValueError, match=r"seed must be a whole number in \[0, 2\*\*64 - 1\]"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, 1.1, 1.2], seed=-1)
    with pytest.raises(ValueError, match="simulate: mass_kg must be a number"):
        bifilar.simulate(inertia_kg_m2=1.0, mass_kg=[1, 2], length_m=2.0, separation_m=0.9)


@pytest.mark.parametrize("call", [
    lambda: bifilar.read_log(str(sample_log(0)) + "\0ignored", SAMPLE_CONFIG),
    lambda: bifilar.read_log(sample_log(0), str(SAMPLE_CONFIG) + "\0.yaml"),
    lambda: bifilar.fit_trace(np.arange(10.0), np.zeros(10), config="c.yaml\0x"),
    lambda: bifilar.process("c\0.yaml"),
    lambda: bifilar.simulate(trace="a\0.csv", inertia_kg_m2=1, mass_kg=1, length_m=2,
                             separation_m=1),
])
def test_path_with_nul_raises_value_error(call):
    # A NUL ended the path in the C library: the part before it was read, silently.
    with pytest.raises(ValueError, match="contains a NUL character"):
        call()


@pytest.mark.parametrize("seed", [-1, 2**64, 1e23, 1.5, "x", True])
def test_seed_out_of_range_is_refused_with_the_range(seed):
    with pytest.raises(ValueError, match=r"seed must be a whole number in \[0, 2\*\*64 - 1\]"):
        bifilar.fit_ellipse([0, 30, 60, 90], [3.0, 2.75, 2.25, 2.0], seed=seed)
    with pytest.raises(ValueError, match=r"\[0, 2\*\*64 - 1\]"):
        bifilar.simulate(seed=seed, inertia_kg_m2=1, mass_kg=1, length_m=2, separation_m=1)


def test_nan_setting_is_refused():
    with pytest.raises(ValueError, match="fit_trace: max_amplitude_deg must be a finite number"):
        bifilar.fit_trace(np.arange(10.0), np.zeros(10), max_amplitude_deg=float("nan"),
                          **GEOMETRY)
