"""The Python API: patterns from every kind of input, results as arrays, errors naming their
field, pickling, the GIL released and Ctrl-C honoured during long calls."""

import json
import math
import os
import pickle
import signal
import threading
import time

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import nanofold

CROSS = dict(
    vertices=[[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1]],
    edges=[[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]],
    assignments=["M", "V", "V", "V", "B", "B", "B", "B"],
)


def test_a_pattern_from_a_path_a_dict_and_arrays_is_the_same_pattern():
    from_path = nanofold.Pattern.open("patterns/many/miura_4x4.fold")
    with open("patterns/many/miura_4x4.fold") as f:
        fold = json.load(f)
    from_dict = nanofold.Pattern.from_fold(fold)
    from_arrays = nanofold.Pattern.from_arrays(
        fold["vertices_coords"], fold["edges_vertices"], fold["edges_assignment"], name="miura_4x4"
    )
    verdicts = [nanofold.check(p).to_dict() for p in (from_path, from_dict, from_arrays)]
    for v in verdicts:
        v.pop("seconds"), v.pop("file"), v.pop("pattern")
    assert verdicts[0] == verdicts[1] == verdicts[2]
    assert verdicts[0]["verdict"] == "rigidly_foldable"


def test_a_cross_of_four_creases_folds_and_its_folded_state_unfolds_as_a_single_vertex():
    cross = nanofold.Pattern.from_arrays(**CROSS, name="cross")
    # Flat, with no fold angles, it is a crease pattern (an assignment to fold).
    assert cross.engine == "network" and len(cross.crease_labels) == 4
    folded = nanofold.fold(cross, to=50)
    assert folded.verdict == "reached"
    # The folded state read back through FOLD unfolds flat by the single-vertex engine.
    state = nanofold.Pattern.from_fold(folded.folded_file(), "cross_folded")
    assert state.engine == "vertex"
    unfolded = nanofold.unfold(state)
    assert unfolded.verdict == "flat"
    assert np.abs(unfolded.final_fold_angles_rad).max() < 1e-6
    assert unfolded.trajectory.shape[1] == 4 and unfolded.trajectory.shape[0] >= 2


def test_results_give_arrays_and_plain_dicts():
    r = nanofold.fold(nanofold.generate.miura(3, 3), to=40, frames=4)
    assert isinstance(r.to_dict(), dict) and isinstance(r.to_dict()["progress"], float)
    assert r.trajectory.ndim == 2 and r.trajectory.shape[1] == r.creases
    assert np.all(np.diff(r.progress_per_step) > 0)
    # Progress is the fraction of the goal (40% of a full fold) reached.
    assert abs(r.progress_per_step[-1] - 1.0) < 1e-9 and r.progress_per_step[0] == 0.0
    assert abs(np.abs(r.final_fold_angles_rad).max() - 0.4 * np.pi) < 1e-9
    assert len(r.fold_file()["file_frames"]) == 4
    with pytest.raises(AttributeError, match="no field 'nonsense'"):
        r.nonsense


@pytest.mark.parametrize(
    "make",
    [
        lambda: nanofold.generate.miura(2, 3, angle_deg=75, fold_deg=40),
        lambda: nanofold.generate.square_twist(twist_deg=20),
        lambda: nanofold.generate.waterbomb(2, 2, row_height=1.5),
        lambda: nanofold.generate.bird_base(2.0),
    ],
)
def test_every_generator_builds_a_pattern_that_checks(make):
    pattern = make()
    assert pattern.engine == "network"
    assert nanofold.check(pattern).verdict in {
        "rigid", "rigidly_foldable", "not_rigidly_foldable", "unknown"
    }


def test_a_folded_miura_from_the_generator_is_rigid_and_unfolds_flat():
    folded = nanofold.generate.miura(3, 3, fold_deg=60)
    assert nanofold.check(folded).verdict == "rigid"
    assert nanofold.unfold(folded).verdict == "flat"


