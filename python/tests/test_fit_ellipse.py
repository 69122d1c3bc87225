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
    plain = dict(result)
    plain["residuals"] = [dict(row) for row in result.residuals]  # Columns -> the CLI's rows
    assert without_timings(plain) == without_timings(expected)


def test_residuals_are_columns_with_rows_on_demand():
    inertia = moments(0.004)
    result = bifilar.fit_ellipse(PITCH, inertia, bootstrap=0)
    residuals = result.residuals
    assert isinstance(residuals, bifilar.Columns)
    assert len(residuals) == PITCH.size
    assert residuals.keys() == ["index", "pitch_deg", "inertia_kg_m2", "fitted_kg_m2",
                                "residual_kg_m2", "studentized", "outlier"]
    # Columns are numpy arrays holding the inputs, in input order, with measured - fitted.
    assert isinstance(residuals.studentized, np.ndarray)
    np.testing.assert_array_equal(residuals.index, np.arange(PITCH.size))
    np.testing.assert_array_equal(residuals.pitch_deg, PITCH)
    np.testing.assert_array_equal(residuals["inertia_kg_m2"], inertia)
    np.testing.assert_allclose(residuals.residual_kg_m2,
                               residuals.inertia_kg_m2 - residuals.fitted_kg_m2, atol=1e-15)
    assert residuals.outlier.dtype == bool
    # A row is a Record of plain Python values, as a row of the CLI's JSON; negative index too.
    last = residuals[-1]
    assert isinstance(last, bifilar.Record) and isinstance(last.index, int)
    assert last.index == PITCH.size - 1 and last.pitch_deg == PITCH[-1]
    assert isinstance(last.outlier, bool)
    assert [row.index for row in residuals[:3]] == [0, 1, 2]
    with pytest.raises(IndexError):
        residuals[PITCH.size]
    with pytest.raises(AttributeError):
        residuals.no_such_column
