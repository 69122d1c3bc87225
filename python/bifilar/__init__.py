"""bifilar from Python: the same C++ core as the ``bifilar`` command line.

Functions
---------
fit_trace(t, rate, *, length_m, separation_m, mass_kg, ...)
    Fit one swing-rate series; the record of ``bifilar fit --json`` plus the fitted and
    residual series as numpy arrays.
read_log(path, config=None)
    Read an IMU log the way ``bifilar fit`` does: the time series a fit uses. Without a
    config, the format ``bifilar inspect`` guesses.
fit_ellipse(pitch_deg, inertia, std=None)
    I_x, I_z, I_xz and tau with their uncertainties (``bifilar ellipse --json``); the
    per-point residuals as :class:`Columns` (numpy arrays; rows on demand).
fit_tensor(directions, inertias, stds=None)
    The full inertia tensor from moments about any body axes (results.json's ``tensor``).
down_in_body(roll_deg, pitch_deg)
    The swing axis (down vertical) in body axes of an aircraft hung at that attitude.
process(config_path, out=None, jobs=None)
    Run a campaign (``bifilar process``); the parsed results.json.
simulate(...)
    Realistic logs with known truth (``bifilar simulate``), in memory or on disk.

Units are SI throughout (s, rad/s, m, kg, kg m^2), pitch and amplitudes in degrees. Paths are
str, bytes or os.PathLike (anything else: TypeError); numbers are numbers, not bools, and whole
numbers lie in their range (``_core.int_ranges``). Bad input
raises ValueError with the command line's message; a file given that does not exist raises
FileNotFoundError (a subclass of ValueError too, so older ``except ValueError`` code still
catches it). Results are :class:`Record` objects: dicts
whose keys are also attributes (``r.inertia_total_kg_m2 == r["inertia_total_kg_m2"]``).
Conventions and the equations: docs/physics.md.
Every function and result is typed (PEP 561: ``py.typed``, and ``_core.pyi`` for the
compiled part); ``mypy --strict`` checks code that uses them (python/tests/test_typing.py).
"""

from __future__ import annotations

import errno as _errno
import math as _math
import operator as _operator
import os as _os
import typing as _typing
from typing import (Any, Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple,
                    TypeVar, Union, overload)

if _typing.TYPE_CHECKING:  # names for the annotations only (they are never evaluated)
    import numpy as np
    import numpy.typing as npt
    from typing_extensions import Literal

    #: A path: str, bytes or os.PathLike, as the os functions take.
    PathArg = Union[str, bytes, "_os.PathLike[str]", "_os.PathLike[bytes]"]
    #: Anything numpy converts to an array of numbers (lists, tuples, arrays).
    ArrayLike = npt.ArrayLike
    FloatArray = npt.NDArray[np.float64]
    Model = Literal["full", "jardin", "linear"]
    Covariance = Literal["auto", "points", "angle_means", "absolute"]
    #: fit_trace's window: None (detected), (t0, t1) or "T0:T1" (s).
    Window = Union[None, Tuple[float, float], str]
    #: process's progress: None/False (quiet), True or "bar" (a text bar), or a callable
    #: progress(done, total, line).
    Progress = Union[None, bool, str, Callable[[int, int, str], object]]
    _RecordBase = Dict[str, Any]
else:
    _RecordBase = dict

_T = TypeVar("_T")

try:
    from . import _core
except ImportError:  # the compiled part was never built here (or for another Python)
    _here = _os.path.dirname(_os.path.abspath(__file__))
    _build = _os.path.dirname(_os.path.dirname(_here))  # BUILD/python/bifilar -> BUILD
    if not _os.path.exists(_os.path.join(_build, "CMakeCache.txt")):
        _build = "build"
    raise ImportError(
        f"bifilar: the compiled part bifilar._core (a _core*.so for this Python) is not in "
        f"{_here}. Build the Python module with\n"
        f"    cmake --build {_build} --target bifilar_python\n"
        "(scripts/run_sample.sh and scripts/test.sh do it when pybind11-dev, python3-dev and "
        "python3-numpy are installed) and keep PYTHONPATH=build/python, or install it with "
        "`python3 -m pip install --no-build-isolation .` (README, \"Python\")"
    ) from None

try:  # needed by every function; `import bifilar` itself works without it
    import numpy as _np
except ImportError:  # pragma: no cover - depends on the interpreter
    _np = None  # type: ignore[assignment]  # each use checks for None first

__all__ = ["Record", "Columns", "fit_trace", "read_log", "fit_ellipse", "fit_tensor",
           "down_in_body", "process", "simulate", "watch"]
__version__ = _core.version


