# Type stubs of the extension bifilar._core (python/src/*.cc, pybind11). Each function's
# parameters are those its m.def names, in order, with the types pybind11 converts (its
# docstring's first line: python/tests/test_typing.py checks that they agree, and that every
# name the extension has is here). The documented API is bifilar/__init__.py, which calls these.
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

# pybind11's array_t<double, forcecast>: anything numpy converts to a float64 array.
_Array = npt.ArrayLike
# std::string: a str, or bytes (a file name that is not UTF-8, as bifilar._path passes it).
_Text = Union[str, bytes]

version: str
# The ranges [low, high] of the whole-number arguments, by keyword.
int_ranges: Dict[str, Tuple[int, int]]

def fit_trace(
    t: _Array, rate: _Array, **kwargs: Any
) -> Tuple[Dict[str, Any], npt.NDArray[np.float64], npt.NDArray[np.float64],
           npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def time_fit_trace(t: _Array, rate: _Array, repeats: int, **kwargs: Any) -> List[float]: ...
def read_log(path: _Text, config: Optional[_Text]) -> Dict[str, Any]: ...
def fit_ellipse(
    pitch_deg: _Array,
    inertia: _Array,
    std: Optional[_Array],
    bootstrap: int,
    seed: int,
    confidence: float,
    covariance: str,
) -> Dict[str, Any]: ...
def fit_tensor(
    directions: _Array,
    inertias: _Array,
    stds: Optional[_Array],
    nominal: Optional[_Array],
    groups: Optional[List[int]],
    bootstrap: int,
    seed: int,
    confidence: float,
    covariance: str,
    common_offset_std: float,
    attitude_scatter: bool,
) -> Dict[str, Any]: ...
def process(
    config: _Text,
    out: Optional[_Text],
    jobs: Optional[int],
    force: bool,
    figures: bool,
    progress_bar: bool,
    callback: Optional[Callable[[int, int, str], object]],
) -> Dict[str, Any]: ...
def simulate(**kwargs: Any) -> Dict[str, Any]: ...

class WatchRun:
    # The next item (a dict), or None when the watch has ended.
    def next(self) -> Optional[Dict[str, Any]]: ...
    def close(self) -> None: ...

def watch_start(
    source: _Text,
    config: _Text,
    save: _Text,
    target_percent: float,
    counter_rate_hz: float,
    counter_column: str,
    cycles: int,
    stop_at_target: bool,
    idle_end_s: float,
    append: bool,
    serve_port: int,
) -> WatchRun: ...
