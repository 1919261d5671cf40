"""Patterns, scenes and the commands on them, over the library's front door."""

from __future__ import annotations

import functools
import json
import math
import os
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, TypeVar, Union

import numpy as np

from . import _native
from ._results import FitResult, FoldResult, NetsResult, PatternResult, Result, SimulationResult
from .errors import InvalidFieldError, NanofoldError, from_native

T = TypeVar("T")
PathLike = Union[str, "os.PathLike[str]"]

# The library's own limits on a pattern and a scene file (io::input).
MAX_FILE_BYTES = {"pattern": 16 << 20, "scene": 1 << 20, "measurement": 64 << 20}


def _call(function: Callable[..., T], *args: Any) -> T:
    try:
        return function(*args)
    except _native.NativeError as error:
        raise from_native(error) from None


def _settings(values: Mapping[str, Any]) -> str:
    """Keywords as the JSON the extension reads; None means "the library's default". A NaN
    or an infinity (which JSON cannot carry) is refused here, naming its keyword."""
    def finite(key: str, v: Any) -> None:
        if isinstance(v, (float, np.floating)) and not math.isfinite(float(v)):
            raise InvalidFieldError(
                f"invalid `{key}`: {v} (a number must be finite)", "invalid_field", key, str(v)
            )
        if isinstance(v, Mapping):
            for x in v.values():
                finite(key, x)
        elif isinstance(v, (list, tuple, np.ndarray)):
            for x in v:
                finite(key, x)

    for key, v in values.items():
        finite(key, v)

    def plain(v: Any) -> Any:
        if isinstance(v, np.generic):
            return v.item()
        if isinstance(v, np.ndarray):
            return v.tolist()
        if isinstance(v, Mapping):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        return v

    return json.dumps({k: plain(v) for k, v in values.items() if v is not None}, allow_nan=True)


def _read_text(path: Path, what: str) -> str:
    try:
        size = path.stat().st_size
    except OSError as error:
        from .errors import FileReadError

        raise FileReadError(f"cannot read {path}: {error.strerror}", "io", "path", str(path)) from None
    if size > MAX_FILE_BYTES[what]:
        from .errors import InvalidFieldError

        raise InvalidFieldError(
            f"invalid `{what}`: {path} ({size} bytes; a {what} file is at most {MAX_FILE_BYTES[what]} bytes)",
            "invalid_field",
            what,
            str(path),
        )
    return path.read_text(encoding="utf-8")


