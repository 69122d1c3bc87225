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
    with pytest.raises(ValueError, match="inertia_kg_m2 = -1; must be > 0"):
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


# ---- issue 23: hostile input (items 4 and 7) ----

def test_whole_numbers_outside_their_range_name_the_argument_and_range():
    # 10**12 reached pybind11 and raised "Unable to cast Python instance of type <class 'int'>".
    t = np.arange(100) * 0.01
    with pytest.raises(ValueError,
                       match=r"fit_trace: whiteness_lags must be a whole number in \[1, 1000\], "
                             r"got 1000000000000"):
        bifilar.fit_trace(t, np.zeros(100), whiteness_lags=10**12, **GEOMETRY)
    with pytest.raises(ValueError, match=r"whiteness_lags must be a whole number in \[1, 1000\]"):
        bifilar.fit_trace(t, np.zeros(100), whiteness_lags=0, **GEOMETRY)
    with pytest.raises(ValueError, match=r"fit_ellipse: bootstrap must be a whole number in "
                                         r"\[0, 100000\], got 1000000000000"):
        bifilar.fit_ellipse([0, 30, 60], [1.0, 1.1, 1.2], bootstrap=10**12)
    with pytest.raises(ValueError, match=r"process: jobs must be a whole number in \[0, 256\]"):
        bifilar.process("c.yaml", jobs=2**40)


@pytest.mark.parametrize("flag", [True, False, np.bool_(True)])
def test_a_bool_is_not_a_number(flag):
    # length_m=True was taken as 1 m.
    t = np.arange(100) * 0.01
    with pytest.raises(ValueError, match="fit_trace: length_m must be a number, got the bool"):
        bifilar.fit_trace(t, np.zeros(100), length_m=flag, separation_m=0.9, mass_kg=6.0)
    with pytest.raises(ValueError, match="simulate: mass_kg must be a number, got the bool"):
        bifilar.simulate(inertia_kg_m2=1.0, mass_kg=flag, length_m=2.0, separation_m=0.9)


def test_bytes_and_pathlike_paths_are_paths(tmp_path):
    # A bytes path was str()-ed to "b'...'" and reported as "no such file".
    import pathlib
    as_str = bifilar.read_log(sample_log(0), str(SAMPLE_CONFIG))
    as_bytes = bifilar.read_log(sample_log(0).encode(), bytes(SAMPLE_CONFIG))
    as_pathlike = bifilar.read_log(pathlib.Path(sample_log(0)), SAMPLE_CONFIG)
    for other in (as_bytes, as_pathlike):
        np.testing.assert_array_equal(other.t_s, as_str.t_s)
        np.testing.assert_array_equal(other.rate_rad_per_s, as_str.rate_rad_per_s)
    missing = str(tmp_path / "missing.csv")
    with pytest.raises(FileNotFoundError) as error:
        bifilar.read_log(missing.encode(), SAMPLE_CONFIG)
    assert missing in str(error.value) and "b'" not in str(error.value)
    with pytest.raises(TypeError, match=r"read_log: path must be a path \(str, bytes or "
                                        r"os.PathLike\), got int"):
        bifilar.read_log(42)


def test_a_bytes_path_that_is_not_utf8_reaches_the_file(tmp_path):
    name = tmp_path / "trial_\xe9.csv"  # a Latin-1 byte in the name: not valid UTF-8
    raw = bytes(tmp_path) + b"/trial_\xe9.csv"
    with open(sample_log(0), "rb") as source:
        import gzip
        data = gzip.decompress(source.read())
    with open(raw, "wb") as target:
        target.write(data)
    got = bifilar.read_log(raw, SAMPLE_CONFIG)
    assert len(got.t_s) == len(bifilar.read_log(sample_log(0), SAMPLE_CONFIG).t_s)
    del name


@pytest.mark.parametrize("roll, pitch, named", [
    (float("nan"), 0.0, r"roll_deg is nan"),
    (0.0, float("inf"), r"pitch_deg is inf"),
    ([0.0, 10.0, float("nan")], [0.0, 0.0, 0.0], r"roll_deg\[2\] is nan"),
])
def test_down_in_body_refuses_angles_that_are_not_finite(roll, pitch, named):
    # down_in_body(nan) returned NaN, an "axis" that fit_tensor then refused far from its cause.
    with pytest.raises(ValueError, match="down_in_body: " + named):
        bifilar.down_in_body(roll, pitch)


def test_fit_tensor_with_a_huge_axis_does_not_crash_the_interpreter():
    # [[1e308, 0, 1]] * 6 overflowed the axis's norm and killed the interpreter (SIGSEGV in
    # JacobiSVD). In a child, so that a crash is a failed assertion here, not a lost run.
    import subprocess
    import sys
    code = ("import bifilar, json\n"
            "r = bifilar.fit_tensor([[1e308, 0, 1]] * 6, [0.45] * 6, bootstrap=0)\n"
            "print(json.dumps([r['Ixx_kg_m2'], r['unobservable']]))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    ixx, unobservable = json.loads(done.stdout)
    assert ixx == pytest.approx(0.45, rel=1e-12)  # the axis is x: six moments of 0.45 about it
    assert unobservable == ["Iyy", "Izz", "Ixy", "Ixz", "Iyz"]
    # Beside valid axes the huge one is the x axis, not a silent zero.
    axes = bifilar.down_in_body([0, 0, 90, 45, 0, 45, 30], [0, 90, 0, 0, 45, 45, -30])
    truth = np.array([[2.0, -0.1, -0.2], [-0.1, 3.0, -0.05], [-0.2, -0.05, 4.0]])
    moments = [float(a @ truth @ a) for a in axes]
    fitted = bifilar.fit_tensor(axes, moments, bootstrap=0)
    huge = axes.copy()
    huge[1] = [1e308, 0, 1e-300]  # the pitch-90 axis, (-1, 0, 0), scaled
    fitted_huge = bifilar.fit_tensor(huge, moments, bootstrap=0)
    for key in ("Ixx_kg_m2", "Iyy_kg_m2", "Izz_kg_m2", "Ixy_kg_m2", "Ixz_kg_m2", "Iyz_kg_m2"):
        assert fitted_huge[key] == pytest.approx(fitted[key], rel=1e-9, abs=1e-12), key
    for bad in ([np.inf, 0, 1], [0, 0, 0]):
        axes_bad = axes.copy()
        axes_bad[3] = bad
        with pytest.raises(ValueError, match=r"directions\[3\] is not finite|point 4: the swing "
                                             r"axis must be a finite, non-zero vector"):
            bifilar.fit_tensor(axes_bad, moments, bootstrap=0)
