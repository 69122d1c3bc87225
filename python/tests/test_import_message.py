"""`import bifilar` where the compiled part was never built (issue 32 item 9): after
scripts/run_sample.sh of an older checkout, PYTHONPATH=build/python found __init__.py but no
_core, and Python said "cannot import name '_core' from partially initialized module 'bifilar'
(most likely due to a circular import)". The message now says what to build, with the command.
"""
import os
import shutil
import subprocess
import sys

from conftest import REPO


def _import_error(package_parent):
    """stderr of `import bifilar` with only `package_parent` on the path."""
    env = dict(os.environ, PYTHONPATH=str(package_parent))
    done = subprocess.run([sys.executable, "-c", "import bifilar"], capture_output=True,
                          text=True, env=env, cwd=package_parent)
    assert done.returncode != 0, done.stdout
    return done.stderr


def test_missing_core_names_the_build_command(tmp_path):
    package = tmp_path / "bifilar"
    package.mkdir()
    shutil.copy(REPO / "python" / "bifilar" / "__init__.py", package)
    err = _import_error(tmp_path)
    assert "circular import" not in err, err
    assert "the compiled part bifilar._core" in err, err
    assert "cmake --build build --target bifilar_python" in err, err
    assert "pip install --no-build-isolation ." in err, err


def test_missing_core_in_a_build_folder_names_that_folder(tmp_path):
    # BUILD/python/bifilar/__init__.py, as CMake copies it, with BUILD/CMakeCache.txt.
    build = tmp_path / "mybuild"
    package = build / "python" / "bifilar"
    package.mkdir(parents=True)
    (build / "CMakeCache.txt").write_text("# CMake cache\n")
    shutil.copy(REPO / "python" / "bifilar" / "__init__.py", package)
    err = _import_error(build / "python")
    assert f"cmake --build {build} --target bifilar_python" in err, err
