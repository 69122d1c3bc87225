"""simulate() against `bifilar simulate` (same seed, same files and truth)."""
import json

import numpy as np
import pytest

import bifilar
from conftest import SAMPLE_CONFIG, without_timings

TRACE = dict(inertia_kg_m2=1.8, mass_kg=5.0, length_m=1.5, separation_m=0.7, amplitude_deg=12,
             duration_s=20, seed=11)


def cli_trace_flags():
    return ["--inertia-kg-m2", "1.8", "--mass-kg", "5.0", "-L", "1.5", "-D", "0.7",
            "--amplitude-deg", "12", "--duration-s", "20", "--seed", "11"]


def test_single_trace_matches_the_cli_file(cli, tmp_path):
    cli_csv = tmp_path / "cli.csv"
    done = cli("simulate", "--trace", cli_csv, *cli_trace_flags())
    assert done.returncode == 0, done.stderr
    py_csv = tmp_path / "py.csv"
    written = bifilar.simulate(trace=py_csv, **TRACE)
    assert py_csv.read_bytes() == cli_csv.read_bytes()
    in_memory = bifilar.simulate(**TRACE)
    # In memory: the same log as read_log reads from the file.
    from_file = bifilar.read_log(cli_csv, SAMPLE_CONFIG)  # default columns t, gx.. az in SI
    np.testing.assert_array_equal(in_memory.t_s, from_file.t_s)
    np.testing.assert_array_equal(in_memory.gyro_rad_per_s, from_file.gyro_rad_per_s)
    np.testing.assert_array_equal(in_memory.accel_mps2, from_file.accel_mps2)
    np.testing.assert_array_equal(written.t_s, from_file.t_s)
    cli_truth = json.loads((tmp_path / "cli.truth.json").read_text())
    for truth in (written.truth, in_memory.truth):
        assert truth.traces[0].inertia_total_kg_m2 == cli_truth["traces"][0]["inertia_total_kg_m2"]
        assert truth.traces[0].t_release_s == cli_truth["traces"][0]["t_release_s"]


def test_campaign_matches_the_cli(cli, repo, tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text((repo / "configs" / "simulate_prandtl_d.yaml").read_text())
    done = cli("simulate", spec, "--out", tmp_path / "cli", "--duration-s", "10", "--seed", "4")
    assert done.returncode == 0, done.stderr
    summary = bifilar.simulate(spec, out=tmp_path / "py", duration_s=10, seed=4)
    cli_files = sorted(p.relative_to(tmp_path / "cli") for p in (tmp_path / "cli").rglob("*.*"))
    py_files = sorted(p.relative_to(tmp_path / "py") for p in (tmp_path / "py").rglob("*.*"))
    assert py_files == cli_files and summary.files_written == len(cli_files) - 1  # + truth
    for name in cli_files:
        if name.name != "truth.json":
            assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    cli_truth = json.loads((tmp_path / "cli" / "truth.json").read_text())
    assert summary.truth["traces"] == cli_truth["traces"]


def test_an_existing_file_is_replaced_only_with_force(tmp_path):
    """Issue 23: simulate writes over no file without force=True, and marks what it writes."""
    real = tmp_path / "real_log.csv"
    real.write_text("t,gx,gy,gz\n0,0,0,0\n")
    with pytest.raises(ValueError, match="real_log.csv exists"):
        bifilar.simulate(trace=real, **TRACE)
    assert real.read_text() == "t,gx,gy,gz\n0,0,0,0\n"
    bifilar.simulate(trace=real, force=True, **TRACE)
    assert real.read_text().startswith("# simulated by bifilar ")
