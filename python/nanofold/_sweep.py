"""Parameter sweeps on Dask distributed: a task over a grid or a table of parameters,
batched into chunks so a million runs are a thousand scheduler tasks, one row per run, an
error row where a run fails, and resumable from an output folder.

>>> import nanofold
>>> table = nanofold.sweep("check", {"pattern": ["patterns/many/miura_4x4.fold"]}, client="serial", progress=False)
>>> list(table["verdict"])
['rigidly_foldable']
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

from .errors import InvalidFieldError, NanofoldError

#: The commands a sweep runs by name.
TASKS = ("check", "fold", "unfold", "constraints", "simulate", "modes")

#: Chunks in flight per worker thread: enough to keep workers busy, few enough that the
#: scheduler holds a bounded number of tasks whatever the sweep's size.
IN_FLIGHT_PER_THREAD = 4

#: The largest chunk chosen by default (runs per scheduler task).
MAX_DEFAULT_CHUNK = 1000

Task = Union[str, Callable[..., Any]]


class Grid:
    """The runs of a sweep: the product of named value lists (the last name varying fastest,
    as ``itertools.product``) or a table of rows (a list of dicts or a pandas DataFrame)."""

    def __init__(self, grid: Any):
        self.names: List[str]
        self.values: List[List[Any]] = []
        self.table: Optional[List[Dict[str, Any]]] = None
        self.offset = 0
        if hasattr(grid, "to_dict") and hasattr(grid, "columns"):  # a pandas DataFrame
            self.table = [dict(r) for r in grid.to_dict(orient="records")]
            self.names = [str(c) for c in grid.columns]
        elif isinstance(grid, Mapping):
            self.names = [str(k) for k in grid]
            for name, values in grid.items():
                if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                    raise InvalidFieldError(
                        f"invalid `grid.{name}`: {values!r} (each parameter takes a list of values)",
                        "invalid_field",
                        f"grid.{name}",
                        repr(values),
                    )
                self.values.append(list(values))
                if not self.values[-1]:
                    raise InvalidFieldError(
                        f"invalid `grid.{name}`: an empty list (the sweep would have no runs)",
                        "invalid_field",
                        f"grid.{name}",
                        "[]",
                    )
        elif isinstance(grid, Sequence) and all(isinstance(r, Mapping) for r in grid):
            self.table = [dict(r) for r in grid]
            self.names = sorted({str(k) for r in self.table for k in r})
        else:
            raise InvalidFieldError(
                f"invalid `grid`: {type(grid).__name__} (expected a dict of value lists, a list of dicts or a DataFrame)",
                "invalid_field",
                "grid",
                type(grid).__name__,
            )

    def __len__(self) -> int:
        if self.table is not None:
            return len(self.table)
        return math.prod(len(v) for v in self.values)

    def rows(self, start: int, stop: int) -> Iterator[Tuple[int, Dict[str, Any]]]:
        """(run number, parameters) for runs start..stop of this grid."""
        if self.table is not None:
            for k, row in enumerate(self.table[start - self.offset : stop - self.offset]):
                yield start + k, row
            return
        sizes = [len(v) for v in self.values]
        for run in range(start, stop):
            index, rest = [], run
            for size in reversed(sizes):
                index.append(rest % size)
                rest //= size
            index.reverse()
            yield run, {n: v[i] for n, v, i in zip(self.names, self.values, index)}

    def part(self, start: int, stop: int) -> "Grid":
        """The runs start..stop alone (a table's rows are sliced, so a worker gets its own)."""
        if self.table is None:
            return self
        piece = Grid.__new__(Grid)
        piece.names, piece.values, piece.offset = self.names, [], start
        piece.table = self.table[start:stop]
        return piece

    def fingerprint(self) -> Any:
        if self.table is not None:
            return [{k: _label(v) for k, v in r.items()} for r in self.table]
        return {n: [_label(v) for v in values] for n, values in zip(self.names, self.values)}


def _label(value: Any) -> Any:
    """A parameter as a table cell: patterns and scenes by their file or name."""
    from ._core import Pattern, Scene

    if isinstance(value, Pattern):
        return value.source or value.name
    if isinstance(value, Scene):
        return value._source
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "item") and callable(value.item):  # numpy scalars
        try:
            return value.item()
        except (TypeError, ValueError):
            pass
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)


