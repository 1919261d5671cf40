"""Results of nanofold's commands: the command line's ``--json`` object as attributes, its
numeric lists as numpy arrays, and what the command writes beside it (FOLD files as dicts)."""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Union

import numpy as np


def _as_array(value: Any) -> Any:
    """A list of numbers (or of equal-length lists of numbers) as a float array."""
    if isinstance(value, list) and value:
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            return np.asarray(value, dtype=float)
        if all(isinstance(v, list) for v in value):
            try:
                array = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                return value
            return array if array.ndim == 2 else value
    return value


class Result:
    """One command's answer. Every key of ``to_dict()`` is an attribute (numeric lists as
    numpy arrays); ``trajectory`` holds the fold angles of every recorded step (rad). The
    pattern commands also give ``crease_labels``, ``start_fold_angles_rad``,
    ``final_fold_angles_rad``, ``max_closure_residual_rad`` and ``engine`` whether or not
    their ``--json`` shows them."""

    command: str

    def __init__(self, command: str, summary: str, rest: str = "{}"):
        self.command = command
        self._summary_text = summary
        self._rest_text = rest
        self._summary: Dict[str, Any] = json.loads(summary)
        self._rest_cache: Optional[Dict[str, Any]] = None

    @property
    def _payload(self) -> Dict[str, Any]:
        """Arrays and files beside the summary, read on first use."""
        if self._rest_cache is None:
            self._rest_cache = json.loads(self._rest_text)
        return self._rest_cache

    def to_dict(self) -> Dict[str, Any]:
        """The result as the command line's ``--json`` prints it (less its ``out`` folder)."""
        return copy.deepcopy(self._summary)

    def keys(self) -> List[str]:
        """The result's fields."""
        return list(self._summary)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return _as_array(self._summary[name])
        except KeyError:
            pass
        try:
            return _as_array(self._payload["extra"][name])
        except (KeyError, TypeError):
            raise AttributeError(
                f"{type(self).__name__} of {self.command!r} has no field {name!r}; its fields: {', '.join(self._summary)}"
            ) from None

    def __getitem__(self, name: str) -> Any:
        return self.__getattr__(name)

    def __contains__(self, name: str) -> bool:
        return name in self._summary

    def __dir__(self) -> List[str]:
        extra = self._payload.get("extra") or {}
        return sorted(set(super().__dir__()) | set(self._summary) | set(extra))

    def __getstate__(self) -> Dict[str, Any]:
        return {"command": self.command, "summary": self._summary_text, "rest": self._rest_text}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__init__(state["command"], state["summary"], state["rest"])  # type: ignore[misc]

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Result)
            and self.command == other.command
            and self._summary == other._summary
            and self._payload == other._payload
        )

    @property
    def library_seconds(self) -> float:
        """Wall time in the library for this call, rendering of every output included, s."""
        return float(self._payload.get("library_seconds", float("nan")))

    def __repr__(self) -> str:
        head = self._summary.get("pattern") or self._summary.get("scene") or ""
        verdict = self._summary.get("verdict") or self._summary.get("stop_reason") or self._summary.get("model")
        return f"<{type(self).__name__} {self.command} {head}: {verdict}>"

    @property
    def trajectory(self) -> np.ndarray:
        """Fold angles of every recorded step, rad (steps × creases)."""
        return np.asarray(self._payload.get("trajectory") or [], dtype=float)

    def fold_file(self) -> Optional[Dict[str, Any]]:
        """The FOLD animation the command writes (``fold.fold``, a scene's ``motion.fold``
        or ``modes.fold``), as a dict; None where it writes none."""
        value = self._payload.get("fold_file")
        return copy.deepcopy(value) if value is not None else None


