"""Shared fixtures: the repository, the `bifilar` executable of the same build, the sample."""
import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SAMPLE_CONFIG = REPO / "configs" / "prandtl_d.yaml"
SAMPLE_LOGS = REPO / "sample_runs" / "prandtl_d" / "logs"


@pytest.fixture(scope="session")
def repo():
    return REPO


@pytest.fixture(scope="session")
def cli():
    """Runs the `bifilar` executable of this build (CTest sets BIFILAR_BINARY)."""
    binary = os.environ.get("BIFILAR_BINARY", str(REPO / "build" / "bifilar"))
    if not os.path.exists(binary):
        pytest.skip(f"no bifilar executable at {binary}")

    def run(*args, check=True):
        done = subprocess.run([binary, *map(str, args)], cwd=REPO, capture_output=True,
                              text=True)
        if check and done.returncode not in (0, 1):
            raise AssertionError(f"bifilar {' '.join(map(str, args))}: {done.stderr}")
        return done

    return run


@pytest.fixture(scope="session")
def cli_fit_json(cli):
    """`bifilar fit CONFIG LOG... --json [extra]` as a list of records."""
    def fit(config, logs, *extra):
        done = cli("fit", config, *logs, "--json", *extra)
        return json.loads(done.stdout)
    return fit


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "realdata: reads the real logs of BIFILAR_DATA_DIR (CTest label realdata)")


def real_data(relative):
    """The path of `relative` in the real-data folder (BIFILAR_DATA_DIR), as the C++ tests'
    BIFILAR_REAL_DATA (tests/test_support.h): skips when no folder is named, fails when the
    folder is named but the file is missing, or when CTest runs the test unlabelled (the test
    needs @pytest.mark.realdata, which python/CMakeLists.txt registers with the label)."""
    folder = os.environ.get("BIFILAR_DATA_DIR", "")
    path = pathlib.Path(folder) / relative
    if os.environ.get("BIFILAR_REALDATA_LABEL") == "0":
        pytest.fail(f"this test reads real data ({relative}) but runs without the realdata "
                    "label: mark it @pytest.mark.realdata")
    if not folder:
        pytest.skip("real data not run: no data folder named (BIFILAR_DATA_DIR; cmake "
                    "-DBIFILAR_DATA_DIR=DIR, or scripts/test.sh with ../shared/data beside "
                    "the checkout)")
    if not path.exists():
        pytest.fail(f"the data folder named by BIFILAR_DATA_DIR has no {path}")
    return path


def sample_log(pitch, trial=1):
    """A sample log, relative to the repository (as a user would type it there)."""
    path = SAMPLE_LOGS / f"pitch_{pitch}" / f"trial_{trial}.csv.gz"
    if not path.exists():
        pytest.skip(f"sample log {path} absent")
    return str(path.relative_to(REPO))


# Keys whose values are wall-clock times: they differ between any two runs.
# Wall times differ between runs, and so do the hashes of traces.csv (which holds fit_seconds)
# that results.json records in "outputs".
TIMING_KEYS = {"fit_seconds", "wall_s", "time_s", "outputs"}


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value
