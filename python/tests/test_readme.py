"""README's Python blocks run as written (from the repository root), except the batch-system
one, which needs dask-jobqueue and a cluster."""

import re

import pytest

from conftest import ROOT

BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), flags=re.S)


def test_readme_has_its_python_blocks():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, tmp_path, monkeypatch):
    block = BLOCKS[index]
    if "dask_jobqueue" in block:
        pytest.skip("needs a batch system (dask-jobqueue)")
    # Outputs go under output/, as README says; keep them out of the repository's.
    monkeypatch.setenv("NANOFOLD_README_TEST", "1")
    block = block.replace('out="output/', f'out="{tmp_path}/')
    exec(compile(block, f"README.md python block {index}", "exec"), {"__name__": "__readme__"})