class Pattern:
    """A crease pattern: a single vertex or a sheet of many vertices, as nanofold reads it.

    Built from a file (:meth:`open`), a FOLD dict (:meth:`from_fold`), arrays
    (:meth:`from_arrays`) or a generator (:mod:`nanofold.generate`). It keeps its text, so it
    pickles and travels to workers.

    >>> import nanofold
    >>> p = nanofold.Pattern.open("patterns/many/miura_4x4.fold")
    >>> (p.name, p.engine, len(p.crease_labels))
    ('miura_4x4', 'network', 24)
    """

    def __init__(
        self,
        text: str,
        name: str = "pattern",
        *,
        origin: Optional[str] = None,
        source: Optional[str] = None,
        closure_tol: Optional[float] = None,
        angle_sum_tol: Optional[float] = None,
    ):
        self._text = text
        self._name = name
        self._origin = origin or name
        self._source = source
        self._options = {"closure_tol": closure_tol, "angle_sum_tol": angle_sum_tol}
        self._handle = _call(
            _native.parse_pattern, text, name, self._origin, _settings(self._options), source
        )

    @classmethod
    def open(cls, path: PathLike, *, closure_tol: Optional[float] = None, angle_sum_tol: Optional[float] = None) -> "Pattern":
        """Reads a FOLD file (``.fold``) or a native vertex (``.json``)."""
        path = Path(path)
        text = _read_text(path, "pattern")
        name = path.name
        for suffix in (".fold", ".json"):
            if name.endswith(suffix):
                name = name[: -len(suffix)]
                break
        return cls(text, name, origin=str(path), source=str(path), closure_tol=closure_tol, angle_sum_tol=angle_sum_tol)

    @classmethod
    def from_fold(
        cls,
        fold: Mapping[str, Any],
        name: Optional[str] = None,
        *,
        closure_tol: Optional[float] = None,
        angle_sum_tol: Optional[float] = None,
    ) -> "Pattern":
        """A FOLD object given as a dict (its ``file_title`` names it, else ``name``)."""
        title = name or str(fold.get("file_title") or fold.get("frame_title") or "pattern")
        return cls(json.dumps(fold), title, origin=f"<FOLD dict {title}>", closure_tol=closure_tol, angle_sum_tol=angle_sum_tol)

    @classmethod
    def from_arrays(
        cls,
        vertices: Iterable[Sequence[float]],
        edges: Iterable[Sequence[int]],
        assignments: Iterable[str],
        fold_angles_deg: Optional[Iterable[float]] = None,
        faces: Optional[Iterable[Sequence[int]]] = None,
        name: str = "pattern",
        *,
        closure_tol: Optional[float] = None,
        angle_sum_tol: Optional[float] = None,
    ) -> "Pattern":
        """A pattern from arrays: vertex coordinates (2D flat, or 3D), edges as vertex pairs,
        FOLD assignments (``"M"``, ``"V"``, ``"F"``, ``"B"``, ``"U"``), optional fold angles in
        degrees (FOLD's convention) and faces.

        >>> import nanofold
        >>> p = nanofold.Pattern.from_arrays(
        ...     [[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1]],
        ...     [[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]],
        ...     ["M", "V", "V", "V", "B", "B", "B", "B"], name="cross")
        >>> # Four right angles fold along one line at a time, so not with all four creases.
        >>> p.engine, nanofold.check(p).verdict
        ('network', 'not_rigidly_foldable')
        """
        fold: Dict[str, Any] = {
            "file_spec": 1.1,
            "file_creator": "nanofold (Python)",
            "file_title": name,
            "vertices_coords": np.asarray(vertices, dtype=float).tolist(),
            "edges_vertices": np.asarray(edges, dtype=int).tolist(),
            "edges_assignment": list(assignments),
        }
        if fold_angles_deg is not None:
            fold["edges_foldAngle"] = np.asarray(fold_angles_deg, dtype=float).tolist()
        if faces is not None:
            fold["faces_vertices"] = [list(map(int, f)) for f in faces]
        return cls.from_fold(fold, name, closure_tol=closure_tol, angle_sum_tol=angle_sum_tol)

    @property
    def name(self) -> str:
        """The pattern's name."""
        return str(self._handle.name)

    @property
    def engine(self) -> str:
        """``"vertex"`` (the single-vertex engine answers) or ``"network"``."""
        return str(self._handle.engine)

    @property
    def source(self) -> Optional[str]:
        """The file it was read from."""
        return self._source

    @property
    def crease_labels(self) -> List[str]:
        """Every crease's label, in the order of the angle arrays."""
        return list(self._handle.crease_labels())

    @property
    def fold_angles(self) -> np.ndarray:
        """The fold angles the input gives, rad."""
        return np.asarray(self._handle.fold_angles(), dtype=float)

    def describe(self) -> Dict[str, Any]:
        """Counts (vertices, creases, interior vertices, panels) and the reader's notes."""
        return dict(json.loads(self._handle.describe()))

    def to_fold(self) -> Dict[str, Any]:
        """The input as a dict (the FOLD object or native vertex it was read from)."""
        return dict(json.loads(self._text))

    def __reduce__(self) -> Any:
        return (
            _restore_pattern,
            (self._text, self._name, self._origin, self._source, self._options),
        )

    def __repr__(self) -> str:
        return f"<Pattern {self.name} ({self.engine}, {len(self.crease_labels)} creases)>"


def _restore_pattern(text: str, name: str, origin: str, source: Optional[str], options: Dict[str, Any]) -> Pattern:
    return Pattern(text, name, origin=origin, source=source, **options)


