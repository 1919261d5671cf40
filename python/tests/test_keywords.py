"""Every numeric keyword of every public call, handed NaN, ±inf, -1, 0 and 1e308.

The walk reads each function's own signature, so a keyword added later is walked too; a
keyword that takes numbers inside a structure (``drive={4: 60}``, ``range=[0, 20]``) must say
here how to put a number into it, or the test fails. The answer must be an error that names
the keyword, or a valid result: never a hang, a crash, a None among the result's numbers, or
NaN and inf taken silently. The command line's flags are walked the same way by
``tests/flags.rs``.
"""

from __future__ import annotations

import inspect
import math
import threading
import typing
from typing import Any, Callable, Dict, List, Optional, Tuple

import pytest

import nanofold

BAD = [math.nan, math.inf, -math.inf, -1, 0, 1e308]

# Keywords whose value may be negative (a signed angle, a direction).
SIGNED = {
    "fold.drive", "constraints.lock", "constraints.range", "constraints.check", "nets.front_deg", "miura.fold_deg",
}

# A cheap valid call of each function, as (callable, positional arguments, keywords).
SCENE = "patterns/bridge_step.scene.json"
MEASURED = "patterns/measurements/bridge_step_measured.csv"
BASES: Dict[str, Tuple[Callable[..., Any], Tuple[Any, ...], Dict[str, Any]]] = {
    "check": (nanofold.check, ("patterns/waterbomb.fold",), {}),
    "unfold": (nanofold.unfold, ("patterns/waterbomb.fold",), {}),
    "fold": (nanofold.fold, ("patterns/many/miura_4x4.fold",), {"to": 50, "frames": 3}),
    "constraints": (
        nanofold.constraints,
        ("patterns/degree6_asymmetric.fold",),
        {"drive": 0, "lock": {2: -60, 3: -82.24906982434894}, "range": [70, 80], "samples": 21},
    ),
    "simulate": (nanofold.simulate, (SCENE,), {}),
    "fit": (
        nanofold.fit,
        (SCENE, MEASURED),
        {"free": {"environment.drag_coefficient": (0.2, 5)}, "max_iterations": 3},
    ),
    "nets": (
        nanofold.nets,
        ("tetrahedron",),
        {"simulate": 1, "fronts": 2, "yield_samples": 2, "top": 1, "progress": False},
    ),
    "miura": (nanofold.generate.miura, (), {}),
    "square_twist": (nanofold.generate.square_twist, (), {}),
    "waterbomb": (nanofold.generate.waterbomb, (), {}),
    "bird_base": (nanofold.generate.bird_base, (), {}),
    "Pattern.open": (nanofold.Pattern.open, ("patterns/many/miura_4x4_folded.fold",), {}),
}

# How a number goes into a keyword whose value is a structure: each template takes the value.
TEMPLATES: Dict[str, List[Callable[[Any], Any]]] = {
    "fold.drive": [lambda x: {4: x}],
    "constraints.lock": [lambda x: {1: x}],
    "constraints.range": [lambda x: [x, 80], lambda x: [70, x]],
    "constraints.free": [lambda x: [x]],
    "constraints.check": [lambda x: [(1, [x, 0.5])]],
    "constraints.degree": [lambda x: x],
    "fit.free": [
        lambda x: {"environment.drag_coefficient": (x, 5)},
        lambda x: {"environment.drag_coefficient": (0.2, x)},
    ],
    "fit.noise": [lambda x: x, lambda x: {"hinge_0_deg": x}],
}

# Keywords that take no number: names, switches, clients.
TEXT = {
    "unfold.energy", "unfold.qp", "constraints.source", "constraints.format", "simulate.model", "simulate.method",
    "fit.method", "nets.rank_by", "nets.merge_coplanar", "nets.client", "nets.progress", "fold.drive_to_targets",
    "simulate.ignore_collisions", "square_twist.flip_pleats",
}


