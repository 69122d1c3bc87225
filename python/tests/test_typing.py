"""The module's type hints (issue 36 item 5): ``mypy --strict`` (pyproject.toml [tool.mypy])
passes on the package, its stubs and a typed program using it (typed_usage.py), and fails on a
type error; the stubs of the extension (_core.pyi) match the extension: every name, and each
function's parameters (names, order, types) and result as pybind11 states them. CMake registers
this test only when mypy imports in the module's Python (Debian package mypy)."""
import ast
import os
import pathlib
import re
import subprocess
import sys

import pytest

import bifilar
from bifilar import _core
from conftest import REPO

PACKAGE = REPO / "python" / "bifilar"
STUBS = PACKAGE / "_core.pyi"
# mypy's cache beside the built module (build/python/.mypy_cache): numpy's stubs are read once.
CACHE = pathlib.Path(bifilar.__file__).resolve().parents[1] / ".mypy_cache"


def mypy(*files):
    """mypy with the project's configuration; files given replace the configured ones."""
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(REPO / "pyproject.toml"),
         "--cache-dir", str(CACHE), "--python-executable", sys.executable, *map(str, files)],
        cwd=REPO, capture_output=True, text=True)


def test_mypy_strict_passes_on_the_package_and_a_typed_program():
    done = mypy()
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Success: no issues found in 3 source files" in done.stdout, done.stdout


def test_the_typed_program_runs():
    done = subprocess.run([sys.executable, str(REPO / "python" / "tests" / "typed_usage.py")],
                          capture_output=True, text=True, env=os.environ)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "typed_usage: ok" in done.stdout


def test_mypy_fails_on_a_type_error(tmp_path):
    bad = tmp_path / "bad_usage.py"
    bad.write_text(
        "import bifilar\n"
        "r = bifilar.fit_ellipse([0.0, 10.0, 20.0], [1.0, 1.1, 1.2], bootstrap='many')\n"
        "axis: str = bifilar.down_in_body(0.0, 10.0)\n"
        "bifilar.process('campaign.yaml', jobs=2.5)\n"
        "bifilar.fit_trace([0.0], [0.0], model='fast')\n"
        "bifilar.simulate(no_such_keyword=1)\n")
    done = mypy(bad)
    assert done.returncode == 1, done.stdout + done.stderr
    for line, code in ((2, "arg-type"), (3, "assignment"), (4, "arg-type"), (5, "arg-type"),
                       (6, "call-arg")):
        assert re.search(r"bad_usage\.py:%d: error: .*\[%s\]" % (line, code), done.stdout), \
            (line, code, done.stdout)
    assert "Found 5 errors in 1 file" in done.stdout, done.stdout