@pytest.mark.parametrize(
    "call, error, field",
    [
        (lambda: nanofold.generate.miura(0, 4), nanofold.InvalidFieldError, "rows, cols"),
        (lambda: nanofold.generate.miura(4, 4, angle_deg=95), nanofold.InvalidFieldError, "angle_deg"),
        (lambda: nanofold.unfold("patterns/miura_vertex.fold", p=-1), nanofold.InvalidFieldError, "p"),
        (lambda: nanofold.unfold("patterns/miura_vertex.fold", energy="quadratic"), nanofold.InvalidFieldError, "energy"),
        (lambda: nanofold.fold("patterns/many/miura_4x4.fold", to=200), nanofold.InvalidFieldError, "drive.to"),
        (lambda: nanofold.fold("patterns/many/miura_4x4.fold", drive={3: 1.0}), nanofold.InvalidFieldError, "drive"),
        (lambda: nanofold.simulate("patterns/bridge_step.scene.json", rtol=-1), nanofold.InvalidFieldError, "rtol"),
        (lambda: nanofold.constraints("patterns/miura_vertex.fold", drive=9), nanofold.InvalidFieldError, "drive"),
        (lambda: nanofold.Pattern.open("patterns/nothing.fold"), nanofold.FileReadError, "path"),
        (lambda: nanofold.Pattern.open("patterns/bridge_step.scene.json"), nanofold.InputError, None),
        (lambda: nanofold.Scene.open("patterns/bridge_step.scene.json").replace({"plates.9.length_um": 1}),
         nanofold.InvalidFieldError, "plates.9.length_um"),
    ],
)
def test_errors_are_one_hierarchy_that_names_the_field(call, error, field):
    with pytest.raises(error) as caught:
        call()
    assert isinstance(caught.value, nanofold.NanofoldError)
    if field is not None:
        assert caught.value.field == field, caught.value
    assert str(caught.value)


def test_a_drive_key_that_is_a_crease_folds_to_its_angle():
    sheet = nanofold.Pattern.open("patterns/many/miura_4x4.fold")
    edge = int(sheet.crease_labels[0].split("[")[1].rstrip("]"))
    # The target's sign is the crease's assignment's (a mountain folds to negative angles).
    sign = np.sign(nanofold.fold(sheet, to=10).final_fold_angles_rad[0])
    r = nanofold.fold(sheet, drive={edge: sign * math.degrees(1.0)})
    assert r.verdict == "reached"
    assert abs(r.final_fold_angles_rad[0] - sign * 1.0) < 1e-9
    with pytest.raises(nanofold.InvalidFieldError, match="contradicts the crease's assignment"):
        nanofold.fold(sheet, drive={edge: -sign * math.degrees(1.0)})


def test_objects_pickle_and_answer_the_same_after():
    pattern = nanofold.Pattern.open("patterns/many/miura_4x4.fold")
    scene = nanofold.Scene.open("patterns/bridge_step.scene.json").replace({"time.t_end_s": 1e-4})
    result = nanofold.check(pattern)
    again = pickle.loads(pickle.dumps((pattern, scene, result)))
    assert again[0].source == pattern.source and again[0].crease_labels == pattern.crease_labels
    a, b = nanofold.check(again[0]).to_dict(), result.to_dict()
    a.pop("seconds"), b.pop("seconds")
    assert a == b
    assert again[1].to_dict()["time"]["t_end_s"] == 1e-4
    assert again[2] == result
    error = pickle.loads(pickle.dumps(nanofold.InvalidFieldError("m", "invalid_field", "rows", "0")))
    assert (type(error), error.field, error.value) == (nanofold.InvalidFieldError, "rows", "0")


def test_a_scene_changed_by_dotted_paths_changes_its_answer():
    scene = nanofold.Scene.open("patterns/bridge_ramp.scene.json")
    slow = nanofold.simulate(scene)
    fast = nanofold.simulate(scene.replace({"actuation.etch_rate_um_per_min": 3.0}))
    # Twice the etch rate: the front reaches every hinge in half the time.
    assert fast.collision["time_s"] == pytest.approx(slow.collision["time_s"] / 2, rel=1e-6)


