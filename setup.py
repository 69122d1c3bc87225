"""Builds the Python module `bifilar` for `pip install .` (see pyproject.toml).

The extension `bifilar._core` is the CMake target bifilar_python (python/CMakeLists.txt), so it
is built by CMake exactly as in a normal build, for the interpreter running pip; the pure-Python
part is python/bifilar/. Environment:

  BIFILAR_CMAKE_BUILD_DIR  CMake build folder to use. Default: the clone's `build` when it is
                           a Release build configured for this Python with the module on (what
                           scripts/run_sample.sh and scripts/test.sh make): its libraries and
                           extension are reused, and pip only builds what is missing (seconds);
                           else build/pip in the clone, configured once and reused.
  BIFILAR_CMAKE_ARGS       Extra arguments for the CMake configure step (split on spaces).
  CMAKE_BUILD_PARALLEL_LEVEL  Parallel build jobs (default: the number of cores).

A fresh build/pip is configured with ccache as the compiler launcher when ccache is installed
(unless BIFILAR_CMAKE_ARGS names a launcher), so a rebuild recompiles nothing unchanged.
"""
import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def _version():
    """The project's version, from CMakeLists.txt's project(... VERSION x.y.z)."""
    with open(os.path.join(HERE, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(\s*bifilar\s+VERSION\s+([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("setup.py: no 'project(bifilar VERSION x.y.z)' in CMakeLists.txt")
    return match.group(1)


def _cached(build_dir, key):
    """The value of KEY:TYPE=VALUE in an existing CMake build folder's cache, or None."""
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if not os.path.exists(cache):
        return None
    with open(cache, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith(key + ":"):
                return line.split("=", 1)[1].strip()
    return None


def _reusable(build_dir):
    """True when build_dir is a Release build for this Python with the module on and no
    sanitizer (an extension built with AddressSanitizer would not load in a plain Python)."""
    python = _cached(build_dir, "Python3_EXECUTABLE")
    return (python is not None
            and os.path.realpath(python) == os.path.realpath(sys.executable)
            and _cached(build_dir, "CMAKE_BUILD_TYPE") == "Release"
            and _cached(build_dir, "BIFILAR_PYTHON") in ("ON", "TRUE", "1")
            and _cached(build_dir, "BIFILAR_SANITIZE") in (None, "OFF", "FALSE", "0"))


def _build_dir():
    """BIFILAR_CMAKE_BUILD_DIR, else the clone's `build` when reusable, else build/pip."""
    given = os.environ.get("BIFILAR_CMAKE_BUILD_DIR")
    if given:
        return os.path.abspath(given)
    main = os.path.join(HERE, "build")
    return main if _reusable(main) else os.path.join(HERE, "build", "pip")


# The CMake build folder; setuptools' own scratch files go into it too (under setuptools/), so
# nothing is written beside the sources and two builds with different folders do not meet.
BUILD_DIR = _build_dir()
SCRATCH = os.path.join(BUILD_DIR, "setuptools")


class CMakeBuild(build_ext):
    """Configures (once) and builds the CMake target bifilar_python, then copies _core*.so."""

    def build_extension(self, ext):
        build_dir = BUILD_DIR
        python = os.path.realpath(sys.executable)
        cached = _cached(build_dir, "Python3_EXECUTABLE")
        if cached is not None and os.path.realpath(cached) != python:
            raise RuntimeError(
                f"setup.py: the CMake build folder {build_dir} was configured for {cached}, "
                f"but pip runs {sys.executable}; use that Python's pip, or give another folder "
                "with BIFILAR_CMAKE_BUILD_DIR")
        if cached is None:
            configure = ["cmake", "-S", HERE, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                         f"-DPython3_EXECUTABLE={sys.executable}", "-DBIFILAR_PYTHON=ON"]
            extra = os.environ.get("BIFILAR_CMAKE_ARGS", "").split()
            if (shutil.which("ccache") and "CMAKE_CXX_COMPILER_LAUNCHER" not in os.environ
                    and not any("COMPILER_LAUNCHER" in a for a in extra)):
                configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            subprocess.check_call(configure + extra)
        print(f"setup.py: building bifilar._core in {build_dir}", flush=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build_dir, "--target", "bifilar_python",
                               "-j", jobs])
        built = glob.glob(os.path.join(build_dir, "python", "bifilar", "_core*.so"))
        if len(built) != 1:
            raise RuntimeError(
                f"setup.py: expected one _core*.so in {build_dir}/python/bifilar, found "
                f"{built or 'none'}; did CMake find pybind11, python3-dev and numpy? (its "
                "output above says 'bifilar Python module: off' when not)")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)


os.makedirs(SCRATCH, exist_ok=True)
setup(
    version=_version(),
    packages=["bifilar"],
    package_dir={"": "python"},
    package_data={"bifilar": ["py.typed", "*.pyi"]},  # type hints (PEP 561)
    ext_modules=[Extension("bifilar._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": SCRATCH}, "egg_info": {"egg_base": SCRATCH}},
)