class Scene:
    """A scene (``*.scene.json``): a strip of plates, a closed chain or a network of panels
    with materials, hinges and actuation. Built from a file or a dict; a ``pattern`` path in
    it is read relative to ``base`` (the scene file's folder), which workers must also see.

    >>> import nanofold
    >>> s = nanofold.Scene.open("patterns/bridge_step.scene.json")
    >>> (s.name, s.kind)
    ('bridge_step', 'strip')
    """

    def __init__(self, spec: Mapping[str, Any], *, base: PathLike = ".", name: Optional[str] = None, source: Optional[str] = None):
        self._spec = json.loads(json.dumps(spec))
        self._base = str(base)
        self._fallback = name or str(self._spec.get("name") or "scene")
        self._source = source or f"<scene dict {self._fallback}>"
        self._handle = _call(
            _native.parse_scene, json.dumps(self._spec), self._source, self._fallback, self._base
        )

    @classmethod
    def open(cls, path: PathLike) -> "Scene":
        """Reads a scene file."""
        path = Path(path)
        spec = json.loads(_read_text(path, "scene"))
        name = path.name
        for suffix in (".scene.json", ".json"):
            if name.endswith(suffix):
                name = name[: -len(suffix)]
                break
        return cls(spec, base=path.parent, name=name, source=str(path))

    @property
    def name(self) -> str:
        """The scene's name."""
        return str(self._handle.name)

    @property
    def kind(self) -> str:
        """``"strip"``, ``"closed"`` or ``"network"``."""
        return str(self._handle.kind)

    def to_dict(self) -> Dict[str, Any]:
        """The scene's specification."""
        return dict(json.loads(json.dumps(self._spec)))

    def replace(self, changes: Mapping[str, Any]) -> "Scene":
        """A copy with fields changed, each named by its dotted path (list items by index):
        ``scene.replace({"actuation.etch_rate_um_per_min": 3.0,
        "hinges.0.layers.1.thickness_um": 0.05})``. A path that is not in the scene is refused."""
        spec = self.to_dict()
        for dotted, value in changes.items():
            node: Any = spec
            keys = dotted.split(".")
            for key in keys[:-1]:
                node = _child(node, key, dotted)
            _child(node, keys[-1], dotted)
            if isinstance(node, list):
                node[int(keys[-1])] = value
            else:
                node[keys[-1]] = value
        return Scene(spec, base=self._base, name=self._fallback, source=self._source)

    def __reduce__(self) -> Any:
        return (_restore_scene, (self._spec, self._base, self._fallback, self._source))

    def __repr__(self) -> str:
        return f"<Scene {self.name} ({self.kind})>"


def _child(node: Any, key: str, dotted: str) -> Any:
    from .errors import InvalidFieldError

    try:
        return node[int(key)] if isinstance(node, list) else node[key]
    except (KeyError, IndexError, ValueError, TypeError):
        raise InvalidFieldError(
            f"invalid `{dotted}`: no such field in the scene ({key!r} not found)", "invalid_field", dotted, key
        ) from None


def _restore_scene(spec: Dict[str, Any], base: str, name: str, source: str) -> Scene:
    return Scene(spec, base=base, name=name, source=source)


#: What the pattern functions take: a path, a :class:`Pattern`, or a FOLD object as a dict.
PatternLike = Union[Pattern, PathLike, Mapping[str, Any]]
#: What the scene functions take: a path, a :class:`Scene`, or a scene file's dict.
SceneLike = Union[Scene, PathLike, Mapping[str, Any]]


def _pattern(pattern: PatternLike) -> Pattern:
    if isinstance(pattern, Pattern):
        return pattern
    if isinstance(pattern, Mapping):
        return Pattern.from_fold(pattern)
    if isinstance(pattern, (str, os.PathLike)):
        return Pattern.open(pattern)
    raise TypeError(
        f"pattern: expected a path, a nanofold.Pattern or a FOLD dict, got {type(pattern).__name__}"
    )


def _scene(scene: SceneLike) -> Scene:
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):
        return Scene(scene)
    if isinstance(scene, (str, os.PathLike)):
        return Scene.open(scene)
    raise TypeError(f"scene: expected a path, a nanofold.Scene or a scene dict, got {type(scene).__name__}")


def check(pattern: PatternLike, *, closure_tol: Optional[float] = None) -> PatternResult:
    """The pattern's verdict: a single vertex by unfolding it; a sheet of many vertices by its
    state (``rigid``, ``not_rigid``, ``self_intersecting``) or, flat, its assignment
    (``rigidly_foldable``, ``not_rigidly_foldable``, ``unknown``), with evidence.

    >>> import nanofold
    >>> nanofold.check("patterns/many/miura_4x4.fold").verdict
    'rigidly_foldable'
    """
    p = _pattern(pattern)
    summary, rest = _call(_native.check, p._handle, _settings({"closure_tol": closure_tol}))
    return PatternResult("check", summary, rest)