class PatternResult(Result):
    """``check``, ``fold``, ``unfold``: ``verdict`` and ``evidence`` always."""

    @property
    def verdict(self) -> str:
        """The answer, in the command line's words (``flat``, ``rigid``, ``reached``, …)."""
        return str(self._summary.get("verdict") or self._summary.get("stop_reason"))

    @property
    def evidence(self) -> str:
        """Why, in words."""
        return str(self._summary.get("evidence", ""))


class FoldResult(PatternResult):
    """``fold``: the path's progress per step and its end state as FOLD."""

    @property
    def progress_per_step(self) -> np.ndarray:
        """Progress (fraction of full folding) at every step."""
        return np.asarray(self._payload.get("progress") or [], dtype=float)

    def folded_file(self) -> Dict[str, Any]:
        """The end state as a FOLD crease pattern with its fold angles (``folded.fold``)."""
        return copy.deepcopy(self._payload["folded_file"])


class SimulationResult(Result):
    """``simulate``: the summary, and ``response.json`` with every sample."""

    def response(self) -> Dict[str, Any]:
        """``response.json`` as a dict."""
        return copy.deepcopy(self._payload["response"])

    @property
    def times(self) -> np.ndarray:
        """Sample times, s."""
        return np.asarray(self._payload["response"].get("time_s") or [], dtype=float)

    @property
    def angles(self) -> np.ndarray:
        """Fold angles at every sample, rad (samples × hinges)."""
        return np.asarray(self._payload["response"].get("angles_rad") or [], dtype=float)


class FitResult(Result):
    """``fit``: the report (``parameters``, ``correlation``, ``singular_values``,
    ``undetermined``, ``residuals``, ...), the fitted scene and the table of measured against
    fitted values."""

    @property
    def fitted_scene(self) -> "Any":
        """The fitted scene (a nanofold.Scene, ready for ``simulate`` and ``modes``)."""
        from ._core import Scene

        return Scene(self._payload["fitted_scene"], name=f"{self._summary.get('scene', 'scene')}-fitted")

    def fitted_scene_dict(self) -> Dict[str, Any]:
        """The fitted scene file's JSON."""
        return copy.deepcopy(self._payload["fitted_scene"])

    @property
    def table(self) -> "Any":
        """Measured, fitted and residual values per time (a pandas DataFrame, as fit.csv)."""
        import io

        import pandas as pd  # type: ignore[import-untyped]

        return pd.read_csv(io.StringIO(self._payload["table_csv"]))


class NetsResult(Result):
    """``nets``: the report (``solid``, ``symmetry_order``, ``distinct_nets``, ``overlapping``,
    ``nets`` ranked best first, ...), the ranked table, the best nets as FOLD and the gallery."""

    @property
    def table(self) -> "Any":
        """The ranked nets with their scores (a pandas DataFrame, as nets.csv)."""
        import io

        import pandas as pd  # type: ignore[import-untyped]

        return pd.read_csv(io.StringIO(self._payload["table_csv"]))

    @property
    def folds(self) -> List[Dict[str, Any]]:
        """The best nets that can be made, as FOLD crease patterns (net_<rank>.fold)."""
        return copy.deepcopy(self._payload["folds"])

    def write_scenes(self, folder: Union[str, "os.PathLike[str]"]) -> List[Path]:
        """Writes each best net's crease pattern (net_<rank>.fold) and ready device scene
        (net_<rank>.scene.json: every fold released at once towards its target, the centre
        face anchored) into ``folder`` (made if missing); returns the scenes' paths, for
        ``nanofold.simulate``."""
        out = Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for fold, scene in zip(self._payload["folds"], self._payload["scenes"]):
            (out / str(scene["pattern"])).write_text(json.dumps(fold, indent=1))
            path = out / (str(scene["pattern"])[: -len(".fold")] + ".scene.json")
            path.write_text(json.dumps(scene, indent=1))
            written.append(path)
        return written

    @property
    def gallery_svg(self) -> str:
        """The best nets drawn to one scale (gallery.svg)."""
        return str(self._payload["gallery_svg"])
