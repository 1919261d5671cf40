"""The exceptions nanofold raises: one hierarchy rooted at :class:`NanofoldError`.

Each carries the library's own words: ``kind`` (what went wrong), ``field`` (the input field
or keyword it concerns, as the command line names it after its flag), ``value`` (the value
refused) and the full message.

>>> import nanofold
>>> try:
...     nanofold.generate.miura(0, 4)
... except nanofold.InvalidFieldError as e:
...     print(e.field)
rows, cols
"""

from __future__ import annotations

from typing import Any, Optional, Tuple


class NanofoldError(Exception):
    """Any error of nanofold."""

    def __init__(self, message: str, kind: str = "other", field: Optional[str] = None, value: Optional[str] = None):
        super().__init__(message)
        self.message = message
        self.kind = kind
        self.field = field or None
        self.value = value or None

    def __reduce__(self) -> Tuple[Any, ...]:  # errors travel from workers to the client
        return (type(self), (self.message, self.kind, self.field, self.value))


class InputError(NanofoldError, ValueError):
    """The input (a file, a keyword, a parameter) is not acceptable."""


class InvalidFieldError(InputError):
    """A field or keyword has a value outside what the library accepts; ``field`` names it."""


class MissingFieldError(InputError):
    """A required field is missing; ``field`` names it."""


class ClosureError(InputError):
    """A folded state does not close its loops within the tolerance."""


class FileReadError(NanofoldError, OSError):
    """A file could not be read or is not JSON."""


class OutputError(NanofoldError, OSError):
    """A file could not be written."""


class NumericalError(NanofoldError, ArithmeticError):
    """A numerical method failed (no convergence, a singular matrix, a step budget)."""


class InternalError(NanofoldError, RuntimeError):
    """A bug in nanofold: please report it with the input."""


_KINDS = {
    "invalid_field": InvalidFieldError,
    "outside_fit_domain": InvalidFieldError,
    "multiple_vertices": InputError,
    "missing_field": MissingFieldError,
    "closure_violated": ClosureError,
    "io": FileReadError,
    "json": FileReadError,
    "output": OutputError,
    "numerical": NumericalError,
    "panic": InternalError,
}


def from_native(error: BaseException) -> NanofoldError:
    """The hierarchy's exception for the extension's ``NativeError(kind, field, value, message)``."""
    kind, field, value, message = error.args
    return _KINDS.get(kind, NanofoldError)(message, kind, field, value)
