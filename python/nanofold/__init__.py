"""nanofold: rigid origami from Python.

Check, fold and unfold crease patterns (a single vertex or a sheet of many), fit their
constraint curves, simulate the folding dynamics of devices, and sweep any of it over a
parameter grid on Dask. Every result is the command line's ``--json`` object, with its
numeric lists as numpy arrays.

>>> import nanofold
>>> sheet = nanofold.generate.miura(4, 4, angle_deg=60)
>>> nanofold.check(sheet).verdict
'rigidly_foldable'
>>> nanofold.fold(sheet, to=90).verdict
'reached'
"""

from . import generate
from ._core import Pattern, Scene, check, constraints, fit, fold, modes, nets, simulate, unfold
from ._results import FitResult, FoldResult, NetsResult, PatternResult, Result, SimulationResult
from ._sweep import sweep
from .errors import (
    ClosureError,
    FileReadError,
    InputError,
    InternalError,
    InvalidFieldError,
    MissingFieldError,
    NanofoldError,
    NumericalError,
    OutputError,
)
from . import _native

__version__: str = _native.version()

__all__ = [
    "Pattern",
    "Scene",
    "check",
    "fold",
    "unfold",
    "constraints",
    "simulate",
    "modes",
    "fit",
    "nets",
    "sweep",
    "generate",
    "Result",
    "PatternResult",
    "FoldResult",
    "SimulationResult",
    "FitResult",
    "NetsResult",
    "NanofoldError",
    "InputError",
    "InvalidFieldError",
    "MissingFieldError",
    "ClosureError",
    "FileReadError",
    "OutputError",
    "NumericalError",
    "InternalError",
]
