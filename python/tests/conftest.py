"""Shared fixtures: the repository root (tests run from it, as README's paths are relative
to it) and the command line's binary, built by `cargo test --release` before pytest runs."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _in_repository_root(monkeypatch):
    monkeypatch.chdir(ROOT)


def cli_json(*args: str):
    """`nanofold ARGS --json` as a dict (the last JSON line of stdout)."""
    binary = os.environ.get("NANOFOLD_BIN", str(ROOT / "target" / "release" / "nanofold"))
    done = subprocess.run([binary, *args, "--json"], cwd=ROOT, capture_output=True, text=True, check=False)
    lines = [l for l in done.stdout.splitlines() if l.startswith("{")]
    assert lines, f"nanofold {' '.join(args)} printed no JSON: {done.stderr}"
    return json.loads(lines[-1])


def comparable(value, drop=("seconds", "out", "frames")):
    """The object without wall times and the command line's own keys."""
    if isinstance(value, dict):
        return {k: comparable(v, drop) for k, v in value.items() if k not in drop}
    if isinstance(value, list):
        return [comparable(v, drop) for v in value]
    return value