class Record(_RecordBase):
    """A result: a dict (JSON-like, as the command line writes it) whose keys are attributes.

    Nested objects are Records too. ``dict(r)`` or ``json.dumps(r)`` give the plain form
    (numpy arrays excepted).
    """

    __slots__ = ()

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        """Like dict(...); nested dicts (also inside lists) become Records."""
        super().__init__(*args, **kwargs)
        for key, value in self.items():
            dict.__setitem__(self, key, _wrap(value))

    def __getattr__(self, name: str) -> Any:
        """r.key is r["key"]; AttributeError for a key that is not there."""
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __dir__(self) -> List[str]:
        """The keys too, for tab completion in notebooks."""
        return list(self.keys()) + list(super().__dir__())

    def __repr__(self) -> str:
        """A summary, not the whole record: the headline numbers first (status, inertia and
        its uncertainty, period, ...), then other short values until about 500 characters;
        arrays as their shape, nested records and long lists as their size; the rest counted.
        ``dict(r)`` (or ``r.keys()``) shows everything."""
        return _summary(self)

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:
        """IPython/Jupyter show the same summary (not the dict pretty-printer's full dump)."""
        printer.text("Record(...)" if cycle else _summary(self))


class Columns:
    """Rows held as equal-length numpy columns: ``c.studentized`` (or ``c["studentized"]``) is
    a column; ``c[i]`` is row i as a Record; ``len(c)`` and ``for row in c`` work as on a list
    of Records (rows are built when asked for). ``c.keys()`` lists the columns.

    fit_ellipse's residuals come this way: one row per input point, ~49 bytes a point, where a
    list of dicts took ~2.7 kB a point. ``[dict(row) for row in c]`` is the plain form.
    """

    __slots__ = ("_columns", "_length")

    def __init__(self, columns: _typing.Mapping[str, ArrayLike]) -> None:
        """From a dict of name -> 1-D array, all of one length."""
        self._columns: Dict[str, npt.NDArray[Any]] = {
            str(k): _np.asarray(v) for k, v in dict(columns).items()}
        lengths = {len(v) for v in self._columns.values()}
        if len(lengths) > 1:
            raise ValueError("Columns: columns of different lengths " + str(sorted(lengths)))
        self._length = lengths.pop() if lengths else 0

    def keys(self) -> List[str]:
        """The column names."""
        return list(self._columns)

    def __len__(self) -> int:
        return self._length

    @overload
    def __getitem__(self, key: str) -> npt.NDArray[Any]: ...

    @overload
    def __getitem__(self, key: slice) -> Columns: ...

    @overload
    def __getitem__(self, key: int) -> Record: ...

    def __getitem__(self, key: Union[str, slice, int]) -> Union[npt.NDArray[Any], Columns, Record]:
        """A column by name, a row (Record) by integer index, a Columns by slice."""
        if isinstance(key, str):
            return self._columns[key]
        if isinstance(key, slice):
            return Columns({k: v[key] for k, v in self._columns.items()})
        i = range(self._length)[key]  # IndexError and negative indices as a list
        return Record({k: v[i].item() for k, v in self._columns.items()})

    def __iter__(self) -> Iterator[Record]:
        for i in range(self._length):
            yield self[i]

    def __getattr__(self, name: str) -> npt.NDArray[Any]:
        """c.name is the column c["name"]."""
        try:
            return self._columns[name]
        except KeyError:
            raise AttributeError(name) from None

    def __dir__(self) -> List[str]:
        return self.keys() + list(super().__dir__())

    def __repr__(self) -> str:
        return "Columns(%d rows: %s)" % (self._length, ", ".join(self._columns))


# Keys shown first in a Record's summary, when present (trace records, ellipse fits, campaigns).
_HEADLINE = ("file", "status", "message", "warnings", "inertia_total_kg_m2",
             "inertia_total_std_total_kg_m2", "inertia_total_std_kg_m2", "inertia_kg_m2",
             "inertia_std_total_kg_m2", "inertia_std_kg_m2", "period_s", "frequency_hz",
             "small_angle_inertia_kg_m2", "Ix_kg_m2", "Ix_kg_m2_std", "Iz_kg_m2", "Iz_kg_m2_std",
             "Ixz_kg_m2", "Ixz_kg_m2_std", "tau_deg", "tau_deg_std", "window_s", "axis_source",
             "summary")
_SUMMARY_CHARS = 500  # about six lines of a terminal


def _short(value: object) -> str:
    """A value in a few characters: numbers to 6 digits, strings cut to 60 characters, arrays as
    <array shape>, records and long or nested lists as their size."""
    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, float):
        return "%.6g" % value
    if isinstance(value, int):
        return repr(value)
    if isinstance(value, str):  # long ones keep their end too (a path's file name)
        return repr(value if len(value) <= 60 else value[:20] + "..." + value[-37:])
    if _np is not None and isinstance(value, _np.ndarray):
        return "<array %s>" % ("x".join(map(str, value.shape)) or "scalar")
    if isinstance(value, dict):
        return "{%d keys}" % len(value)
    if isinstance(value, Columns):
        return "<%d rows x %d columns>" % (len(value), len(value.keys()))
    if isinstance(value, (list, tuple)):
        simple = all(isinstance(v, (int, float, str, bool)) or v is None for v in value)
        if simple and len(value) <= 4:
            text = ", ".join(_short(v) for v in value)
            return ("[%s]" if isinstance(value, list) else "(%s)") % text
        return "[%d items]" % len(value)
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _summary(record: _typing.Mapping[str, Any]) -> str:
    """Record(key=value, ..., +N more keys: a, b, ...) within about _SUMMARY_CHARS."""
    keys = [k for k in _HEADLINE if k in record]
    keys += [k for k in record if k not in keys]
    parts: List[str] = []
    length = 0
    for key in keys:
        part = "%s=%s" % (key, _short(record[key]))
        if parts and length + len(part) > _SUMMARY_CHARS:
            break
        parts.append(part)
        length += len(part) + 2
    rest = keys[len(parts):]
    if rest:
        names = ", ".join(rest[:6]) + (", ..." if len(rest) > 6 else "")
        parts.append("+%d more keys: %s" % (len(rest), names))
    return "Record(%s)" % ", ".join(parts)


