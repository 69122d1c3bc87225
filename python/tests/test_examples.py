"""examples/first_look.py, the notebook-style example, runs from start to end as a script and
prints the numbers the library gives for its log."""
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import pytest

import bifilar
from conftest import REPO, SAMPLE_CONFIG, sample_log


def test_first_look_runs_and_reports_the_fit(tmp_path):
    log = str(REPO / sample_log(0))
    done = subprocess.run([sys.executable, str(REPO / "examples" / "first_look.py"), log,
                           str(SAMPLE_CONFIG), "--out", str(tmp_path)],
                          capture_output=True, text=True, env=dict(os.environ, DISPLAY=""),
                          cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout
    # Step 1: the guesses are shown.
    assert "guessed: time column 't' in s" in out
    assert "guessed: gyro columns gx, gy, gz in rad/s" in out
    # Step 2 and 4: the printed inertia and its whole uncertainty are the library's, to the
    # digits printed (5 and 2 significant).
    series = bifilar.read_log(log, SAMPLE_CONFIG)
    result = bifilar.fit_trace(series.t_s, series.rate_rad_per_s, config=str(SAMPLE_CONFIG),
                               name=log)
    match = re.search(r"I_total = (\S+) ± (\S+) kg m²", out)
    assert match, out
    assert float(match.group(1)) == pytest.approx(result.inertia_total_kg_m2, rel=1e-4)
    assert float(match.group(2)) == pytest.approx(result.inertia_total_std_total_kg_m2,
                                                  rel=0.05)
    assert "statistical (fit)" in out and "configured_inputs" in out
    # Step 3: a figure (a PNG with matplotlib, else a plain SVG that parses, with the fit, the
    # measured samples and the residual).
    png, svg = tmp_path / "first_look.png", tmp_path / "first_look.svg"
    assert png.exists() or svg.exists(), out
    if svg.exists():
        root = ElementTree.parse(svg).getroot()
        ns = "{http://www.w3.org/2000/svg}"
        assert len(root.findall(ns + "polyline")) == 2
        assert len(root.findall(ns + "circle")) == result.t_s.size