def test_long_calls_release_the_gil():
    # A native call of a known length (it only waits on the worker thread, as every command
    # runs), so the premise does not shrink as the library gets faster.
    ticks = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks[0] += 1

    counter = threading.Thread(target=count)
    counter.start()
    before = ticks[0]
    waited = nanofold._native.wait(0.3)
    during = ticks[0] - before
    stop.set()
    counter.join()
    # A call that held the GIL for its 0.3 s would leave the counter where it was.
    assert waited >= 0.3 and during > 1_000, (waited, during)


def test_ctrl_c_interrupts_a_long_call():
    # The call waits 30 s unless interrupted; the signal comes 0.3 s after it starts, so it
    # cannot finish first however fast the machine is. Python turns SIGINT into
    # KeyboardInterrupt only if it was not ignored when the interpreter started, and a
    # shell without job control starts its background jobs with it ignored: the test sets
    # Python's own handler for its span, so it checks the library, not how it was launched.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        clock = time.perf_counter()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            nanofold._native.wait(30.0)
        assert time.perf_counter() - clock < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)


@settings(max_examples=12, deadline=None)
@given(
    rows=st.integers(3, 5),
    cols=st.integers(2, 4),
    angle=st.floats(20, 85),
    fold_deg=st.floats(10, 150),
)
def test_generated_miura_sheets_fold_rigidly_and_their_folded_states_are_rigid(rows, cols, angle, fold_deg):
    flat = nanofold.generate.miura(rows, cols, angle_deg=angle)
    assert nanofold.check(flat).verdict == "rigidly_foldable"
    folded = nanofold.generate.miura(rows, cols, angle_deg=angle, fold_deg=fold_deg)
    state = nanofold.check(folded)
    assert state.verdict == "rigid" and state.max_vertex_residual_rad < 1e-9
    assert pickle.loads(pickle.dumps(folded)).fold_angles.tolist() == folded.fold_angles.tolist()


def test_every_pattern_function_takes_a_path_a_pattern_or_a_fold_dict():
    path = "patterns/many/miura_4x4.fold"
    with open(path) as f:
        fold_dict = json.load(f)
    by_path = nanofold.check(path)
    for given in (nanofold.Pattern.open(path), fold_dict):
        r = nanofold.check(given)
        assert (r.verdict, r.dof) == (by_path.verdict, by_path.dof)
    assert nanofold.fold(fold_dict, to=50).verdict == nanofold.fold(path, to=50).verdict == "reached"
    with pytest.raises(TypeError, match="a path, a nanofold.Pattern or a FOLD dict, got int"):
        nanofold.check(3)  # type: ignore[arg-type]


def test_a_scene_dict_simulates_as_its_file_does():
    path = "patterns/bridge_step.scene.json"
    with open(path) as f:
        spec = json.load(f)
    spec["time"]["t_end_s"] = 1e-4
    by_dict = nanofold.simulate(spec)
    by_scene = nanofold.simulate(nanofold.Scene.open(path).replace({"time.t_end_s": 1e-4}))
    assert by_dict.final_angles_rad.tolist() == by_scene.final_angles_rad.tolist()


def test_constraints_take_the_command_lines_options_by_the_same_names():
    # The Miura vertex's collinear creases fold equal and opposite: rho_2 = -rho_0 exactly,
    # so the checked curve -theta has no error and +0.5 deg has 0.5 deg everywhere.
    r = nanofold.constraints("patterns/miura_vertex.fold", drive=0, check=[(2, [0, -1]), (2, [0.5, -1])])
    errors = [c["max_error_rad"] for c in r.checked_curves]
    assert errors[0] < 1e-9 and abs(errors[1] - math.radians(0.5)) < 1e-9
    capped = nanofold.constraints("patterns/miura_vertex.fold", drive=0, degree="auto", tol=1e-12, format="mujoco")
    assert capped.degree <= 4
    with pytest.raises(nanofold.InvalidFieldError, match="quartic"):
        nanofold.constraints("patterns/miura_vertex.fold", drive=0, degree=6, format="mujoco")


