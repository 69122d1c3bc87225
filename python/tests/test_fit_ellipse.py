"""fit_ellipse against `bifilar ellipse --json` and against a known ellipse."""
import json
import math

import numpy as np
import pytest

import bifilar
from conftest import without_timings

# A known aircraft (kg m^2): I(theta) = Iz cos^2 + Ix sin^2 + Ixz sin 2theta (docs/physics.md).
IX, IZ, IXZ = 3.2, 3.9, 0.05
PITCH = np.repeat(np.arange(-80.0, 91.0, 10.0), 3)


def moments(sigma, seed=4):
    theta = np.radians(PITCH)
    exact = IZ * np.cos(theta) ** 2 + IX * np.sin(theta) ** 2 + IXZ * np.sin(2 * theta)
    return exact + sigma * np.random.default_rng(seed).standard_normal(PITCH.size)


def test_recovers_a_known_ellipse():
    sigma = 0.004  # kg m^2 per trial, seeded
    result = bifilar.fit_ellipse(PITCH, moments(sigma), bootstrap=0)
    for name, truth in (("Ix_kg_m2", IX), ("Iz_kg_m2", IZ), ("Ixz_kg_m2", IXZ)):
        # 5 of the fit's own standard errors, which come from the scatter of 54 points.
        assert abs(result[name] - truth) < 5 * result[name + "_std"], name
        assert 0 < result[name + "_std"] < 5 * sigma
    tau = 0.5 * math.degrees(math.atan2(2 * IXZ, IZ - IX))
    assert abs(result.tau_deg - tau) < 5 * result.tau_deg_std


def test_gives_the_cli_numbers(cli, tmp_path):
    inertia = moments(0.004)
    std = np.full(PITCH.size, 0.004)
    table = tmp_path / "moments.csv"
    table.write_text("pitch_deg,inertia,std\n" + "".join(
        f"{float(p)!r},{float(i)!r},{float(s)!r}\n" for p, i, s in zip(PITCH, inertia, std)))
    done = cli("ellipse", table, "--json", "--bootstrap", "300", "--seed", "5")
    assert done.returncode == 0, done.stderr
    result = bifilar.fit_ellipse(PITCH, inertia, std, bootstrap=300, seed=5)
    expected = json.loads(done.stdout)
    del expected["table"], expected["figures"]  # the CLI's file names
    assert without_timings(dict(result)) == without_timings(expected)