def _scalars(value: Any) -> Dict[str, Any]:
    """A result's scalars: its top-level numbers, strings and booleans, and those one level
    down in objects (``collision.time_s``); lists are left out (arrays belong to results)."""
    from ._results import Result

    if isinstance(value, Result):
        value = value.to_dict()
    if not isinstance(value, Mapping):
        return {"value": _label(value)}
    row: Dict[str, Any] = {}
    for key, item in value.items():
        if isinstance(item, Mapping):
            for inner, x in item.items():
                if x is None or isinstance(x, (bool, int, float, str)):
                    row[f"{key}.{inner}"] = x
        elif item is None or isinstance(item, (bool, int, float, str)):
            row[str(key)] = item
        elif hasattr(item, "item") and getattr(item, "ndim", 1) == 0:
            row[str(key)] = item.item()
    return row


def _builtin(task: str, params: Dict[str, Any], settings: Mapping[str, Any]) -> Any:
    from . import _core

    p = dict(settings)
    p.update(params)
    if task in ("simulate", "modes"):
        if "scene" not in p:
            raise InvalidFieldError(f"the `{task}` task needs a `scene` parameter", "missing_field", "scene", None)
        scene = p.pop("scene")
        scene = scene if isinstance(scene, _core.Scene) else _core.Scene.open(scene)
        changes = {k: p.pop(k) for k in list(p) if "." in k}
        if changes:
            scene = scene.replace(changes)
        return _core.simulate(scene, **p) if task == "simulate" else _core.modes(scene, **p)
    if "pattern" not in p:
        raise InvalidFieldError(f"the `{task}` task needs a `pattern` parameter", "missing_field", "pattern", None)
    pattern = p.pop("pattern")
    return getattr(_core, task)(pattern, **p)


def run_one(task: Task, params: Dict[str, Any], settings: Mapping[str, Any]) -> Dict[str, Any]:
    """One run's row: its result's scalars, or its error, and its wall time."""
    clock = time.perf_counter()
    row: Dict[str, Any]
    try:
        out = task(**params) if callable(task) else _builtin(task, params, settings)
        row = _scalars(out)
        row["error"] = None
        row["error_kind"] = None
    except NanofoldError as error:
        row = {"error": f"{type(error).__name__}: {error}", "error_kind": error.kind}
    except Exception as error:  # one bad case never stops the sweep
        row = {"error": f"{type(error).__name__}: {error}", "error_kind": "python"}
    row["run_seconds"] = time.perf_counter() - clock
    return row


def run_chunk(task: Task, grid: Grid, start: int, stop: int, settings: Mapping[str, Any]) -> List[Dict[str, Any]]:
    """Runs start..stop of the grid (on a worker): one row each, its parameters first."""
    rows = []
    for run, params in grid.rows(start, stop):
        row: Dict[str, Any] = {"run": run}
        row.update({f"{k}": _label(v) for k, v in params.items()})
        for key, value in run_one(task, params, settings).items():
            row[key if key not in params and key != "run" else f"result.{key}"] = value
        rows.append(row)
    return rows


def _task_name(task: Task) -> str:
    if isinstance(task, str):
        return task
    return f"{getattr(task, '__module__', '?')}.{getattr(task, '__qualname__', repr(task))}"