def unfold(
    pattern: PatternLike,
    *,
    energy: Optional[str] = None,
    p: Optional[float] = None,
    qp: Optional[str] = None,
    flat_tol: Optional[float] = None,
    max_iterations: Optional[int] = None,
    bending_metric: Optional[float] = None,
    restarts: Optional[int] = None,
    seed: Optional[int] = None,
) -> PatternResult:
    """Unfolds a folded pattern to flat by energy descent; ``verdict`` is ``flat``, ``locked``,
    ``local_minimum``, ``not_rigid``, … Keywords are the library's ``UnfoldSettings``
    (``energy``: ``"separable"`` or ``"non_separable"``; ``qp``: ``"clarabel"`` or ``"direct"``).

    >>> import nanofold
    >>> r = nanofold.unfold("patterns/miura_vertex.fold")
    >>> r.verdict, bool(abs(r.final_fold_angles_rad).max() < 1e-6)
    ('flat', True)
    """
    pat = _pattern(pattern)
    keywords = dict(energy=energy, p=p, qp=qp, flat_tol=flat_tol, max_iterations=max_iterations,
                    bending_metric=bending_metric, restarts=restarts, seed=seed)
    summary, rest = _call(_native.unfold, pat._handle, _settings(keywords))
    return PatternResult("unfold", summary, rest)


def fold(
    pattern: PatternLike,
    *,
    to: Optional[float] = None,
    drive: Optional[Mapping[int, float]] = None,
    frames: Optional[int] = None,
    max_step: Optional[float] = None,
    max_steps: Optional[int] = None,
    drive_to_targets: Optional[bool] = None,
) -> FoldResult:
    """Folds a pattern rigidly: from flat along its assignment until the most folded crease
    reaches ``to`` % of 180° (a percentage, default 100, as ``fold --to``), or ``drive`` =
    {FOLD edge index: angle in degrees} (as ``fold --drive EDGE=DEG``). A file whose
    ``edges_foldAngle`` are targets folds every crease towards them (``to`` % of the way);
    ``drive_to_targets`` (as ``fold --drive-to-targets``) asks for that, or with ``False``
    the assignment instead; on a file whose angles are a folded state, ``True`` folds from
    flat to it. ``frames`` snapshots
    go into the FOLD animation (``fold_file()``); ``max_step`` is the largest change of any
    fold angle in one step, degrees (as ``fold --max-step``).

    >>> import nanofold
    >>> r = nanofold.fold("patterns/many/miura_4x4.fold", to=50, frames=5)
    >>> r.verdict, r.dof, len(r.fold_file()["file_frames"])
    ('reached', 1, 5)
    """
    pat = _pattern(pattern)
    keywords = dict(to=to, drive=drive, frames=frames, max_step=max_step, max_steps=max_steps,
                    drive_to_targets=drive_to_targets)
    summary, rest = _call(_native.fold, pat._handle, _settings(keywords))
    return FoldResult("fold", summary, rest)


def constraints(
    pattern: PatternLike,
    *,
    drive: int,
    lock: Optional[Mapping[int, float]] = None,
    free: Optional[Sequence[int]] = None,
    degree: Union[int, str, None] = None,
    tol: Optional[float] = None,
    range: Optional[Sequence[float]] = None,
    samples: Optional[int] = None,
    source: Optional[str] = None,
    check: Optional[Sequence[Tuple[int, Sequence[float]]]] = None,
    format: Optional[str] = None,
) -> Result:
    """Constraint curves: every free crease as a polynomial of the ``drive`` crease (the
    file's crease index: a FOLD edge index), swept by exact loop closure over ``range``
    (degrees, as ``constraints --range A:B``), with each curve's error. ``lock`` holds
    creases at angles in degrees (``--lock J=DEG``); ``degree`` is 1..20 or ``"auto"`` with
    ``tol`` (rad). ``source`` is ``"sweep"`` (exact) or, for a single vertex, ``"unfold"``;
    ``check`` measures given polynomials, ``[(crease, [c0, c1, ...]), ...]`` in degrees
    (``--check J=C0,C1,...``); ``format="mujoco"`` caps ``degree="auto"`` at 4.

    >>> import nanofold
    >>> c = nanofold.constraints("patterns/miura_vertex.fold", drive=0, degree=6)
    >>> bool(c.max_closure_residual < 1e-3)
    True
    """
    pat = _pattern(pattern)
    keywords = dict(drive=drive, lock=lock, free=list(free) if free is not None else None,
                    degree=degree, tol=tol, range=list(range) if range is not None else None, samples=samples,
                    source=source, check=[[c, list(k)] for c, k in check] if check is not None else None,
                    format=format)
    summary, rest = _call(_native.constraints, pat._handle, _settings(keywords))
    return Result("constraints", summary, rest)