def test_stubtest_finds_the_stubs_consistent_with_the_extension(tmp_path):
    """mypy.stubtest imports the extension and compares: every name on both sides, the module
    constants' types. (pybind11's functions have no introspectable signature: the parameters
    are checked against their docstrings below.)"""
    allow = tmp_path / "allow.txt"
    # pybind11's class: metaclass pybind11_type and a placeholder __init__ (no constructor from
    # Python; watch_start makes one). Neither can be written in a stub.
    allow.write_text("bifilar._core.WatchRun\nbifilar._core.WatchRun.__init__\n")
    env = dict(os.environ, MYPYPATH=str(REPO / "python"))
    done = subprocess.run([sys.executable, "-m", "mypy.stubtest", "bifilar._core",
                           "--allowlist", str(allow), "--mypy-config-file",
                           str(REPO / "pyproject.toml")],
                          cwd=tmp_path, capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr


# ---- the stubs' parameters against pybind11's signatures ----

def _split_top_level(text):
    """'a: X[b, c], d: Y' -> ['a: X[b, c]', 'd: Y']."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += ch == "["
        depth -= ch == "]"
        if ch == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def _runtime_signature(function):
    """[(name, type)], return type from pybind11's first docstring line
    'name(a: T, b: U, **kwargs) -> R' (self dropped)."""
    first = function.__doc__.strip().splitlines()[0]
    match = re.fullmatch(r"\w+\((.*)\) -> (.+)", first)
    assert match, first
    params = []
    for part in _split_top_level(match.group(1)):
        name, _, kind = part.partition(": ")
        if name != "self":
            params.append((name, kind))
    return params, match.group(2)


# What a stub may say for each pybind11 type (python/src: array_t<double, forcecast> takes
# anything numpy converts; std::string takes str or bytes; py::object anything).
_PARAM_TYPES = {"numpy.ndarray[numpy.float64]": {"_Array"}, "str": {"str", "_Text"},
                "int": {"int"}, "float": {"float"}, "bool": {"bool"},
                "List[int]": {"List[int]"}}
_RESULT_TYPES = {"object": r".+", "dict": r"Dict\[str, Any\]", "tuple": r"Tuple\[.+\]",
                 "List[float]": r"List\[float\]", "None": r"None",
                 "bifilar._core.WatchRun": r"WatchRun"}


def _param_matches(runtime, stub):
    optional = re.fullmatch(r"Optional\[(.+)\]", runtime)
    if optional:
        inner = re.fullmatch(r"Optional\[(.+)\]", stub)
        return inner is not None and _param_matches(optional.group(1), inner.group(1))
    if runtime == "object":  # py::object: the stub names what the code expects
        return True
    return stub in _PARAM_TYPES.get(runtime, ())


def _stub_functions():
    """name -> ast.FunctionDef of the stubs (methods as Class.name)."""
    tree = ast.parse(STUBS.read_text())
    found = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            found[node.name] = node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    found[node.name + "." + item.name] = item
    return found


def _runtime_functions():
    found = {}
    for name in dir(_core):
        value = getattr(_core, name)
        if callable(value) and not isinstance(value, type) and not name.startswith("_"):
            found[name] = value
        elif isinstance(value, type):
            for method in ("next", "close"):
                found[name + "." + method] = getattr(value, method)
            assert sorted(m for m in vars(value) if not m.startswith("_")) == ["close", "next"]
    return found


@pytest.mark.skipif(sys.version_info < (3, 9), reason="ast.unparse needs Python 3.9")
def test_every_function_of_the_extension_has_a_stub_with_its_parameters():
    stubs, runtime = _stub_functions(), _runtime_functions()
    assert sorted(stubs) == sorted(runtime)
    for name, function in runtime.items():
        params, result = _runtime_signature(function)
        node = stubs[name]
        args = [a for a in node.args.args if a.arg != "self"]
        stub_params = [(a.arg, ast.unparse(a.annotation)) for a in args]
        if node.args.kwarg is not None:
            kwarg = node.args.kwarg
            stub_params.append(("**" + kwarg.arg, ast.unparse(kwarg.annotation)))
        assert [p for p, _ in stub_params] == [p for p, _ in params], name
        for (param, kind), (_, stub_kind) in zip(params, stub_params):
            if param.startswith("**"):
                assert stub_kind == "Any", (name, param, stub_kind)
            else:
                assert _param_matches(kind, stub_kind), (name, param, kind, stub_kind)
        assert re.fullmatch(_RESULT_TYPES[result], ast.unparse(node.returns)), \
            (name, result, ast.unparse(node.returns))


def test_the_checker_of_the_stubs_fails_on_a_wrong_stub():
    """The comparison above is not vacuous: a renamed parameter and a wrong type are caught."""
    params, _ = _runtime_signature(_core.fit_ellipse)
    assert params[0] == ("pitch_deg", "numpy.ndarray[numpy.float64]")
    assert params[2] == ("std", "Optional[numpy.ndarray[numpy.float64]]")
    assert _param_matches(params[2][1], "Optional[_Array]")
    assert not _param_matches(params[2][1], "_Array")
    assert not _param_matches("int", "float")
    assert not _param_matches("str", "int")


def test_the_package_is_typed():
    built = pathlib.Path(bifilar.__file__).parent
    assert (built / "py.typed").exists() and (built / "_core.pyi").exists()
    assert (PACKAGE / "py.typed").exists()
