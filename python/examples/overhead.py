"""Speed of the Python layer: the per-call overhead against the library's own time for a
task of about 1 ms, and sweep throughput in one process and on a local Dask cluster of 1
and 2 workers (with the engine's overhead per run).

    python python/examples/overhead.py [--runs 400] [--repeat 5]
"""

import argparse
import os
import statistics
import time

import nanofold


def one_ms_task(angle_deg: float) -> dict:
    """Folds a 4 × 4 Miura-ori to 30% (about 1 ms in the library)."""
    r = nanofold.fold(_sheet(angle_deg), to=30)
    return {"steps": r.steps, "library_seconds": r.seconds}


_SHEETS: dict = {}


def _sheet(angle_deg: float) -> nanofold.Pattern:
    if angle_deg not in _SHEETS:
        _SHEETS[angle_deg] = nanofold.generate.miura(4, 4, angle_deg=angle_deg)
    return _SHEETS[angle_deg]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=400, help="runs per sweep")
    parser.add_argument("--repeat", type=int, default=5, help="repetitions of each timing (median reported)")
    args = parser.parse_args()
    print(f"machine: {os.cpu_count()} cores; medians of {args.repeat}")

    sheet = _sheet(60.0)
    calls = 200
    engine, library, wall = [], [], []
    for _ in range(args.repeat):
        clock = time.perf_counter()
        results = [nanofold.fold(sheet, to=30) for _ in range(calls)]
        wall.append((time.perf_counter() - clock) / calls)
        engine.append(statistics.mean(r.seconds for r in results))
        library.append(statistics.mean(r.library_seconds for r in results))
    empty = []
    for _ in range(args.repeat):
        clock = time.perf_counter()
        for _ in range(1000):
            nanofold._native.noop()
        empty.append((time.perf_counter() - clock) / 1000)
    w, l, e = statistics.median(wall), statistics.median(library), statistics.median(empty)
    print(f"fold(miura 4x4, to=30): {w * 1e3:.3f} ms per call from Python; in the library {l * 1e3:.3f} ms "
          f"(the path {statistics.median(engine) * 1e3:.3f} ms, the rest its summary, DOF and FOLD files); "
          f"the Python layer {(w - l) * 1e6:.0f} µs ({(w - l) / l * 100:.1f}% of the library's time); "
          f"an empty call {e * 1e6:.0f} µs")

    grid = {"angle_deg": [50.0 + 20.0 * k / args.runs for k in range(args.runs)]}
    from dask.distributed import Client, LocalCluster

    for label, workers in (("serial (one process, no Dask)", 0), ("LocalCluster, 1 worker", 1), ("LocalCluster, 2 workers", 2)):
        times = []
        mean_run = 0.0
        for _ in range(args.repeat):
            if workers == 0:
                clock = time.perf_counter()
                table = nanofold.sweep(one_ms_task, grid, client="serial", progress=False)
                times.append(time.perf_counter() - clock)
            else:
                with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
                    client.run(lambda: None)
                    clock = time.perf_counter()
                    table = nanofold.sweep(one_ms_task, grid, client=client, progress=False)
                    times.append(time.perf_counter() - clock)
            mean_run = float(table["run_seconds"].mean())
        t = statistics.median(times)
        per_run = t * max(workers, 1) / args.runs
        print(f"{label}: {args.runs} runs in {t:.3f} s = {args.runs / t:.0f} runs/s; "
              f"per run {per_run * 1e3:.3f} ms of worker time against {mean_run * 1e3:.3f} ms in the task: "
              f"engine overhead {(per_run - mean_run) * 1e3:.3f} ms per run")


if __name__ == "__main__":
    main()