def simulate(
    scene: SceneLike,
    *,
    model: Optional[str] = None,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    t_end: Optional[float] = None,
    ignore_collisions: Optional[bool] = None,
    max_steps: Optional[int] = None,
) -> SimulationResult:
    """A scene's response to its actuation (``model``: ``"auto"``, ``"dynamic"``,
    ``"quasi_static"``; ``method``: ``"auto"``, ``"bdf"``, ``"esdirk34"``, ``"tr_bdf2"``,
    ``"tsit45"``); ``times`` and ``angles`` are the samples, ``collision`` the first contact.

    >>> import nanofold
    >>> r = nanofold.simulate("patterns/bridge_ramp.scene.json")
    >>> r.model, r.collision["pair"]
    ('quasi_static', ['plate 3', 'substrate'])
    """
    s = _scene(scene)
    keywords = dict(model=model, method=method, rtol=rtol, t_end=t_end,
                    ignore_collisions=ignore_collisions, max_steps=max_steps)
    summary, rest = _call(_native.simulate, s._handle, _settings(keywords))
    return SimulationResult("simulate", summary, rest)


def fit(
    scene: SceneLike,
    measured: Any,
    *,
    free: Any,
    noise: Any = None,
    rtol: Optional[float] = None,
    max_iterations: Optional[int] = None,
    method: Optional[str] = None,
) -> FitResult:
    """Fits a scene's parameters to a measured trajectory (``nanofold fit``): ``measured`` is a
    pandas DataFrame or a CSV file (``time_s`` and columns such as ``crease_3_deg``; NaN or
    empty where nothing was seen); ``free`` names each parameter by its path in the scene file
    with its bounds, ``{"environment.drag_coefficient": (0.5, 4)}`` or
    ``["environment.drag_coefficient=0.5:4"]``; ``noise`` is one σ for every column, a dict by
    column, or None to estimate it. The result has the estimates (``parameters``), what the
    data cannot separate (``undetermined``), the residuals, ``fitted_scene`` (a Scene) and
    ``table`` (measured against fitted, a DataFrame).

    >>> import nanofold
    >>> r = nanofold.fit("patterns/bridge_step.scene.json",
    ...                  "patterns/measurements/bridge_step_measured.csv",
    ...                  free={"environment.drag_coefficient": (0.2, 5)})
    >>> r.status, r.parameters[0]["determined"]
    ('converged', True)
    """
    s = _scene(scene)
    if isinstance(measured, (str, os.PathLike)):
        path = Path(measured)
        text, source = _read_text(path, "measurement"), str(path)
    elif hasattr(measured, "to_csv") and hasattr(measured, "columns"):  # a pandas DataFrame
        text, source = measured.to_csv(index=False), "<DataFrame>"
    else:
        raise TypeError(f"measured: expected a path or a pandas DataFrame, got {type(measured).__name__}")
    if isinstance(free, Mapping):
        free_list = [{"path": str(k), "lower": float(v[0]), "upper": float(v[1])} for k, v in free.items()]
    elif isinstance(free, (list, tuple)):
        free_list = list(free)
    else:
        raise TypeError(f"free: expected a dict of (lower, upper) or a list of PATH=LOWER:UPPER, got {type(free).__name__}")
    keywords = dict(free=free_list, noise=noise, rtol=rtol, max_iterations=max_iterations, method=method)
    summary, rest = _call(
        _native.fit, json.dumps(s._spec), s._source, s._fallback, s._base, text, source, _settings(keywords)
    )
    return FitResult("fit", summary, rest)


