"""The Python results equal the command line's `--json` for the bundled patterns and scenes
(both are the library's front door, rendered by the same code)."""

from pathlib import Path

import pytest

import nanofold
from conftest import ROOT, cli_json, comparable

PATTERNS = sorted(
    str(p.relative_to(ROOT))
    for p in list((ROOT / "patterns").glob("*.fold")) + list((ROOT / "patterns").glob("*.json"))
    + list((ROOT / "patterns" / "many").glob("*.fold"))
    if not p.name.endswith(".scene.json")
)
SCENES = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "patterns").rglob("*.scene.json"))


def test_the_bundled_set_is_not_empty():
    assert len(PATTERNS) >= 15 and len(SCENES) >= 8


@pytest.mark.parametrize("path", PATTERNS)
def test_check_equals_the_command_line(path):
    try:
        result = nanofold.check(path)
    except nanofold.NanofoldError as error:
        pytest.skip(f"not a pattern nanofold checks: {error}")
    assert comparable(result.to_dict()) == comparable(cli_json("check", path))


@pytest.mark.parametrize("path", [p for p in PATTERNS if "many/" not in p][:8] + ["patterns/many/miura_4x4_folded.fold"])
def test_unfold_equals_the_command_line(path, tmp_path):
    try:
        result = nanofold.unfold(path)
    except nanofold.NanofoldError as error:
        pytest.skip(f"not a pattern nanofold unfolds: {error}")
    assert comparable(result.to_dict()) == comparable(cli_json("unfold", path, "--out", str(tmp_path / "u")))


@pytest.mark.parametrize("path", ["patterns/many/miura_4x4.fold", "patterns/many/square_twist.fold"])
def test_fold_equals_the_command_line(path, tmp_path):
    if not (ROOT / path).exists():
        pytest.skip(f"{path} is not bundled")
    result = nanofold.fold(path, to=60, frames=7)
    expected = cli_json("fold", path, "--to", "60", "--frames", "7", "--out", str(tmp_path / "f"))
    assert comparable(result.to_dict()) == comparable(expected)
    # The square twist stops at its branch point at once: one frame, as on the command line.
    assert len(result.fold_file()["file_frames"]) == expected["frames"]
    assert result.verdict == expected["stop_reason"]


@pytest.mark.parametrize("scene", SCENES)
def test_modes_equal_the_command_line(scene, tmp_path):
    result = nanofold.modes(scene)
    assert comparable(result.to_dict()) == comparable(cli_json("modes", scene, "--out", str(tmp_path / "m")))


@pytest.mark.parametrize(
    "scene", ["patterns/bridge_step.scene.json", "patterns/bridge_ramp.scene.json", "patterns/corner_cube_step1.scene.json"]
)
def test_simulate_equals_the_command_line(scene, tmp_path):
    result = nanofold.simulate(scene)
    expected = cli_json("simulate", scene, "--out", str(tmp_path / "s"))
    assert comparable(result.to_dict()) == comparable(expected)
    assert len(result.times) == len(result.angles) > 10


def test_constraints_equal_the_command_line(tmp_path):
    vertex = nanofold.constraints("patterns/miura_vertex.fold", drive=0, degree=6, samples=101)
    assert comparable(vertex.to_dict()) == comparable(
        cli_json("constraints", "patterns/miura_vertex.fold", "--drive", "0", "--degree", "6", "--samples", "101",
                 "--out", str(tmp_path / "c1"))
    )
    folded = "patterns/many/miura_4x4_folded.fold"
    network = nanofold.constraints(folded, drive=_first_crease(folded), degree=5, samples=41)
    assert comparable(network.to_dict()) == comparable(
        cli_json("constraints", folded, "--drive", str(_first_crease(folded)), "--degree", "5", "--samples", "41",
                 "--out", str(tmp_path / "c2"))
    )


def _first_crease(path):
    label = nanofold.Pattern.open(path).crease_labels[0]
    return int(label.split("[")[1].rstrip("]"))


@pytest.mark.parametrize("shape", ["cube", "box:1x2x3", "pyramid:5:1.5", "patterns/solids/cube_binary.stl"])
def test_nets_equal_the_command_line(shape, tmp_path):
    result = nanofold.nets(shape, top=4, rank_by="seam_length", simulate=2, fronts=3, yield_samples=4)
    expected = cli_json("nets", shape, "--top", "4", "--rank-by", "seam-length", "--simulate", "2", "--fronts", "3",
                        "--yield-samples", "4", "--out", str(tmp_path / "n"))
    assert comparable(result.to_dict()) == comparable(expected)
