"""`pip install --no-build-isolation .` from the clone (issue 18 item 7): the wheel builds with
Debian's setuptools and wheel, offline, installs into a fresh target folder, and the module
imported from there works (a simulated trace fitted back to its known inertia).

The build reuses this build's CMake folder (BIFILAR_CMAKE_BUILD_DIR, setup.py), where the
extension is already built: pip then only packages it (a few seconds). A clean
`pip install .` builds it once in build/pip."""
import json
import os
import pathlib
import re
import subprocess
import sys

import pytest

from conftest import REPO


def _build_dir():
    """The CMake build folder of the `bifilar` executable CTest gives, or None."""
    binary = os.environ.get("BIFILAR_BINARY")
    if not binary:
        return None
    folder = pathlib.Path(binary).resolve().parent
    return folder if (folder / "CMakeCache.txt").exists() else None


def test_pip_install_into_a_target_folder_and_import(tmp_path):
    pytest.importorskip("setuptools")
    pytest.importorskip("wheel")
    if subprocess.run([sys.executable, "-m", "pip", "--version"],
                      capture_output=True).returncode != 0:
        pytest.skip("no pip for %s (Debian: python3-pip)" % sys.executable)
    build = _build_dir()
    if build is None:
        pytest.skip("no CMake build folder to reuse (run under CTest)")
    target = tmp_path / "site"
    env = dict(os.environ, BIFILAR_CMAKE_BUILD_DIR=str(build), PIP_NO_INDEX="1",
               PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)  # pip's build must not see the module of build/python
    done = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps",
         "--no-cache-dir", "--target", str(target), str(REPO)],
        capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    installed = list((target / "bifilar").glob("_core*.so"))
    assert len(installed) == 1, sorted(os.listdir(target / "bifilar"))
    assert (target / "bifilar" / "__init__.py").exists()
    # Typed (PEP 561): the marker and the extension's stubs are installed with it.
    assert (target / "bifilar" / "py.typed").exists()
    assert (target / "bifilar" / "_core.pyi").exists()

    # Imported from the target folder alone (not build/python), it fits a simulated trace with
    # known inertia 2.5 kg m^2 to within 5 sigma of the fit's statistical std, as
    # test_fit_trace.py's test_known_inertia_from_a_simulated_trace does with build/python.
    script = (
        "import bifilar, json\n"
        "sim = bifilar.simulate(inertia_kg_m2=2.5, mass_kg=6.0, length_m=2.0,\n"
        "                       separation_m=0.9, amplitude_deg=15, duration_s=40, seed=7)\n"
        "r = bifilar.fit_trace(sim.t_s, sim.gyro_rad_per_s[:, 2], length_m=2.0,\n"
        "                      separation_m=0.9, mass_kg=6.0)\n"
        "print(json.dumps([bifilar.__file__, bifilar.__version__, r.status,\n"
        "                  r.inertia_total_kg_m2, r.inertia_total_std_kg_m2]))\n")
    env = dict(os.environ, PYTHONPATH=str(target))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    where, version, status, inertia, std = json.loads(done.stdout)
    assert pathlib.Path(where).resolve().is_relative_to(target.resolve()), where
    project = re.search(r"project\(bifilar VERSION ([0-9.]+)",
                        (REPO / "CMakeLists.txt").read_text())
    assert version == project.group(1)
    assert status == "ok"
    assert abs(inertia - 2.5) < 5 * std
