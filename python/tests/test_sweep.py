"""Sweeps: the same rows on a 2-worker LocalCluster as in one process, a bad case that does
not stop the sweep, a worker killed mid-sweep that loses and duplicates nothing, and a sweep
killed and started again that resumes from its output folder."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
from conftest import comparable as report_without_times

import nanofold
import sweep_tasks
from conftest import ROOT

TIMING = ["run_seconds", "seconds"]


def comparable(table):
    return table.drop(columns=[c for c in TIMING if c in table.columns]).reset_index(drop=True)


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("dask.distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


PATTERN_GRID = {
    "pattern": ["patterns/many/miura_4x4.fold", "patterns/many/square_twist.fold", "patterns/many/bird_base.fold",
                "patterns/no_such_file.fold"],
    "to": [30, 80, 700],
}


def test_a_grid_is_its_product_in_order_and_a_bad_case_is_a_row():
    table = nanofold.sweep("fold", PATTERN_GRID, client="serial", progress=False)
    assert list(table["run"]) == list(range(12))
    assert list(table["pattern"][:3]) == ["patterns/many/miura_4x4.fold"] * 3
    assert list(table["to"][:3]) == [30, 80, 700]
    bad_goal = table[(table["to"] == 700) & (table["pattern"] != "patterns/no_such_file.fold")]
    assert bad_goal["error_kind"].eq("invalid_field").all() and bad_goal["error"].str.contains("drive.to").all()
    missing = table[table["pattern"] == "patterns/no_such_file.fold"]
    assert missing["error_kind"].eq("io").all()
    good = table[table["error"].isna()]
    assert len(good) == 6 and set(good["stop_reason"]) <= {"reached", "branch_point", "blocked"}
    miura = good[good["pattern"] == "patterns/many/miura_4x4.fold"]
    assert list(miura["stop_reason"]) == ["reached", "reached"]


def test_a_cluster_gives_the_serial_rows(client):
    serial = nanofold.sweep("fold", PATTERN_GRID, client="serial", progress=False)
    parallel = nanofold.sweep("fold", PATTERN_GRID, client=client, chunk=2, progress=False)
    pd.testing.assert_frame_equal(comparable(serial), comparable(parallel))
    grid = {"angle_deg": [40.0, 65.0], "rows": [3, 5], "cols": [2, 4]}
    serial = nanofold.sweep(sweep_tasks.miura_design, grid, client="serial", progress=False)
    parallel = nanofold.sweep(sweep_tasks.miura_design, grid, client=client, chunk=3, progress=False)
    pd.testing.assert_frame_equal(comparable(serial), comparable(parallel))
    assert set(serial["verdict"]) == {"rigidly_foldable"} and set(serial["dof"]) == {1}


def test_a_table_of_rows_and_scene_fields_by_dotted_names(client):
    rows = [
        {"scene": "patterns/bridge_ramp.scene.json", "actuation.etch_rate_um_per_min": rate}
        for rate in (1.5, 3.0, 6.0)
    ]
    table = nanofold.sweep("simulate", rows, client=client, progress=False)
    times = list(table["collision.time_s"])
    assert times[0] == pytest.approx(2 * times[1], rel=1e-6) and times[1] == pytest.approx(2 * times[2], rel=1e-6)


def test_a_worker_killed_mid_sweep_loses_and_duplicates_nothing(client):
    grid = {"x": list(range(40)), "delay": [0.05]}
    serial = nanofold.sweep(sweep_tasks.slow_square, grid, client="serial", progress=False)
    pids = list(client.run(os.getpid).values())

    killed_at = []

    def kill():
        os.kill(pids[0], signal.SIGKILL)
        killed_at.append(time.perf_counter())

    timer = threading.Timer(0.6, kill)
    timer.start()
    parallel = nanofold.sweep(sweep_tasks.slow_square, grid, client=client, chunk=2, progress=False)
    finished_at = time.perf_counter()
    timer.join()
    # The worker died while the sweep ran (40 runs of 50 ms on two workers take over 1 s).
    assert killed_at and killed_at[0] < finished_at - 0.1
    assert list(parallel["run"]) == list(range(40))
    pd.testing.assert_frame_equal(comparable(serial), comparable(parallel))
    assert parallel.loc[13, "error"] == "ValueError: thirteen is refused"
    assert parallel.loc[12, "square"] == 144
    client.wait_for_workers(2, timeout=30)
    assert pids[0] not in client.run(os.getpid).values()


def test_a_sweep_killed_and_started_again_resumes(tmp_path):
    (tmp_path / "tasks.py").write_text((Path(__file__).parent / "sweep_tasks.py").read_text())
    spec = tmp_path / "squares.json"
    spec.write_text(json.dumps({
        "task": "tasks:slow_square",
        "grid": {"x": list(range(30)), "delay": [0.1]},
        "chunk": 3,
        "out": "squares",
    }))
    command = [sys.executable, "-m", "nanofold.sweep", str(spec), "--serial", "--quiet"]
    parts = tmp_path / "squares" / "parts"
    first = subprocess.Popen(command, cwd=ROOT)
    deadline = time.time() + 60
    while time.time() < deadline and len(list(parts.glob("part-*.parquet")) if parts.exists() else []) < 3:
        time.sleep(0.05)
    first.kill()
    first.wait()
    written = {p.name: p.stat().st_mtime_ns for p in parts.glob("part-*.parquet")}
    assert 3 <= len(written) < 10, written
    assert not (tmp_path / "squares" / "results.parquet").exists()
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # The parts written before the kill were kept as they were, the rest added.
    after = {p.name: p.stat().st_mtime_ns for p in parts.glob("part-*.parquet")}
    assert len(after) == 10 and all(after[name] == mtime for name, mtime in written.items())
    table = pd.read_parquet(tmp_path / "squares" / "results.parquet")
    assert list(table["run"]) == list(range(30))
    expected = nanofold.sweep(sweep_tasks.slow_square, {"x": list(range(30)), "delay": [0.0]}, client="serial", progress=False)
    assert list(table["square"].fillna(-1)) == list(expected["square"].fillna(-1))
    assert list(table["error"].fillna("")) == list(expected["error"].fillna(""))


def test_an_output_folder_of_another_sweep_is_refused(tmp_path):
    nanofold.sweep(sweep_tasks.slow_square, {"x": [1, 2], "delay": [0.0]}, client="serial", out=tmp_path, progress=False)
    with pytest.raises(nanofold.InvalidFieldError) as caught:
        nanofold.sweep(sweep_tasks.slow_square, {"x": [1, 3], "delay": [0.0]}, client="serial", out=tmp_path, progress=False)
    assert caught.value.field == "out" and "another sweep" in str(caught.value)


def test_bad_sweep_arguments_are_refused_by_name():
    with pytest.raises(nanofold.InvalidFieldError, match="task"):
        nanofold.sweep("origami", {"pattern": ["x"]}, client="serial")
    with pytest.raises(nanofold.InvalidFieldError, match="grid.rows"):
        nanofold.sweep(sweep_tasks.miura_design, {"rows": []}, client="serial")
    with pytest.raises(nanofold.InvalidFieldError, match="chunk"):
        nanofold.sweep("check", {"pattern": ["x"]}, client="serial", chunk=0)


@pytest.mark.parametrize("example", ["miura_sweep.py", "device_sweep.py"])
def test_the_examples_run_on_a_local_cluster(example, tmp_path):
    done = subprocess.run(
        [sys.executable, str(ROOT / "python" / "examples" / example), "--small", "--out", str(tmp_path)],
        cwd=ROOT, capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr
    figure = tmp_path / example.replace(".py", ".svg")
    assert figure.exists() and figure.stat().st_size > 5000
    table = pd.read_parquet(tmp_path / "results.parquet")
    assert table["error"].isna().all() and len(table) >= 6


def test_the_command_line_form_runs_on_a_scheduler_started_apart(tmp_path):
    """As a batch job does it: `dask scheduler` and `dask worker` processes, the sweep given
    the scheduler file."""
    bin_dir = Path(sys.executable).parent
    scheduler_file = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen([str(bin_dir / "dask"), "scheduler", "--scheduler-file", str(scheduler_file),
                                  "--port", "0", "--dashboard-address", ":0"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers = []
    try:
        deadline = time.time() + 60
        while not scheduler_file.exists() and time.time() < deadline:
            time.sleep(0.1)
        workers = [
            subprocess.Popen([str(bin_dir / "dask"), "worker", "--scheduler-file", str(scheduler_file),
                              "--nthreads", "1", "--no-dashboard"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
            for _ in range(2)
        ]
        spec = tmp_path / "checks.json"
        spec.write_text(json.dumps({
            "task": "check",
            "grid": {"pattern": [str(ROOT / "patterns/many/miura_4x4.fold"), str(ROOT / "patterns/many/bird_base.fold"),
                                 str(ROOT / "patterns/many/square_twist.fold")]},
            "chunk": 1,
        }))
        done = subprocess.run([sys.executable, "-m", "nanofold.sweep", str(spec), "--scheduler", str(scheduler_file),
                               "--quiet"], cwd=ROOT, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        assert "3 runs (0 failed)" in done.stdout
        table = pd.read_parquet(tmp_path / "checks.sweep" / "results.parquet")
        serial = nanofold.sweep("check", {"pattern": [str(ROOT / "patterns/many/miura_4x4.fold"),
                                                      str(ROOT / "patterns/many/bird_base.fold"),
                                                      str(ROOT / "patterns/many/square_twist.fold")]},
                                client="serial", progress=False)
        assert list(table["verdict"]) == list(serial["verdict"])
    finally:
        for process in workers + [scheduler]:
            process.terminate()
        for process in workers + [scheduler]:
            process.wait(timeout=30)


def test_a_nets_study_on_the_cluster_equals_the_one_on_this_machines_cores(client):
    keywords = dict(top=3, simulate=3, fronts=3, yield_samples=4, unit_um=50, overdrive_deg=5)
    on_cores = nanofold.nets("octahedron", **keywords)
    on_cluster = nanofold.nets("octahedron", client=client, progress=False, **keywords)
    assert report_without_times(on_cluster.to_dict()) == report_without_times(on_cores.to_dict())
    # Three nets: three releases of a nominal and 4 varied devices each, then 4 fresh ones
    # at each of three captures.
    assert on_cluster.to_dict()["study"]["devices"] == 3 * (3 * 5 + 3 * 4)
    assert on_cluster.table.equals(on_cores.table)