def test_the_known_length_call_refuses_a_length_out_of_range():
    # The native call raises the binding's own error (kind, field, value, message).
    for seconds in (-1.0, 61.0):
        with pytest.raises(nanofold._native.NativeError, match="seconds"):
            nanofold._native.wait(seconds)


def test_fit_takes_a_dataframe_with_gaps_and_gives_the_estimate_its_interval_and_the_fitted_scene():
    import pandas as pd

    measured = pd.read_csv("patterns/measurements/bridge_step_measured.csv", comment="#")
    window = measured[measured.time_s <= 30e-6][["time_s", "hinge_0_deg", "hinge_2_deg"]].copy()
    window.loc[window.index[::3], "hinge_0_deg"] = float("nan")  # every third sample missed
    scene = nanofold.Scene.open("patterns/bridge_step.scene.json").replace({"hinges.0.target_angle_deg": 85})
    scene = scene.replace({k: 85 for k in ("hinges.1.target_angle_deg", "hinges.2.target_angle_deg",
                                           "hinges.3.target_angle_deg")})
    r = nanofold.fit(scene, window, free={"environment.drag_coefficient": (0.2, 5)}, noise=0.5)
    (p,) = r.parameters
    assert r.status == "converged" and p["determined"]
    low, high = p["interval_95"]
    assert low <= 1.6 <= high  # the value the measurement was simulated with
    assert r.observations == int(window[["hinge_0_deg", "hinge_2_deg"]].notna().sum().sum())
    table = r.table
    assert list(table.columns[:4]) == ["time_s", "hinge_0_deg", "hinge_0_deg_fitted", "hinge_0_deg_residual"]
    assert r.fitted_scene.to_dict()["environment"]["drag_coefficient"] == p["estimate"]
    with pytest.raises(nanofold.InvalidFieldError, match="drag_coeficient"):
        nanofold.fit(scene, window, free={"environment.drag_coeficient": (0.2, 5)})


def test_fit_of_a_slow_release_goes_through_its_contact():
    import pandas as pd

    # The film was made with the walls' target at 97 deg and their stiffness 1.6 times the lid's;
    # only the contact of the south wall pressing the lid shows the stiffness.
    film = pd.read_csv("patterns/measurements/cube_lid_first_filmed.csv", comment="#")
    r = nanofold.fit("patterns/devices/cube_lid_first_lid_apart.scene.json", film,
                     free={"hinge_defaults.target_angle_deg": (85, 105),
                           "hinge_defaults.stiffness_scale": (0.2, 5)})
    assert r.status == "converged"
    for p, truth in zip(r.parameters, (97.0, 1.6)):
        low, high = p["interval_95"]
        assert low <= truth <= high, (p["path"], low, high)


def test_nets_rank_a_solids_nets_and_give_the_best_as_fold():
    r = nanofold.nets("box:1x2x3", top=5, unit_um=50, simulate=0)
    # A box of three different sides has 54 distinct nets (and a symmetry group of order 8).
    assert (r.distinct_nets, r.symmetry_order, r.search) == (54, 8, "enumerated")
    table = r.table
    assert list(table["rank"]) == list(range(1, 55))
    assert table["radius_of_gyration_um"].is_monotonic_increasing
    assert len(r.folds) == 5 and all(f["nanofold:seams"] for f in r.folds)
    assert r.gallery_svg.startswith("<svg")



def test_a_best_nets_scene_simulates_and_its_walls_meet_along_seams(tmp_path):
    r = nanofold.nets("cube", top=1, simulate=1, fronts=0, yield_samples=0)
    (scene,) = r.write_scenes(tmp_path)
    run = nanofold.simulate(scene)
    seams = {tuple(s) for s in r.folds[0]["nanofold:seams"]}
    edges = lambda text: int(text.split("edges[")[1].split("]")[0])
    met = [tuple(sorted((edges(a), edges(b)))) for a, b in run.meeting_at_contact]
    assert met and all(m in seams for m in met), (met, seams)


