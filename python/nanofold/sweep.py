"""``python -m nanofold.sweep SPEC.json``: a sweep described by a JSON file, for clusters
without notebooks (see :func:`nanofold._sweep.main`).

Importing this module makes ``nanofold.sweep`` this module; it stays callable as the
function :func:`nanofold.sweep`, so ``nanofold.sweep(...)`` works either way.
"""

import sys
import types
from typing import Any

from nanofold._sweep import main, sweep


class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

__all__ = ["main", "sweep"]

if __name__ == "__main__":
    raise SystemExit(main())