class _Store:
    """An output folder: ``sweep.json`` (what the sweep is), ``parts/part-NNNNNN.parquet``
    (one per finished chunk, each written whole by a rename) and ``results.parquet``."""

    def __init__(self, folder: Path, description: Dict[str, Any]):
        self.folder = folder
        self.parts = folder / "parts"
        meta = folder / "sweep.json"
        if meta.exists():
            held = json.loads(meta.read_text())
            if held.get("fingerprint") != description["fingerprint"]:
                raise InvalidFieldError(
                    f"invalid `out`: {folder} holds another sweep ({held.get('task')}, {held.get('runs')} runs, "
                    "other parameters or chunking); give another folder or remove this one",
                    "invalid_field",
                    "out",
                    str(folder),
                )
        else:
            folder.mkdir(parents=True, exist_ok=True)
            _write_whole(meta, json.dumps(description, indent=1, default=str).encode())
        self.parts.mkdir(exist_ok=True)

    def path(self, k: int) -> Path:
        return self.parts / f"part-{k:06d}.parquet"

    def has(self, k: int) -> bool:
        return self.path(k).exists()

    def write(self, k: int, rows: List[Dict[str, Any]]) -> None:
        import pandas as pd  # type: ignore[import-untyped]

        target = self.path(k)
        temporary = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        _frame(pd, rows).to_parquet(temporary, index=False)
        os.replace(temporary, target)

    def read(self, k: int) -> List[Dict[str, Any]]:
        import pandas as pd  # type: ignore[import-untyped]

        return list(pd.read_parquet(self.path(k)).to_dict(orient="records"))


def _write_whole(path: Path, data: bytes) -> None:
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    temporary.write_bytes(data)
    os.replace(temporary, path)


def _frame(pd: Any, rows: List[Dict[str, Any]]) -> Any:
    frame = pd.DataFrame(rows)
    # Parquet wants one type per column: a column of strings and None stays object; a mixed
    # column (a task returning a number in one run and a string in another) becomes strings.
    for column in frame.columns:
        kinds = {type(v) for v in frame[column] if v is not None and not (isinstance(v, float) and math.isnan(v))}
        if len(kinds) > 1 and not kinds <= {int, float, bool}:
            frame[column] = frame[column].map(lambda v: None if v is None else str(v))
    return frame


class _Progress:
    def __init__(self, total_runs: int, done_runs: int, show: bool):
        self.total, self.done, self.show = total_runs, done_runs, show
        self.clock = time.perf_counter()
        self.errors = 0

    def add(self, rows: List[Dict[str, Any]]) -> None:
        self.done += len(rows)
        self.errors += sum(1 for r in rows if r.get("error"))
        if self.show:
            width = 30
            filled = int(width * self.done / max(self.total, 1))
            seconds = time.perf_counter() - self.clock
            sys.stderr.write(
                f"\rsweep [{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} runs, "
                f"{self.errors} errors, {seconds:.1f} s"
            )
            sys.stderr.flush()

    def close(self) -> None:
        if self.show:
            sys.stderr.write("\n")