def test_a_nets_study_closes_the_cube_along_the_bundled_front_and_gives_yields():
    # The Latin cross released along the bundled cube's closing front (180° as nets lays it).
    r = nanofold.nets("cube", top=1, simulate=1, front_deg=180, unit_um=50, overdrive_deg=5, yield_samples=20)
    best = r.to_dict()["nets"][0]["closing"]["releases"][0]
    assert best["outcome"] == "closes" and best["latched"] == 7
    low, high = best["yield"]["interval_95"]
    assert low <= best["yield"]["fraction"] <= high
    table = r.table
    assert table.loc[0, "best_release"] == "front 180.0" or table.loc[0, "best_release"] == "front 180"
    assert table.loc[0, "outcome"] == "closes"


def test_a_slow_release_goes_on_through_contact_to_the_closed_cube():
    r = nanofold.simulate("patterns/devices/cube_lid_first.scene.json")
    assert r.model == "quasi_static"
    # The south wall meets the lid at 85° (8000 s + 85/95 of a 1326.5 s ramp), pushes it
    # back, and the cube closes as the south wall reaches 90° (8000 s + 1256.6 s).
    assert abs(r.collision["time_s"] - 9186.8239) < 1e-3
    assert r.released["outcome"] == "closes" and len(r.released["latches"]) == 7
    closes = 8000 + 0.5 * math.pi / (1.5 / 60 / 20)
    assert abs(r.released["time_s"] - closes) < 1e-9 * closes


def test_a_studys_fidelity_is_pandas_spearman_of_its_yields_against_compactness():
    import pandas as pd

    r = nanofold.nets("cube", top=6, simulate=6, fronts=2, unit_um=50, overdrive_deg=5, yield_samples=6)
    d = r.to_dict()
    rows = [n for n in d["nets"] if n.get("closing")]
    assert len(rows) == 6

    def best(closing):
        chosen = closing.get("fresh_yield") or closing["releases"][closing["best"]]["yield"]
        return chosen["fraction"]

    frame = pd.DataFrame({"y": [best(n["closing"]) for n in rows],
                          "rg": [n["radius_of_gyration_um"] for n in rows],
                          "leaves": [float(n["leaves"]) for n in rows]})
    # pandas ranks ties at their mean too; its correlation of ranks is an independent one.
    theirs = frame.corr(method="spearman")
    fidelity = d["study"].get("fidelity")
    if frame["y"].nunique() == 1:
        assert fidelity is None
    else:
        for key, column in [("radius_of_gyration", "rg"), ("leaves", "leaves")]:
            if frame[column].nunique() == 1:
                assert key not in fidelity
                continue
            ours = fidelity[key]
            assert ours["pairs"] == 6
            assert abs(ours["rho"] - theirs.loc["y", column]) < 1e-12, (key, ours, theirs)
            low, high = ours["interval_95"]
            assert -1 <= low <= ours["rho"] <= high <= 1


def test_nets_refuse_bad_shapes_and_settings_by_name():
    with pytest.raises(nanofold.InvalidFieldError, match="top"):
        nanofold.nets("cube", top=1000)
    with pytest.raises(nanofold.InvalidFieldError, match="capture_percent"):
        nanofold.nets("cube", capture_percent=0)
    with pytest.raises(nanofold.InvalidFieldError, match="stress_spread_percent"):
        nanofold.nets("cube", stress_spread_percent=45)
    with pytest.raises(nanofold.InvalidFieldError, match="rank_by"):
        nanofold.nets("cube", rank_by="yield", simulate=0)
    with pytest.raises(nanofold.InvalidFieldError, match="shape"):
        nanofold.nets("sphere")


def test_drive_to_targets_folds_from_flat_onto_a_given_state_and_refuses_a_sheet_without_one():
    folded = nanofold.generate.miura(3, 4, angle_deg=65, fold_deg=110)
    targets = np.asarray(folded.fold_angles)
    r = nanofold.fold(folded, drive_to_targets=True)
    assert r.verdict == "reached"
    assert np.abs(np.asarray(r.final_fold_angles_rad) - targets).max() < 1e-9
    flat = nanofold.generate.miura(3, 4, angle_deg=65)
    with pytest.raises(nanofold.NanofoldError, match="drive_to_targets"):
        nanofold.fold(flat, drive_to_targets=True)