def _numeric(annotation: Any) -> bool:
    """Whether a keyword's type is a number (or an optional one)."""
    if annotation in (int, float):
        return True
    args = typing.get_args(annotation)
    return typing.get_origin(annotation) is typing.Union and any(a in (int, float) for a in args) and all(
        a in (int, float, type(None)) for a in args
    )


def _cases() -> List[Tuple[str, str, Any]]:
    cases = []
    unplaced = []
    for name, (function, positional, base) in BASES.items():
        hints = typing.get_type_hints(function)
        parameters = list(inspect.signature(function).parameters.values())
        for parameter in parameters[len(positional):]:
            if parameter.name in ("self", "cls") or parameter.kind == parameter.VAR_KEYWORD:
                continue
            key = f"{name}.{parameter.name}"
            annotation = hints.get(parameter.name, Any)
            if key in TEMPLATES:
                makers = TEMPLATES[key]
            elif _numeric(annotation):
                makers = [lambda x: x]
            elif key in TEXT:
                continue
            else:
                unplaced.append(key)
                continue
            for maker in makers:
                for bad in BAD:
                    cases.append((name, parameter.name, maker(bad)))
    assert not unplaced, f"keywords neither numeric, templated nor known to be text: {unplaced}"
    return cases


CASES = _cases()


def _nulls(value: Any, at: str = "") -> Optional[str]:
    if value is None:
        return at or "the result"
    if isinstance(value, float) and not math.isfinite(value):
        return at
    if isinstance(value, dict):
        for k, v in value.items():
            found = _nulls(v, f"{at}.{k}")
            if found:
                return found
    if isinstance(value, (list, tuple)):
        for k, v in enumerate(value):
            found = _nulls(v, f"{at}[{k}]")
            if found:
                return found
    return None


def _kind(value: Any) -> str:
    flat = repr(value).lower()
    if "nan" in flat:
        return "nan"
    if "inf" in flat:
        return "inf"
    if "-1" in flat and "e-1" not in flat:
        return "negative"
    return "finite"


def test_the_walk_covers_every_call():
    keywords = {(name, keyword) for name, keyword, _ in CASES}
    assert len({name for name, _ in keywords}) == len(BASES)
    assert len(keywords) >= 45, sorted(keywords)


@pytest.mark.parametrize("name,keyword,value", CASES, ids=[f"{n}.{k}={v!r}" for n, k, v in CASES])
def test_a_numeric_keyword_refuses_by_name_or_answers(name, keyword, value, tmp_path):
    function, positional, base = BASES[name]
    keywords = dict(base, **{keyword: value})
    outcome: Dict[str, Any] = {}

    def call() -> None:
        try:
            outcome["result"] = function(*positional, **keywords)
        except BaseException as error:  # noqa: BLE001 (the test sorts them below)
            outcome["error"] = error

    worker = threading.Thread(target=call, daemon=True)
    worker.start()
    worker.join(30)
    assert not worker.is_alive(), f"{name}({keyword}={value!r}) still running after 30 s"
    kind = _kind(value)
    must_refuse = kind in ("nan", "inf") or (kind == "negative" and f"{name}.{keyword}" not in SIGNED)
    if "error" in outcome:
        error = outcome["error"]
        assert isinstance(error, nanofold.NanofoldError), f"{name}({keyword}={value!r}) raised {error!r}"
        assert not isinstance(error, nanofold.InternalError), f"{name}({keyword}={value!r}): {error}"
        assert keyword in str(error) or keyword == (error.field or ""), (
            f"{name}({keyword}={value!r}) refused without naming {keyword}: {error}"
        )
        return
    assert not must_refuse, f"{name}({keyword}={value!r}) was taken (NaN, inf or a negative size must be refused)"
    result = outcome["result"]
    summary = result.to_dict() if hasattr(result, "to_dict") else result.describe()
    found = _nulls(summary)
    assert found is None, f"{name}({keyword}={value!r}): None or a non-finite number at {found}"