def sweep(
    task: Task,
    grid: Any,
    *,
    client: Any = None,
    chunk: Optional[int] = None,
    out: Union[str, "os.PathLike[str]", None] = None,
    settings: Optional[Mapping[str, Any]] = None,
    progress: bool = True,
) -> Any:
    """Runs ``task`` once per row of ``grid`` and returns a pandas DataFrame, one row per run
    in run order: ``run``, the parameters, the result's scalars (``verdict``, ``dof``,
    ``collision.time_s``, …), ``error`` and ``error_kind`` (None when the run succeeded) and
    ``run_seconds``.

    ``task`` is ``"check"``, ``"fold"``, ``"unfold"``, ``"constraints"`` (a ``pattern``
    parameter, a path or a :class:`~nanofold.Pattern`; the others are the command's keywords),
    ``"simulate"`` or ``"modes"`` (a ``scene`` parameter; dotted parameters such as
    ``"actuation.etch_rate_um_per_min"`` change the scene's fields), or any function of the
    parameters returning a result, a dict or a number. ``settings`` are keywords every run
    shares.

    ``grid`` is a dict of value lists (their product), a list of dicts or a DataFrame.

    ``client`` is a ``dask.distributed.Client``, a scheduler address or scheduler file
    (``.json``, as ``dask scheduler --scheduler-file`` writes it), ``None`` (a
    ``LocalCluster`` with one single-threaded worker process per core, closed afterwards) or
    ``"serial"`` (this process, no Dask). ``chunk`` runs go in one scheduler task (default:
    about 16 chunks per worker, at most 1000 runs each).

    With ``out``, each finished chunk is written to ``out/parts/`` as it arrives and the
    table to ``out/results.parquet``; started again with the same arguments, a killed sweep
    skips the chunks already written (no run is lost or written twice).
    """
    g = Grid(grid)
    n = len(g)
    settings = dict(settings or {})
    if isinstance(task, str) and task not in TASKS:
        raise InvalidFieldError(
            f"invalid `task`: {task!r} (expected one of {', '.join(TASKS)} or a function)", "invalid_field", "task", task
        )
    if chunk is not None and (not isinstance(chunk, int) or chunk < 1):
        raise InvalidFieldError(f"invalid `chunk`: {chunk!r} (a whole number ≥ 1)", "invalid_field", "chunk", repr(chunk))
    own_client = None
    try:
        dask_client = None
        if client != "serial":
            dask_client, own_client = _client(client)
        threads = sum(dask_client.nthreads().values()) if dask_client is not None else 1
        size = chunk or max(1, min(MAX_DEFAULT_CHUNK, math.ceil(n / (16 * max(threads, 1)))))
        bounds = [(s, min(s + size, n)) for s in range(0, n, size)]
        description = {
            "task": _task_name(task),
            "runs": n,
            "chunk": size,
            "settings": settings,
        }
        description["fingerprint"] = hashlib.sha256(
            json.dumps([description, g.fingerprint()], sort_keys=True, default=str).encode()
        ).hexdigest()
        store = _Store(Path(out), description) if out is not None else None
        done: Dict[int, List[Dict[str, Any]]] = {}
        todo = []
        for k in range(len(bounds)):
            if store is not None and store.has(k):
                done[k] = store.read(k)
            else:
                todo.append(k)
        bar = _Progress(n, sum(len(r) for r in done.values()), progress)

        def finished(k: int, rows: List[Dict[str, Any]]) -> None:
            if store is not None:
                store.write(k, rows)
            done[k] = rows
            bar.add(rows)

        try:
            if dask_client is None:
                for k in todo:
                    finished(k, run_chunk(task, g.part(*bounds[k]), *bounds[k], settings))
            else:
                _distribute(dask_client, task, g, bounds, todo, settings, threads, finished)
        finally:
            bar.close()
        rows = [row for k in sorted(done) for row in done[k]]
    finally:
        if own_client is not None:
            cluster = own_client.cluster
            own_client.close()
            if cluster is not None:
                cluster.close()
    import pandas as pd  # type: ignore[import-untyped]

    table = _frame(pd, rows)
    if store is not None:
        target = store.folder / "results.parquet"
        temporary = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        table.to_parquet(temporary, index=False)
        os.replace(temporary, target)
    return table