def nets(
    shape: Union[str, "os.PathLike[str]"],
    *,
    max_trees: Optional[int] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    rank_by: Optional[str] = None,
    top: Optional[int] = None,
    unit_um: Optional[float] = None,
    overdrive_deg: Optional[float] = None,
    front_deg: Optional[float] = None,
    etch_rate_um_per_min: Optional[float] = None,
    anchored_face: Optional[int] = None,
    simulate: Optional[int] = None,
    fronts: Optional[int] = None,
    yield_samples: Optional[int] = None,
    stiffness_spread_percent: Optional[float] = None,
    stress_spread_percent: Optional[float] = None,
    capture_percent: Optional[float] = None,
    merge_coplanar: Optional[str] = None,
    client: Any = "threads",
    progress: bool = True,
) -> NetsResult:
    """The distinct nets of a solid and their simulated self-folding (``nanofold nets``):
    ``shape`` is an .obj, .stl, .ply, .off or .fold file (read with the precision of its own
    digits or float width; ``merge_coplanar``: ``"auto"``, ``"always"`` or ``"never"``, as
    ``--merge-coplanar``), or a generated solid (``"cube"``,
    ``"box:1x2x3"``, ``"prism:6"``, ``"polycube:0,0,0;1,0,0"``, ...). Every net is laid flat,
    tested for overlap and scored (radius of gyration, leaves, seam length, footprint);
    ``rank_by`` is ``"radius_of_gyration"`` (default), ``"seam_length"``, ``"footprint"`` or
    ``"yield"``. The best ``simulate`` nets that can be made are folded with their seams
    latching (within ``capture_percent`` of a seam's length), released by an etch front
    along ``fronts`` directions (or ``front_deg`` alone; ``fronts=0``: all at once), each
    release's nominal device and ``yield_samples`` devices varied by
    ``stiffness_spread_percent`` and ``stress_spread_percent``. The ``top`` best come back as
    FOLD crease patterns with ready device scenes (hinges driven ``overdrive_deg`` past
    closing, released their best way, ``anchored_face`` held; default the centre face).

    ``client`` runs the study: ``"threads"`` (default: this machine's cores, as the command
    line), or as :func:`nanofold.sweep` takes it: a ``dask.distributed.Client``, a scheduler
    address or file, ``None`` (a ``LocalCluster``) or ``"serial"``; one task per net and
    release.

    >>> import nanofold
    >>> r = nanofold.nets("cube", top=3, simulate=0)
    >>> r.distinct_nets, r.symmetry_order, len(r.folds)
    (11, 48, 3)
    """
    keywords = dict(max_trees=max_trees, samples=samples, seed=seed, rank_by=rank_by, top=top, unit_um=unit_um,
                    overdrive_deg=overdrive_deg, front_deg=front_deg, etch_rate_um_per_min=etch_rate_um_per_min,
                    anchored_face=anchored_face, simulate=simulate, fronts=fronts, yield_samples=yield_samples,
                    stiffness_spread_percent=stiffness_spread_percent, stress_spread_percent=stress_spread_percent,
                    capture_percent=capture_percent, merge_coplanar=merge_coplanar)
    settings = _settings(keywords)
    shape_text = os.fspath(shape)
    if isinstance(client, str) and client == "threads":
        summary, rest = _call(_native.nets, shape_text, settings)
        return NetsResult("nets", summary, rest)
    import time

    from ._sweep import sweep

    clock = time.perf_counter()
    table = json.loads(_call(_native.nets_table, shape_text, settings))
    rows = table["report"]["nets"]
    chosen = [r for r in rows if not r["overlapping"] and r.get("touching") is False][: table["simulate"]]
    releases = table["releases"]
    grid = [
        {"rank": row["rank"], "folds": " ".join(str(k) for k in row["folds"]), "release": k}
        for row in chosen
        for k in range(len(releases))
    ]
    by_rank: Dict[int, List[Any]] = {row["rank"]: [None] * len(releases) for row in chosen}
    if grid:
        task = functools.partial(_net_release, shape_text, settings)
        done = sweep(task, grid, client=client, progress=progress)
        failed = done[done["error"].notna()]
        if len(failed):
            first = failed.iloc[0]
            raise NanofoldError(f"a study job failed (net {first['rank']}, release {first['release']}): {first['error']}")
        for _, job in done.iterrows():
            by_rank[int(job["rank"])][int(job["release"])] = json.loads(job["result"])
    study = {"by_rank": [[rank, results] for rank, results in by_rank.items()], "seconds": time.perf_counter() - clock}
    summary, rest = _call(_native.nets_with_study, shape_text, settings, json.dumps(study))
    return NetsResult("nets", summary, rest)


def _net_release(shape: str, settings: str, rank: int, folds: str, release: int) -> Dict[str, Any]:
    """One job of a nets study (on a worker): the release's result as JSON."""
    del rank  # a label of the job's row
    return {"result": _call(_native.nets_release, shape, settings, [int(k) for k in folds.split()], release)}


def modes(scene: SceneLike) -> Result:
    """Natural frequencies (Hz), mode shapes and stability at the scene's folded equilibrium.

    >>> import nanofold
    >>> m = nanofold.modes("patterns/bridge_step.scene.json")
    >>> m.stable, len(m.frequencies_hz)
    (True, 4)
    """
    s = _scene(scene)
    summary, rest = _call(_native.modes, s._handle)
    return Result("modes", summary, rest)
