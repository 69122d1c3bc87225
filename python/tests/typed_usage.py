"""Code that uses every public function of `bifilar` the way a typed program would: checked with
``mypy --strict`` against the package's hints and stubs (test_typing.py), and run too, so that
the types the hints promise are the ones the calls return. Quick: one short simulated trace.

    PYTHONPATH=build/python python3 python/tests/typed_usage.py
"""
import os
import sys
import tempfile
from typing import Dict, Iterator, List, Optional

import numpy as np
import numpy.typing as npt

import bifilar


def fit_a_simulated_trace() -> float:
    """The relative error of the fitted inertia of a simulated trace (truth 2.5 kg m^2)."""
    sim: bifilar.Record = bifilar.simulate(inertia_kg_m2=2.5, mass_kg=6.0, length_m=2.0,
                                           separation_m=0.9, amplitude_deg=15, duration_s=20,
                                           seed=3)
    t: npt.NDArray[np.float64] = sim.t_s
    rate = sim.gyro_rad_per_s[:, 2]
    result = bifilar.fit_trace(t, rate, length_m=2.0, separation_m=0.9, mass_kg=6.0,
                               model="full", window=None, whiteness_lags=20, name="sim")
    inertia: Optional[float] = result.inertia_total_kg_m2
    assert result["status"] == "ok" and inertia is not None, result
    residual: npt.NDArray[np.float64] = result.residual_rad_per_s
    assert residual.shape == t.shape or residual.size < t.size
    return abs(inertia - 2.5) / 2.5


def read_a_log(folder: str) -> int:
    """Writes a simulated trace, reads it back as `bifilar fit` would; the number of samples."""
    path = os.path.join(folder, "trace.csv")
    written = bifilar.simulate(trace=path, inertia_kg_m2=1.0, mass_kg=3.0, length_m=1.0,
                               separation_m=0.5, duration_s=10, seed=5)
    log = bifilar.read_log(path.encode())  # bytes are paths too
    assert log.t_s.size == written.samples_written
    return int(log.t_s.size)


def ellipse_and_tensor() -> Dict[str, float]:
    """An ellipse and a tensor from exact moments; their headline numbers."""
    pitch = [-30.0, -10.0, 0.0, 10.0, 30.0]
    ix, iz, ixz = 1.2, 2.0, 0.1
    moments = [iz * np.cos(np.radians(p)) ** 2 + ix * np.sin(np.radians(p)) ** 2
               + ixz * np.sin(2 * np.radians(p)) for p in pitch]
    ellipse = bifilar.fit_ellipse(pitch, moments, bootstrap=0, covariance="points")
    residuals: bifilar.Columns = ellipse.residuals
    first: bifilar.Record = residuals[0]
    column: npt.NDArray[np.float64] = residuals["studentized"]
    rows: List[bifilar.Record] = [row for row in residuals[1:3]]
    assert len(rows) == 2 and isinstance(first, bifilar.Record) and column.size == len(pitch)

    axes = bifilar.down_in_body([0.0, 0.0, 30.0, -30.0, 0.0, 45.0],
                                [0.0, 30.0, 0.0, 0.0, -30.0, 20.0])
    j = np.array([[1.2, -0.05, -0.1], [-0.05, 1.6, -0.02], [-0.1, -0.02, 2.0]])
    inertias = np.einsum("ni,ij,nj->n", axes, j, axes)
    tensor = bifilar.fit_tensor(axes, inertias, np.full(len(inertias), 1e-3),
                                groups=range(len(inertias)), bootstrap=0, covariance="absolute")
    return {"Ix": float(ellipse.Ix_kg_m2), "Ixx": float(tensor.Ixx_kg_m2)}


def watch_items(source: str, config: str) -> Iterator[bifilar.Record]:
    """The watch is a generator of Records (not run here: it follows a live stream)."""
    return bifilar.watch(source, config, cycles=10, stop_at_target=True, serve_port=None)


def main() -> int:
    error = fit_a_simulated_trace()
    assert error < 0.01, error
    with tempfile.TemporaryDirectory() as folder:
        samples = read_a_log(folder)
    numbers = ellipse_and_tensor()
    assert abs(numbers["Ix"] - 1.2) < 1e-6 and abs(numbers["Ixx"] - 1.2) < 1e-6, numbers
    print(f"typed_usage: ok ({samples} samples read, relative error {error:.2g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
