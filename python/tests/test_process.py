"""process() against `bifilar process` on a small campaign drawn from the sample logs."""
import json

import pytest

import bifilar
from conftest import SAMPLE_LOGS, without_timings

# 5 angles x 1 trial of the sample campaign and one tare log: enough for the ellipse, fast.
PITCHES = (-60, -30, 0, 30, 60)


@pytest.fixture
def small_campaign(tmp_path):
    if not SAMPLE_LOGS.exists():
        pytest.skip("sample logs absent")
    table = tmp_path / "runs.csv"
    table.write_text("path,pitch_deg\n" + "".join(
        f"pitch_{p}/trial_1.csv.gz,{p}\n" for p in PITCHES))
    config = tmp_path / "campaign.yaml"
    config.write_text(f"""
rig:
  filar_length_m: 2.0
  filar_separation_m: 1.8
  mass_kg: 1.25
  inertia:
    tare:
      logs: [{SAMPLE_LOGS}/tare/tare_1.csv.gz]
  uncertainties: {{filar_length_std_m: 0.002, mass_std_kg: 0.005}}
aircraft: {{mass_kg: 5.5, mass_std_kg: 0.01}}
imu:
  time: {{column: t, unit: s}}
  gyro: {{columns: [gx, gy, gz], unit: rad/s}}
  accel: {{columns: [ax, ay, az], unit: m/s^2}}
runs:
  root: {SAMPLE_LOGS}
  table: runs.csv
fit: {{max_amplitude_deg: 30}}
ellipse: {{bootstrap: 300, seed: 3}}
""")
    return config


def outside(value, out_dir):
    """The results with the output folder in any path written as OUT."""
    if isinstance(value, dict):
        return {k: outside(v, out_dir) for k, v in value.items()}
    if isinstance(value, list):
        return [outside(v, out_dir) for v in value]
    if isinstance(value, str):
        return value.replace(str(out_dir), "OUT")
    return value


def test_process_gives_the_results_json_of_the_cli(cli, small_campaign, tmp_path):
    done = cli("process", small_campaign, "--out", tmp_path / "cli_out", "--jobs", "2")
    assert done.returncode == 0, done.stderr
    cli_results = json.loads((tmp_path / "cli_out" / "results.json").read_text())
    results = bifilar.process(small_campaign, out=tmp_path / "py_out", jobs=2)
    assert results.summary.n_ok == len(PITCHES) + 1
    assert results.ellipse.Ix_kg_m2 > 0
    # Identical but for wall times and the output folders named in paths.
    assert (without_timings(outside(dict(results), tmp_path / "py_out")) ==
            without_timings(outside(cli_results, tmp_path / "cli_out")))
    # The file on disk is what was returned.
    on_disk = json.loads((tmp_path / "py_out" / "results.json").read_text())
    assert on_disk == results

    # A second run reuses the cache, as the CLI's does.
    again = bifilar.process(small_campaign, out=tmp_path / "py_out", figures=False)
    assert again.summary.n_reused == len(PITCHES) + 1
    assert [t.inertia_kg_m2 for t in again.traces] == [t.inertia_kg_m2 for t in results.traces]


def test_progress_callback_sees_every_fit(small_campaign, tmp_path):
    seen = []
    bifilar.process(small_campaign, out=tmp_path / "out", jobs=2, figures=False,
                    progress=lambda done, total, line: seen.append((done, total, line)))
    total = len(PITCHES) + 1  # the aircraft logs and the tare log
    assert [d for d, _, _ in seen] == list(range(1, total + 1))
    assert all(t == total for _, t, _ in seen)
    assert all(": ok" in line for _, _, line in seen)
    with pytest.raises(ValueError, match="progress must be"):
        bifilar.process(small_campaign, out=tmp_path / "out", progress="lines")


def test_ctrl_c_raises_keyboard_interrupt_and_keeps_the_finished_fits(tmp_path):
    """SIGINT during process() on the whole sample campaign (57 logs, one worker): the run stops
    long before its end however loaded the machine is (the signal lands within one 50 ms poll,
    the remaining fits take seconds)."""
    import os
    import signal

    from conftest import SAMPLE_CONFIG

    if not SAMPLE_LOGS.exists():
        pytest.skip("sample logs absent")
    out = tmp_path / "out"

    def interrupt_after_two(done, total, line):
        if done == 2:
            os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C sends

    with pytest.raises(KeyboardInterrupt):
        bifilar.process(SAMPLE_CONFIG, out=out, jobs=1, figures=False,
                        progress=interrupt_after_two)
    assert not (out / "results.json").exists()  # no partial result
    cached = list((out / "cache").glob("*.json"))
    assert 2 <= len(cached) < 57
    # The next run goes on from the cache.
    results = bifilar.process(SAMPLE_CONFIG, out=out, jobs=2, figures=False)
    assert results.summary["n_reused"] >= 2
