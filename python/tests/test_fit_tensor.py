"""fit_tensor against a known tensor: 3-D design, three axes, bad input."""
import numpy as np
import pytest

import bifilar

# A small UAV with an off-centre payload (kg m^2), products positive (docs/physics.md 3.5).
IXX, IYY, IZZ, IXY, IXZ, IYZ = 0.20, 0.30, 0.45, 0.008, 0.010, -0.009
J = np.array([[IXX, -IXY, -IXZ], [-IXY, IYY, -IYZ], [-IXZ, -IYZ, IZZ]])
ATTITUDES = np.array([[0, 0], [0, 45], [0, -45], [0, -90], [45, 0], [-45, 0], [90, 0],
                      [45, 45], [-45, 45], [45, -45], [-45, -45], [90, 45]], dtype=float)


def test_down_in_body_follows_physics_md():
    assert np.allclose(bifilar.down_in_body(0, -90), [1, 0, 0])
    assert np.allclose(bifilar.down_in_body(90, 0), [0, 1, 0])
    assert bifilar.down_in_body(ATTITUDES[:, 0], ATTITUDES[:, 1]).shape == (12, 3)


def test_recovers_a_known_tensor():
    rng = np.random.default_rng(3)
    att = np.repeat(ATTITUDES, 2, axis=0)
    n = bifilar.down_in_body(att[:, 0], att[:, 1])
    sigma = 0.0004  # kg m^2 per trial, seeded
    inertia = np.einsum("ij,jk,ik->i", n, J, n) + sigma * rng.standard_normal(len(n))
    r = bifilar.fit_tensor(n, inertia, bootstrap=0)
    assert r.mode == "full_3d" and r.rank == 6 and r.unobservable == []
    for name, truth in (("Ixx", IXX), ("Iyy", IYY), ("Izz", IZZ), ("Ixy", IXY), ("Ixz", IXZ),
                        ("Iyz", IYZ)):
        # 5 of the fit's own standard errors (from the scatter of 24 points, 18 dof).
        assert abs(r[name + "_kg_m2"] - truth) < 5 * r[name + "_kg_m2_std"], name
    assert np.allclose(r.principal_moments_kg_m2, np.linalg.eigvalsh(J), atol=5 * max(r.principal_moments_kg_m2_std))
    assert len(r.covariance_kg2_m4) == 6 and len(r.orientations) == 12


def test_three_axes_name_the_products():
    n = np.repeat(np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]), 4, axis=0)
    inertia = np.repeat([IXX, IYY, IZZ], 4) * (1 + 0.002 * np.random.default_rng(1).standard_normal(12))
    r = bifilar.fit_tensor(n, inertia, np.full(12, 1e-4))
    assert r.mode == "partial"
    assert r.unobservable == ["Ixy", "Ixz", "Iyz"]
    assert r.Ixy_kg_m2 is None and r.principal_moments_kg_m2 is None
    assert abs(r.Ixx_kg_m2 - IXX) < 5 * r.Ixx_kg_m2_std


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="shape"):
        bifilar.fit_tensor(np.ones(5), np.ones(5))
    with pytest.raises(ValueError, match="different lengths"):
        bifilar.fit_tensor(np.ones((5, 3)), np.ones(4))
    with pytest.raises(ValueError, match="none of the six components"):
        bifilar.fit_tensor(np.tile([1.0, 1.0, 0.0], (4, 1)), np.full(4, 0.25))