def _client(client: Any) -> Tuple[Any, Any]:
    """(the client to use, the one this sweep made and must close)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise InvalidFieldError(
            f"invalid `client`: Dask is not installed ({error}); pip install 'nanofold-origami[sweep]' or pass client='serial'",
            "invalid_field",
            "client",
            repr(client),
        ) from None
    if client is None:
        cluster = LocalCluster(
            n_workers=os.cpu_count() or 1, threads_per_worker=1, processes=True, dashboard_address=None
        )
        made = Client(cluster)
        return made, made
    if isinstance(client, (str, os.PathLike)):
        # A scheduler file (`dask scheduler --scheduler-file F`, as batch jobs start one) or
        # an address.
        target = os.fspath(client)
        made = Client(scheduler_file=target) if target.endswith(".json") else Client(target)
        return made, made
    return client, None


def _distribute(
    client: Any,
    task: Task,
    grid: Grid,
    bounds: List[Tuple[int, int]],
    todo: List[int],
    settings: Dict[str, Any],
    threads: int,
    finished: Callable[[int, List[Dict[str, Any]]], None],
) -> None:
    """Chunks to the cluster with a bounded number in flight; a chunk that fails as a whole
    (its worker lost too often, an unpicklable task) becomes error rows."""
    from dask.distributed import as_completed

    limit = max(2, IN_FLIGHT_PER_THREAD * threads)
    pending = iter(todo)
    chunk_of: Dict[Any, int] = {}
    task_future = client.scatter(task, broadcast=True, hash=False) if callable(task) else task

    def submit() -> Optional[Any]:
        k = next(pending, None)
        if k is None:
            return None
        start, stop = bounds[k]
        future = client.submit(run_chunk, task_future, grid.part(start, stop), start, stop, settings, pure=False)
        chunk_of[future] = k
        return future

    first = [f for f in (submit() for _ in range(limit)) if f is not None]
    queue = as_completed(first)
    for future in queue:
        k = chunk_of.pop(future)
        try:
            rows = future.result()
        except Exception as error:
            start, stop = bounds[k]
            rows = []
            for run, params in grid.part(start, stop).rows(start, stop):
                row = {"run": run, **{n: _label(v) for n, v in params.items()}}
                row.update({"error": f"{type(error).__name__}: {error}", "error_kind": "cluster", "run_seconds": None})
                rows.append(row)
        finished(k, rows)
        future.release()
        following = submit()
        if following is not None:
            queue.add(following)


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m nanofold.sweep SPEC.json``: a sweep described by a JSON file.

    SPEC keys: ``task`` (a command name or ``"module:function"``), ``grid`` (name → value
    list) or ``table`` (a CSV or Parquet file of rows), ``settings``, ``chunk``, ``out``
    (default: the spec's name with ``.sweep`` beside it), ``scheduler`` (an address; default
    a local cluster). Paths of ``pattern`` and ``scene`` values are relative to the spec.
    """
    import argparse
    import importlib

    parser = argparse.ArgumentParser(prog="python -m nanofold.sweep", description="Run a nanofold sweep described by a JSON file.")
    parser.add_argument("spec", help="the sweep's JSON description")
    parser.add_argument("--scheduler", help="a Dask scheduler address or scheduler file (.json); overrides the spec's")
    parser.add_argument("--serial", action="store_true", help="run in this process, without Dask")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    spec_path = Path(args.spec)
    try:
        spec = json.loads(spec_path.read_text())
    except (OSError, ValueError) as error:
        print(f"error: cannot read {spec_path}: {error}", file=sys.stderr)
        return 2
    known = {"task", "grid", "table", "settings", "chunk", "out", "scheduler"}
    unknown = set(spec) - known
    if unknown or not isinstance(spec.get("task"), str) or ("grid" in spec) == ("table" in spec):
        print(
            f"error: {spec_path}: needs `task` (a string) and one of `grid` or `table`; known keys {sorted(known)}"
            + (f"; unknown {sorted(unknown)}" if unknown else ""),
            file=sys.stderr,
        )
        return 2
    base = spec_path.parent
    task: Task = spec["task"]
    if ":" in spec["task"]:
        module, function = spec["task"].split(":", 1)
        sys.path.insert(0, str(base.resolve()))
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(base.resolve()), os.environ.get("PYTHONPATH")]))
        task = getattr(importlib.import_module(module), function)

    def located(name: str, value: Any) -> Any:
        return str(base / value) if name in ("pattern", "scene") and isinstance(value, str) else value

    if "grid" in spec:
        grid: Any = {k: [located(k, v) for v in values] for k, values in spec["grid"].items()}
    else:
        import pandas as pd  # type: ignore[import-untyped]

        table_path = base / spec["table"]
        frame = pd.read_parquet(table_path) if table_path.suffix == ".parquet" else pd.read_csv(table_path)
        grid = [{k: located(k, v) for k, v in r.items()} for r in frame.to_dict(orient="records")]
    out = base / spec.get("out", spec_path.name.removesuffix(".json") + ".sweep")
    client: Any = "serial" if args.serial else (args.scheduler or spec.get("scheduler"))
    clock = time.perf_counter()
    try:
        table = sweep(task, grid, client=client, chunk=spec.get("chunk"), out=out,
                      settings=spec.get("settings"), progress=not args.quiet)
    except NanofoldError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    errors = int(table["error"].notna().sum()) if "error" in table else 0
    print(f"{len(table)} runs ({errors} failed) in {time.perf_counter() - clock:.1f} s; wrote {out / 'results.parquet'}")
    return 0