class _FileNotFoundError(FileNotFoundError, ValueError):
    """FileNotFoundError for a path given that does not exist; str() is the command line's
    message. Also a ValueError, as bifilar raised before."""

    def __init__(self, message: str, filename: str) -> None:
        super().__init__(_errno.ENOENT, message, filename)
        self.message = message

    def __str__(self) -> str:
        return self.message


# Tracebacks say "bifilar.FileNotFoundError: <the command line's message>".
_FileNotFoundError.__name__ = _FileNotFoundError.__qualname__ = "FileNotFoundError"


def _calling(inputs: Sequence[Optional[PathArg]], call: Callable[..., _T], *args: Any,
             **kwargs: Any) -> _T:
    """call(*args, **kwargs); a ValueError raised while one of `inputs` (paths the call reads,
    None skipped) does not exist becomes FileNotFoundError, with the command line's message
    when it names that file."""
    try:
        return call(*args, **kwargs)
    except ValueError as error:
        for path in inputs:
            if path is not None and not _os.path.exists(path):
                message, shown = str(error), _os.fsdecode(path)
                if shown not in message:
                    message = "%s: no such file" % shown
                raise _FileNotFoundError(message, shown) from None
        raise


def _wrap(value: Any) -> Any:
    """Dicts to Records, recursively through lists; anything else unchanged."""
    if isinstance(value, dict) and not isinstance(value, Record):
        return Record(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


def _series(values: ArrayLike, name: str) -> FloatArray:
    """A float64 numpy view/copy of an array-like; ValueError naming the argument otherwise."""
    if _np is None:
        raise ImportError("bifilar needs numpy for this interpreter (Debian: python3-numpy, "
                          "for /usr/bin/python3)")
    try:
        return _np.asarray(values, dtype=_np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be an array of numbers: {error}") from None


@overload
def _path(function: str, name: str, value: None) -> None: ...


@overload
def _path(function: str, name: str, value: PathArg) -> Union[str, bytes]: ...


@overload
def _path(function: str, name: str, value: Optional[PathArg]) -> Union[str, bytes, None]: ...


def _path(function: str, name: str, value: Optional[PathArg]) -> Union[str, bytes, None]:
    """None, or the path for the core: a str, bytes or os.PathLike given (bytes decoded as the
    file system does, os.fsdecode); TypeError for anything else; ValueError when it holds a NUL
    (the C library would read only the part before it: another file, silently). A name that is
    not valid UTF-8 goes on as bytes (the core takes them as they are)."""
    if value is None:
        return None
    try:
        text = _os.fsdecode(value)
    except TypeError:
        raise TypeError(f"{function}: {name} must be a path (str, bytes or os.PathLike), got "
                        f"{type(value).__name__} {value!r}") from None
    if "\0" in text:
        raise ValueError(f"{function}: {name} contains a NUL character: {text!r}")
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:  # undecodable bytes, held as surrogates by os.fsdecode
        return _os.fsencode(text)
    return text


def _seed(function: str, value: Any) -> int:
    """A seed: a whole number in [0, 2**64 - 1]; anything else (-1, 2**64, 1e23, 1.5) is a
    ValueError giving the range, never a wrapped or saturated seed."""
    message = f"{function}: seed must be a whole number in [0, 2**64 - 1], got {value!r}"
    try:
        if isinstance(value, bool):
            raise TypeError
        if isinstance(value, float):
            if not (value.is_integer() and abs(value) < 2.0**53):  # 1e23 is not exact
                raise ValueError
            seed = int(value)
        elif isinstance(value, str):
            seed = int(value)
        else:
            seed = _operator.index(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(message) from None
    if not 0 <= seed <= 2**64 - 1:
        raise ValueError(message)
    return seed


@overload
def _number(function: str, name: str, value: None, kind: type = ...) -> None: ...


@overload
def _number(function: str, name: str, value: float, kind: _typing.Type[int]) -> int: ...


@overload
def _number(function: str, name: str, value: float, kind: _typing.Type[float] = ...) -> float: ...


@overload
def _number(function: str, name: str, value: Optional[float],
            kind: _typing.Type[int]) -> Optional[int]: ...


@overload
def _number(function: str, name: str, value: Optional[float],
            kind: _typing.Type[float] = ...) -> Optional[float]: ...


def _number(function: str, name: str, value: Any, kind: type = float) -> Union[int, float, None]:
    """None, or the value as a float (or int); ValueError naming the argument otherwise (NaN
    and infinities too: a number the computation cannot use is never passed on; a bool, which
    Python would take as 0 or 1, too). A whole number outside its range (_core.int_ranges, or
    the range of a C int) is refused with that range."""
    if value is None:
        return None
    if isinstance(value, bool) or (_np is not None and isinstance(value, _np.bool_)):
        raise ValueError(f"{function}: {name} must be a number, got the bool {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{function}: {name} must be a number, got {value!r}") from None
    if not _math.isfinite(number):
        raise ValueError(f"{function}: {name} must be a finite number, got {value!r}")
    if kind is int:
        low, high = _core.int_ranges.get(name, (-2**31, 2**31 - 1))
        if not number.is_integer() or not low <= number <= high:
            raise ValueError(f"{function}: {name} must be a whole number in [{low}, {high}], "
                             f"got {value!r}")
        return int(number)
    return number


def fit_trace(t: ArrayLike, rate: ArrayLike, *, length_m: Optional[float] = None,
              separation_m: Optional[float] = None, mass_kg: Optional[float] = None,
              g: Optional[float] = None, model: Optional[Model] = None, window: Window = None,
              config: Optional[PathArg] = None, max_amplitude_deg: Optional[float] = None,
              min_amplitude_deg: Optional[float] = None, length_std_m: Optional[float] = None,
              separation_std_m: Optional[float] = None, mass_std_kg: Optional[float] = None,
              g_std: Optional[float] = None, gyro_scale_std: Optional[float] = None,
              max_rms_over_noise: Optional[float] = None,
              max_residual_autocorr: Optional[float] = None,
              whiteness_lags: Optional[int] = None,
              max_secondary_motion_ratio: Optional[float] = None,
              min_periods: Optional[float] = None, name: str = "trace") -> Record:
    """Fit the moment of inertia to one swing-rate series, as ``bifilar fit`` does.

    The whole processing of ``bifilar fit`` after reading the log runs on the series: the
    free-oscillation window (or ``window``), the amplitude band, the pendulum-model fit, the
    quality checks and the uncertainty budget. The GIL is released during the fit.

    Parameters
    ----------
    t : array-like, shape (N,)
        Sample times (s), finite and strictly increasing (the log's own clock; gaps are fine).
    rate : array-like, shape (N,)
        Swing rate about the down vertical (rad/s), e.g. ``read_log(...).rate_rad_per_s``.
    length_m, separation_m : float
        Filar length L and separation D (m).
    mass_kg : float
        Whole suspended mass: aircraft + rig + IMU (kg).
    g : float, default 9.80665
        Local gravity (m/s^2), in [9.76, 9.84] (Earth) unless the config sets
        ``gravity_off_earth: true`` (then (0, 100]).
    model : {'full', 'jardin', 'linear'}, default 'full'
        Equation of motion fitted (docs/physics.md).
    window : None, (t0, t1) or 'T0:T1'
        Fit only this window (s, the series' own time) instead of the detected one.
    config : str, optional
        A YAML config (configs/README.md): geometry, masses (aircraft + rig), uncertainties,
        fit settings and quality thresholds are taken from it; keyword arguments given
        override it. Without it, length_m, separation_m and mass_kg are required.
    max_amplitude_deg, min_amplitude_deg : float, optional
        Amplitude band of the fitted part (deg); default as the config's ``fit`` section.
    length_std_m, separation_std_m, mass_std_kg, g_std, gyro_scale_std : float, optional
        1-sigma uncertainties of L, D, m, g and the gyro scale factor (fraction) for the
        uncertainty budget; default the config's, or without one an assumed 1 mm on L and D
        (labelled in ``uncertainty``); any of the first four given (0 too) replaces it.
    max_rms_over_noise, max_residual_autocorr, whiteness_lags, max_secondary_motion_ratio,
    min_periods : optional
        Quality thresholds (``fit.quality`` of the config); default the library's.
    name : str, default 'trace'
        Stands for the file name in the record and in messages.

    Returns
    -------
    Record
        The fields of ``bifilar fit --json`` (``status``, ``message``, ``inertia_total_kg_m2``,
        ``inertia_total_std_kg_m2``, ``window_s``, ``budget``, ...; numbers that do not apply
        are None), plus numpy arrays of the fitted window: ``t_s``, ``measured_rad_per_s``,
        ``fitted_rad_per_s`` (model rate + bias) and ``residual_rad_per_s`` (measured -
        fitted, the sign of the figures' "meas. - fit" panel); empty when no fit ran. A trace the data cannot support has status
        ``'rejected'`` with the reason in ``message``.

    Raises
    ------
    ValueError
        t and rate of different lengths, not finite or t not increasing (naming the argument);
        bad settings; any trace the command line would report as ``error`` (its message).
    FileNotFoundError
        ``config`` does not exist.
    """
    settings: Dict[str, Any] = dict(
                    length_m=length_m, separation_m=separation_m, mass_kg=mass_kg, g=g,
                    model=model, window=window, config=config,
                    max_amplitude_deg=max_amplitude_deg, min_amplitude_deg=min_amplitude_deg,
                    length_std_m=length_std_m, separation_std_m=separation_std_m,
                    mass_std_kg=mass_std_kg, g_std=g_std, gyro_scale_std=gyro_scale_std,
                    max_rms_over_noise=max_rms_over_noise,
                    max_residual_autocorr=max_residual_autocorr, whiteness_lags=whiteness_lags,
                    max_secondary_motion_ratio=max_secondary_motion_ratio,
                    min_periods=min_periods, name=name)
    for key, value in settings.items():
        if key not in ("model", "window", "config", "name"):
            settings[key] = _number("fit_trace", key, value,
                                    int if key == "whiteness_lags" else float)
    for key in ("model", "name"):
        if settings[key] is not None:
            settings[key] = str(settings[key])
    settings["config"] = _path("fit_trace", "config", settings["config"])
    record, t_s, measured, fitted, residual = _calling(
        [settings["config"]], _core.fit_trace, _series(t, "t"), _series(rate, "rate"), **settings)
    result = Record(record)
    result["t_s"] = t_s
    result["measured_rad_per_s"] = measured
    result["fitted_rad_per_s"] = fitted
    # measured - fitted, as the figures' "meas. - fit" axis (the core computes fitted - measured)
    result["residual_rad_per_s"] = -residual
    return result


def read_log(path: PathArg, config: Optional[PathArg] = None) -> Record:
    """Read an IMU log as ``bifilar fit`` does: the time series its fit uses.

    Parameters
    ----------
    path : str, bytes or os.PathLike
        The log (CSV or ULog, optionally .gz), as given to ``bifilar fit``.
    config : str, optional
        The YAML config naming the columns and units (``imu`` section, configs/README.md).
        Without it, the format is guessed from the file as ``bifilar inspect`` guesses it
        (column names and data; ULog topics), with the default swing-axis settings; the
        guess is in ``format_guessed`` (its ``guesses`` say what was guessed from what).

    Returns
    -------
    Record
        ``t_s`` (N,), ``rate_rad_per_s`` (N,) the swing rate gyro . n, ``gyro_rad_per_s``
        (N, 3), ``accel_mps2`` (N, 3) or None, all in SI and IMU axes; ``axis_in_imu``,
        ``axis_in_body``, ``axis_source`` (the swing axis n and how it was found),
        ``pitch_measured_deg`` and ``roll_measured_deg`` (from the accelerometer at rest, or None),
        ``window_s`` (the config's window for this file, or None), ``warnings`` (repairs made
        while reading), ``notes`` and ``format_guessed`` (None when the config gave the format).
        ``fit_trace(r.t_s, r.rate_rad_per_s, config=config, name=path)`` then gives the
        numbers of ``bifilar fit config path``.

    Raises
    ------
    FileNotFoundError
        ``path`` or ``config`` does not exist.
    ValueError
        The file or config cannot be read or is malformed (the command line's message, naming
        the file, line and column or key); without a config, a file that is not a log
        bifilar recognises (what it looks like instead, as ``bifilar inspect`` says).
    """
    core_path = _path("read_log", "path", path)
    core_config = _path("read_log", "config", config)
    return Record(_calling([core_config, core_path], _core.read_log, core_path, core_config))


def fit_ellipse(pitch_deg: ArrayLike, inertia: ArrayLike, std: Optional[ArrayLike] = None, *,
                bootstrap: int = 2000, seed: int = 1, confidence: float = 0.95,
                covariance: Covariance = "auto") -> Record:
    """Fit the ellipse of inertia to moments measured at several pitch angles.

    I(theta) = I_z cos^2 theta + I_x sin^2 theta + I_xz sin 2 theta (docs/physics.md), as
    ``bifilar ellipse --json``. The GIL is released during the fit.

    Parameters
    ----------
    pitch_deg : array-like, shape (N,)
        Nose-up pitch of each measurement (deg); at least 3 distinct angles.
    inertia : array-like, shape (N,)
        Moment about the swing axis at that pitch (kg m^2), > 0.
    std : array-like, shape (N,), optional
        Standard errors of ``inertia`` (kg m^2): weights 1/std^2.
    bootstrap : int, default 2000
        Parametric bootstrap replicates for the intervals (0: covariance intervals).
    seed : int, default 1
        Seed of the bootstrap.
    confidence : float, default 0.95
        Confidence level of the intervals.
    covariance : {'auto', 'points', 'angle_means', 'absolute'}
        How the covariance is scaled (README, ``bifilar ellipse``).

    Returns
    -------
    Record
        ``Ix_kg_m2``, ``Iz_kg_m2``, ``Ixz_kg_m2``, ``tau_deg``, ``Ixp_kg_m2``, ``Izp_kg_m2``,
        each with ``_std`` and ``_ci95`` variants, plus ``rmse_kg_m2``, ``angles``,
        ``residuals``, ``warnings``, ... (the ``bifilar ellipse --json`` document). The
        residuals, one per point, are :class:`Columns`: ``residuals.studentized`` is a numpy
        array, ``residuals[i]`` the row as in the CLI's JSON (memory ~49 bytes a point, so
        1e6 points fit in about the memory of ``bifilar ellipse``).

    Raises
    ------
    ValueError
        Arrays of different lengths or not finite (naming the argument), fewer than 3 angles,
        non-positive inertia, bad options.
    """
    std_array = None if std is None else _series(std, "std")
    bootstrap = _number("fit_ellipse", "bootstrap", bootstrap, int)
    seed = _seed("fit_ellipse", seed)
    if bootstrap < 0:
        raise ValueError("fit_ellipse: bootstrap must be >= 0")
    result = Record(_core.fit_ellipse(_series(pitch_deg, "pitch_deg"), _series(inertia, "inertia"),
                                      std_array, bootstrap, seed,
                                      _number("fit_ellipse", "confidence", confidence),
                                      str(covariance)))
    dict.__setitem__(result, "residuals", Columns(result["residuals"]))
    return result


def down_in_body(roll_deg: ArrayLike, pitch_deg: ArrayLike) -> FloatArray:
    """The down vertical in body axes of an aircraft hung at roll and pitch (deg), a numpy array.

    n = (-sin pitch, sin roll cos pitch, cos roll cos pitch) (docs/physics.md 3.5); scalars give
    shape (3,), arrays of N attitudes shape (N, 3). A NaN or infinite angle raises ValueError.
    """
    angles = {"roll_deg": _series(roll_deg, "roll_deg"), "pitch_deg": _series(pitch_deg, "pitch_deg")}
    for name, value in angles.items():
        bad = _np.flatnonzero(~_np.isfinite(value))
        if bad.size:  # NaN in, NaN out would pass for an axis
            where = "" if value.ndim == 0 else "[%d]" % bad[0]
            raise ValueError("down_in_body: %s%s is %r; every angle must be a finite number (deg)"
                             % (name, where, float(value.flat[bad[0]])))
    roll = _np.radians(angles["roll_deg"])
    pitch = _np.radians(angles["pitch_deg"])
    return _np.stack([-_np.sin(pitch), _np.sin(roll) * _np.cos(pitch),
                      _np.cos(roll) * _np.cos(pitch)], axis=-1)


def fit_tensor(directions: ArrayLike, inertias: ArrayLike, stds: Optional[ArrayLike] = None, *,
               nominal: Optional[ArrayLike] = None, groups: Optional[Iterable[int]] = None,
               bootstrap: int = 2000, seed: int = 1, confidence: float = 0.95,
               covariance: Covariance = "auto", common_offset_std: float = 0.0,
               attitude_scatter: bool = True) -> Record:
    """Fit the full inertia tensor to moments measured about swing axes in any body direction.

    I(n) = n^T J n with J = [[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]]
    (products positive: Ixy = integral x y dm; docs/physics.md 3.5), by weighted least squares
    (Ceres) over what the axes determine; components they do not determine are None and named
    in ``unobservable``. As ``bifilar process`` fits a campaign that rolls; the GIL is released.

    Parameters
    ----------
    directions : array-like, shape (N, 3)
        Swing axis of each moment in body axes (x forward, y right wing, z down); any length.
        ``down_in_body(roll_deg, pitch_deg)`` gives them from attitudes.
    inertias : array-like, shape (N,)
        Moment about that axis (kg m^2), > 0.
    stds : array-like, shape (N,), optional
        Standard errors of ``inertias`` (kg m^2).
    nominal : array-like, shape (N, 3), optional
        The planned axes (when ``directions`` are measured ones): they decide what the design
        observes. Default: ``directions``.
    groups : sequence of int, optional
        Orientation of each moment (trials of one attitude share it). Default: by axis.
    bootstrap, seed, confidence, covariance
        As ``fit_ellipse`` (covariance 'angle_means' uses the orientations' means).
    common_offset_std : float, default 0
        Std of an offset shared by every moment (the rig inertia): enters Ixx, Iyy, Izz.
    attitude_scatter : bool, default True
        Weigh by the scatter an attitude error explains (docs/method.md 16).

    Returns
    -------
    Record
        ``Ixx_kg_m2`` ... ``Iyz_kg_m2`` each with ``_std`` and ``_ci95``, ``covariance_kg2_m4``,
        ``principal_moments_kg_m2`` (ascending), ``principal_axes``, ``principal_euler_deg``,
        ``condition_number``, ``unobservable``, ``residuals``, ``orientations``, ``warnings``.

    Raises
    ------
    ValueError
        Arrays of different lengths, not finite or of the wrong shape (naming the argument),
        non-positive inertia, nothing observable (naming the components), bad options.
    """
    direction_array = _series(directions, "directions")
    nominal_array = None if nominal is None else _series(nominal, "nominal")
    std_array = None if stds is None else _series(stds, "stds")
    bootstrap = _number("fit_tensor", "bootstrap", bootstrap, int)
    seed = _seed("fit_tensor", seed)
    if bootstrap < 0:
        raise ValueError("fit_tensor: bootstrap must be >= 0")
    group_list = None if groups is None else [int(g) for g in groups]
    return Record(_core.fit_tensor(direction_array, _series(inertias, "inertias"), std_array,
                                   nominal_array, group_list, bootstrap, seed,
                                   _number("fit_tensor", "confidence", confidence),
                                   str(covariance),
                                   _number("fit_tensor", "common_offset_std", common_offset_std),
                                   bool(attitude_scatter)))


def process(config_path: PathArg, out: Optional[PathArg] = None, jobs: Optional[int] = None, *,
            force: bool = False, figures: bool = True, progress: Progress = None) -> Record:
    """Process a campaign as ``bifilar process CONFIG --out OUT --jobs JOBS``.

    Fits every log (in parallel, with the cache in OUT/cache), subtracts the rig, fits the
    ellipse and writes results.json, traces.csv, angles.csv, report.html and figures into OUT.
    The GIL is released while the fits run. Ctrl-C raises ``KeyboardInterrupt`` as soon as the
    fits running have finished (well within a second); the finished fits stay in the cache, no
    result file is written, and the next call goes on from the cache.

    Parameters
    ----------
    config_path : str
        The campaign config (YAML, configs/README.md).
    out : str, optional
        Output folder; default ``out/`` beside the config.
    jobs : int, optional
        Worker threads; default all cores.
    force : bool, default False
        Ignore the cache and refit every log (``--force``).
    figures : bool, default True
        Draw the per-trace figures, Fig. 3/4 and report.html (False: results files only).
    progress : None, True, "bar" or callable, default None
        None or False: quiet. True or "bar": a text bar on stderr. A callable is called as
        ``progress(done, total, line)`` after every fit (``line``: "pitch_10/trial_1.csv: ok
        I_total = ..."); an exception it raises stops the run and is raised here.

    Returns
    -------
    Record
        The parsed OUT/results.json: ``summary``, ``rig``, ``traces`` (one record per log,
        the fields of ``bifilar fit --json`` plus the campaign's), ``angles``, ``ellipse``,
        ``table1``, ...

    Raises
    ------
    ValueError
        Config or usage problems (the command line's exit code 2, with its message). Problems
        with single logs are records with status ``error``, not exceptions.
    FileNotFoundError
        ``config_path`` does not exist.
    KeyboardInterrupt
        Ctrl-C.
    """
    callback = progress if callable(progress) else None
    bar = progress is True or progress == "bar"
    if progress not in (None, False, True, "bar") and callback is None:
        raise ValueError("process: progress must be None, True, 'bar' or a callable "
                         "progress(done, total, line), got %r" % (progress,))
    core_config = _path("process", "config_path", config_path)
    return Record(_calling([core_config], _core.process, core_config,
                           _path("process", "out", out), _number("process", "jobs", jobs, int),
                           bool(force), bool(figures), bar, callback))


def simulate(spec: Optional[PathArg] = None, *, out: Optional[PathArg] = None,
             trace: Optional[PathArg] = None, truth: Optional[PathArg] = None,
             seed: Optional[int] = None, model: Optional[Model] = None,
             inertia_kg_m2: Optional[float] = None, mass_kg: Optional[float] = None,
             length_m: Optional[float] = None, separation_m: Optional[float] = None,
             g: Optional[float] = None, amplitude_deg: Optional[float] = None,
             pitch_deg: Optional[float] = None, duration_s: Optional[float] = None,
             sample_rate_hz: Optional[float] = None, no_accel: bool = False,
             force: bool = False) -> Record:
    """Simulate realistic IMU logs with known truth, as ``bifilar simulate``.

    Three uses:

    * ``simulate(spec, out=DIR)``: a campaign from a spec with ``aircraft``, ``rig`` and
      ``campaign`` sections (e.g. configs/simulate_prandtl_d.yaml) written to DIR.
    * ``simulate(inertia_kg_m2=I, mass_kg=m, length_m=L, separation_m=D, trace='x.csv')``: one
      trace written to a CSV (and its truth JSON beside it, or to ``truth``).
    * the same without ``trace``: the trace is returned as arrays, nothing is left on disk.

    Parameters
    ----------
    spec : str, optional
        Simulation spec (YAML); sensor, timeline and format settings and the defaults.
    seed : int, optional
        Random seed (default: the spec's, or 1).
    model : {'full', 'jardin', 'linear'}, optional
        The truth's equation of motion.
    inertia_kg_m2, mass_kg : float
        Single trace: whole suspended inertia I (kg m^2) and mass m (kg).
    length_m, separation_m, g : float
        Filar length L, separation D (m) and gravity (m/s^2).
    amplitude_deg, pitch_deg : float
        Single trace: psi at release (default 20 deg) and the body's true pitch (default 0).
    duration_s, sample_rate_hz : float
        Free-oscillation duration (s) and IMU sample rate (Hz).
    no_accel : bool
        Write no accelerometer.
    force : bool
        Replace files that exist (``trace``, ``truth``, the files of ``out``); without it an
        existing file is refused (ValueError naming it). Every log written is marked as
        simulated, with its seed.

    Returns
    -------
    Record
        ``truth`` (the parsed truth JSON), ``samples_written``, ``samples_dropped``,
        ``truth_path``; for a campaign ``files_written`` and ``out``; for one trace ``t_s``,
        ``gyro_rad_per_s`` (N, 3) and ``accel_mps2`` (N, 3, or None), as read back from the
        written CSV (so exactly what ``read_log`` would give), and ``file`` when written.

    Raises
    ------
    ValueError
        Missing or out-of-range parameters, bad spec (naming the key), both out and trace.
    FileNotFoundError
        ``spec`` does not exist.
    """
    settings: Dict[str, Any] = dict(
                    spec=spec, out=out, trace=trace, truth=truth, seed=seed, model=model,
                    inertia_kg_m2=inertia_kg_m2, mass_kg=mass_kg, length_m=length_m,
                    separation_m=separation_m, g=g, amplitude_deg=amplitude_deg,
                    pitch_deg=pitch_deg, duration_s=duration_s, sample_rate_hz=sample_rate_hz,
                    no_accel=bool(no_accel), force=bool(force))
    for key in ("spec", "out", "trace", "truth"):
        settings[key] = _path("simulate", key, settings[key])
    if settings["model"] is not None:
        settings["model"] = str(settings["model"])
    for key in ("inertia_kg_m2", "mass_kg", "length_m", "separation_m", "g", "amplitude_deg",
                "pitch_deg", "duration_s", "sample_rate_hz"):
        settings[key] = _number("simulate", key, settings[key])
    settings["seed"] = None if seed is None else _seed("simulate", seed)
    return Record(_calling([settings["spec"]], _core.simulate, **settings))


def watch(source: PathArg, config: PathArg, *, save: Optional[PathArg] = None,
          target_percent: float = 0.5, counter_rate_hz: Optional[float] = None,
          counter_column: str = "count", cycles: Optional[int] = None,
          stop_at_target: bool = False, idle_end_s: Optional[float] = None, append: bool = False,
          serve_port: Optional[int] = None) -> Iterator[Record]:
    """Watch the moment of inertia converge while the body swings, as ``bifilar watch``.

    A generator: each item is a dict, as ``bifilar watch --json`` prints one per line. An update
    has ``t_s``, ``cycles``, ``amplitude_deg``, ``period_s``, ``inertia_kg_m2``,
    ``inertia_std_stat_kg_m2``, ``inertia_std_total_kg_m2``, ``cycles_needed``, ``verdict``
    (``waiting``, ``swinging``, ``enough``, ``swing_again``, ``fix_rig``) and ``reason``; an
    event has ``event`` (a line of news: the saved file, a restart, a disconnect); the last item
    has ``final`` True and the fit of each saved log (``logs[i].record``, the numbers
    ``bifilar fit`` gives on it) and the input counters. Closing the generator (or Ctrl-C) stops
    the watch; the saved log keeps every sample received.

    Parameters
    ----------
    source : str
        A log file being written (followed), ``"-"`` for standard input, or a transport spec
        (``serial:DEV@BAUD``, ``ws://...``, ``mavlink:DEV@BAUD``, ``mavlink-udp:HOST:PORT``).
    config : str
        The config (YAML), as for ``bifilar fit``.
    save : str, optional
        The new CSV every sample is written to (default: time-stamped, beside the config).
    target_percent : float
        Target of the per-swing std of I, in % of I (default 0.5).
    counter_rate_hz : float, optional
        The stream carries a sample counter (``counter_column``) instead of a time, at this rate.
    cycles : int, optional
        End once the fit holds this many cycles.
    stop_at_target : bool
        End at the first ``enough``.
    idle_end_s : float, optional
        End when no sample came for this long (default: keep waiting).
    append : bool
        After a restarted stream, append to the same log (default: start a new one).
    serve_port : int, optional
        Also serve the live page on http://127.0.0.1:PORT/ (0: any free port).
    """
    run = _calling([config], _core.watch_start, _path("watch", "source", source) if source != "-" else "-",
                   _path("watch", "config", config), _path("watch", "save", save) or "",
                   _number("watch", "target_percent", target_percent),
                   _number("watch", "counter_rate_hz", counter_rate_hz) or 0.0,
                   str(counter_column), int(cycles or 0), bool(stop_at_target),
                   _number("watch", "idle_end_s", idle_end_s) or 0.0, bool(append),
                   -1 if serve_port is None else int(serve_port))
    try:
        while True:
            item = run.next()
            if item is None:
                return
            yield Record(item)
    finally:
        run.close()
