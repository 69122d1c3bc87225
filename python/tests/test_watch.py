"""bifilar.watch: the generator yields the updates `bifilar watch --json` prints, and its final
result is `bifilar fit` on the saved log."""
import math

import pytest

import bifilar

CONFIG = "rig: {filar_length_m: 1.0, filar_separation_m: 0.3, mass_kg: 2}\n"


def _swing(tmp_path):
    log = tmp_path / "sw.csv"
    bifilar.simulate(inertia_kg_m2=0.05, mass_kg=2.0, length_m=1.0, separation_m=0.3,
                     duration_s=25.0, seed=4, trace=str(log))
    config = tmp_path / "c.yaml"
    config.write_text(CONFIG)
    return log, config


def test_watch_yields_updates_and_fits_the_saved_log(tmp_path, cli_fit_json):
    log, config = _swing(tmp_path)
    saved = tmp_path / "saved.csv"
    items = list(bifilar.watch(str(log), str(config), save=str(saved), idle_end_s=1.0))
    updates = [i for i in items if "verdict" in i]
    assert len(updates) > 10
    for key in ("t_s", "cycles", "amplitude_deg", "period_s", "inertia_kg_m2",
                "inertia_std_stat_kg_m2", "inertia_std_total_kg_m2", "verdict", "reason"):
        assert key in updates[-1]
    assert {u.verdict for u in updates} <= {"waiting", "swinging", "enough", "swing_again",
                                           "fix_rig"}
    assert any(u.verdict != "waiting" for u in updates)
    final = items[-1]
    assert final["final"] is True
    record = final.logs[0].record
    fit = cli_fit_json(config, [saved])[0]
    assert math.isclose(record.inertia_total_kg_m2, fit["inertia_total_kg_m2"], rel_tol=1e-12)
    assert abs(record.inertia_total_kg_m2 - 0.05) < 5 * record.inertia_total_std_total_kg_m2


def test_watch_closed_early_keeps_the_log(tmp_path):
    log, config = _swing(tmp_path)
    saved = tmp_path / "saved.csv"
    run = bifilar.watch(str(log), str(config), save=str(saved))
    for item in run:
        if item.get("verdict") not in (None, "waiting"):
            break
    run.close()
    assert saved.exists()
    assert saved.read_text().splitlines()[1].startswith("t,gx,gy,gz")


def test_watch_serial_port_that_does_not_open(tmp_path):
    _, config = _swing(tmp_path)
    with pytest.raises(ValueError, match="bifilar_no_such_port"):
        list(bifilar.watch("serial:/dev/bifilar_no_such_port@115200", str(config)))
