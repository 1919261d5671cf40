"""The Python blocks of README and of the user guide's chapters run as written (from the
repository root), except the batch-system one, which needs dask-jobqueue and a cluster."""

import re

import pytest

from conftest import ROOT


def _documents():
    """README, then every chapter the guide's index links to, in its order."""
    index = (ROOT / "docs" / "guide" / "README.md").read_text()
    names = ["README.md"]
    for target in re.findall(r"\]\(([^)/]+\.md)\)", index):
        if f"docs/guide/{target}" not in names:
            names.append(f"docs/guide/{target}")
    return names


BLOCKS = [
    (name, block)
    for name in _documents()
    for block in re.findall(r"```python\n(.*?)```", (ROOT / name).read_text(), flags=re.S)
]


def test_the_documents_have_their_python_blocks():
    assert len(BLOCKS) >= 4
    assert any(name == "README.md" for name, _ in BLOCKS)


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_a_documents_python_block_runs(index, tmp_path, monkeypatch):
    name, block = BLOCKS[index]
    if "dask_jobqueue" in block:
        pytest.skip("needs a batch system (dask-jobqueue)")
    # Outputs go under output/, as the documents say; keep them out of the repository's.
    monkeypatch.setenv("NANOFOLD_README_TEST", "1")
    block = block.replace('out="output/', f'out="{tmp_path}/')
    exec(compile(block, f"{name} python block {index}", "exec"), {"__name__": "__readme__"})
