"""Tests of the Python package: records, time series, errors, searches, sweeps, threads."""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import signal
import threading
import traceback
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Iterator

import numpy as np
import pytest

import whirlmap

CLASSES = {"pendulum", "bouncing", "backward_whirl", "forward_whirl", "unresolved"}


@pytest.fixture(scope="module")
def whirl_drop() -> whirlmap.DropResult:
    """A short drop at 8000 r/min, mu 0.4: backward whirl (the onset is near 4500 r/min)."""
    return whirlmap.drop(8000, 0.4, duration_s=0.3)


def test_record_fields(whirl_drop: whirlmap.DropResult) -> None:
    rec = whirl_drop.record
    assert rec["class"] in CLASSES
    assert rec["class"] == "backward_whirl"
    assert rec["model_version"] == whirlmap.MODEL_VERSION >= 5
    force = rec["max_contact_force_n"]
    assert math.isfinite(force) and force > 0
    assert rec["max_contact_force_n"] >= rec["first_contact_force_n"] > 0
    assert rec["energy"]["residual_rel"] < 0.5
    assert len(rec["scene_hash"]) == 16
    assert whirl_drop.scene["mu_dynamic"] == 0.4
    assert whirl_drop.scene["speed_rpm"] == 8000


def test_series_arrays(whirl_drop: whirlmap.DropResult) -> None:
    s = whirl_drop.series
    assert s is not None
    assert set(s) == set(whirlmap.SERIES_NAMES)
    n = len(s["t_s"])
    assert n > 100
    for name, a in s.items():
        assert isinstance(a, np.ndarray) and a.dtype == np.float64 and a.shape == (n,), name
        assert np.all(np.isfinite(a)), name
    t = s["t_s"]
    assert np.all(np.diff(t) > 0), "time increases"
    assert t[-1] <= whirl_drop.record["end_time_s"] + 1e-12
    # The rotor is the race plus the rotor relative to it; it stays near the clearance circle.
    np.testing.assert_allclose(s["x_rotor_m"], s["x_race_m"] + s["x_rel_m"])
    np.testing.assert_allclose(s["y_rotor_m"], s["y_race_m"] + s["y_rel_m"])
    r = np.hypot(s["x_rel_m"], s["y_rel_m"])
    assert r.max() < 1.1 * whirl_drop.clearance_m
    assert np.all(s["contact_force_n"] >= 0)
    assert s["contact_force_n"].max() <= whirl_drop.record["max_contact_force_n"] * (1 + 1e-9)


def test_no_series_and_the_same_record() -> None:
    a = whirlmap.drop(6000, 0.2, duration_s=0.1, series=False)
    b = whirlmap.drop(6000, 0.2, duration_s=0.1)
    assert a.series is None
    assert a.record == b.record


def test_overrides_reach_the_scene() -> None:
    r = whirlmap.drop(
        4000, 0.1, duration_s=0.05, series=False, clearance_m=2e-4, solver__rtol=1e-6
    )
    assert r.scene["clearance_m"] == 2e-4
    assert r.scene["solver"]["rtol"] == 1e-6
    assert r.clearance_m == 2e-4
    same = whirlmap.drop(
        4000, 0.1, duration_s=0.05, series=False, **{"clearance_m": 2e-4, "solver.rtol": 1e-6}
    )
    assert same.record == r.record
    assert whirlmap.drop(4000, 0.1, duration_s=0.05, series=False).record != r.record


BEARING_FIELDS = (
    "peak_ball_load_n",
    "peak_contact_pressure_pa",
    "static_safety_factor",
    "damage_per_drop",
    "drops_to_failure",
)


def test_bearing_analysis_fields() -> None:
    off = whirlmap.drop(8000, 0.1, duration_s=0.05, series=False)
    assert not set(BEARING_FIELDS) & set(off.record)
    on = whirlmap.drop(8000, 0.1, duration_s=0.05, series=False, bearing={})
    rec = on.record
    for key in BEARING_FIELDS:
        assert math.isfinite(rec[key]) and rec[key] > 0, key
    # The analysis only reads the motion: the dynamics are those of the drop without it.
    assert rec["max_contact_force_n"] == off.record["max_contact_force_n"]
    assert rec["static_safety_factor"] * rec["peak_contact_pressure_pa"] == pytest.approx(4.2e9)
    assert rec["drops_to_failure"] * rec["damage_per_drop"] == pytest.approx(1.0)
    assert on.scene["bearing"]["balls_per_row"] == 22


def test_a_bad_value_names_the_field_value_and_range() -> None:
    with pytest.raises(ValueError) as e:
        whirlmap.drop(8000, 0.3, duration_s=0.1, clearance_m=-1)
    msg = str(e.value)
    assert "clearance_m" in msg and "-1" in msg and "allowed" in msg, msg
    with pytest.raises(ValueError, match=r"mu_dynamic = 2\.5: allowed \[0, 2\]"):
        whirlmap.drop(8000, 2.5)
    with pytest.raises(ValueError, match=r"duration_s = -1: allowed"):
        whirlmap.drop(8000, 0.3, duration_s=-1)
    with pytest.raises(ValueError, match="solver.rtol"):
        whirlmap.drop(8000, 0.3, solver__rtol="tight")
    # Not a number at all: named as any other bad value, not float()'s message.
    for bad in ("abc", None, True, np.array([8000.0, 9000.0])):
        with pytest.raises(ValueError, match=r"invalid duration_s = .*: allowed a number"):
            whirlmap.drop(8000, 0.3, duration_s=bad)
    with pytest.raises(ValueError, match=r"invalid speed_rpm = 'fast': allowed a number"):
        whirlmap.drop("fast", 0.3)
    with pytest.raises(ValueError, match=r"invalid mu = 'abc': allowed a number"):
        whirlmap.critical("abc", from_rpm=3000, to_rpm=4000)
    with pytest.raises(ValueError, match=r"invalid mu = \[0\.4, \[0\.5\]\]: allowed a number or a list"):
        whirlmap.critical([0.4, [0.5]], from_rpm=3000, to_rpm=4000)
    with pytest.raises(ValueError, match=r"invalid duration_s = .*: allowed a number"):
        whirlmap.drop(8000, 0.3, duration_s=[1, [2]])
    with pytest.raises(ValueError, match=r"invalid flat = 'no': allowed True or False"):
        whirlmap.sweep({"duration_s": 0.05, "axes": {"mu": [0.3]}}, flat="no")
    # A call refused for a bad value does not also warn of an override the preset replaces.
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ValueError, match="mu_dynamic"):
            whirlmap.drop(8000, 5, fidelity="draft", solver__rtol=1e-9)
    with pytest.raises(ValueError, match='fidelity = "fast"'):
        whirlmap.drop(8000, 0.3, fidelity="fast")


def test_an_unknown_key_raises_and_lists_the_known_ones() -> None:
    with pytest.raises(ValueError) as e:
        whirlmap.drop(8000, 0.3, clearence_m=1e-4)
    msg = str(e.value)
    assert "clearence_m" in msg and "clearance_m" in msg, msg
    with pytest.raises(ValueError, match="race_atol_scale"):
        whirlmap.drop(8000, 0.3, solver__race_atol=10)


def test_a_solver_failure_is_a_simulation_error() -> None:
    with pytest.raises(whirlmap.SimulationError, match=r"simulation failed \(step_budget\)"):
        whirlmap.drop(8000, 0.3, duration_s=0.01, solver__max_step_attempts=10)
    assert issubclass(whirlmap.SimulationError, RuntimeError)
    # In a sweep the failure is recorded in its row instead.
    rows = whirlmap.sweep(
        {"duration_s": 0.01, "scene": {"solver": {"max_step_attempts": 10}},
         "axes": {"mu": [0.3]}}
    )  # fmt: skip
    assert rows[0]["status"] == "failed" and rows[0]["error_kind"] == "step_budget"


def test_default_scene_lists_the_override_keys() -> None:
    scene = whirlmap.default_scene()
    assert scene["speed_rpm"] == 8000
    assert "rtol" in scene["solver"]
    # The keys a scene may leave out are listed too, the optional sections at their defaults.
    for key in ("release_offset_m", "race_speed_rad_s", "quasi_static_race", "stop_speed_rpm"):
        assert key in scene, key
    assert isinstance(scene["thermal"], dict) and scene["thermal"], scene["thermal"]
    assert scene["bearing"]["balls_per_row"] == 22


def test_critical_rows() -> None:
    rows = whirlmap.critical(
        [0.4, 0.1],
        from_rpm=2000,
        to_rpm=8000,
        resolution_rpm=1000,
        tol_rpm=500,
        duration_s=0.5,
        fidelity="draft",
    )
    assert [r["mu"] for r in rows] == [0.4, 0.1]
    keys = {
        "mu", "onset_rpm", "bracket_rpm", "class_below", "class_above",
        "whirl_intervals_rpm", "whirl_at_range_top", "non_monotone", "drops",
        "failed_drops", "converged", "from_rpm", "to_rpm", "resolution_rpm", "tol_rpm",
        "duration_s", "scene_hash", "model_version", "note", "scan", "bisections",
    }  # fmt: skip
    for r in rows:
        assert keys <= set(r), keys - set(r)
        assert r["failed_drops"] == 0
    onset = rows[0]["onset_rpm"]
    assert onset is not None and 2000 < onset < 8000
    lo, hi = rows[0]["bracket_rpm"]
    assert lo < onset <= hi and hi - lo <= 500
    assert rows[0]["class_above"] == "backward_whirl"
    assert rows[0]["recheck"]["fidelity"] == "standard"
    assert rows[1]["onset_rpm"] is None, "mu 0.1 does not whirl"
    json.dumps(rows)  # plain JSON types only


def test_critical_warns_when_failed_drops_leave_the_onset_undecided() -> None:
    # A step budget too small for any drop (the cheapest of the four takes 2986 step
    # attempts in model version 12): every row is returned, with the warning.
    message = r"undecided at mu 0.4 \(4 of 4 drops failed\)"
    with pytest.warns(RuntimeWarning, match=message):
        rows = whirlmap.critical(
            0.4,
            from_rpm=3000,
            to_rpm=6000,
            resolution_rpm=1000,
            tol_rpm=250,
            duration_s=0.3,
            solver__max_step_attempts=2000,
        )
    assert len(rows) == 1
    assert rows[0]["undecided"] is True and rows[0]["converged"] is False
    assert rows[0]["failed_drops"] == 4


def test_critical_warns_when_unsettled_drops_leave_the_onset_undecided() -> None:
    # A backward whirl with intermittent contact at 12000 r/min, below the first continuous
    # whirl at 13000: the classifier calls it unresolved, and the onset above it is undecided.
    with pytest.warns(RuntimeWarning, match=r"mu 0.3 \(0 of \d+ drops failed, \d+ did not settle\)"):
        rows = whirlmap.critical(
            0.3, from_rpm=8000, to_rpm=28000, resolution_rpm=2000, tol_rpm=500,
            unbalance_m=5e-6, clearance_m=2.5e-4,
        )  # fmt: skip
    assert rows[0]["undecided"] is True
    assert rows[0]["note"].startswith("UNDECIDED: 1 drop(s) below the onset")


def test_an_onset_the_re_check_finds_again_within_the_tolerance_holds() -> None:
    # At mu 0.45 standard gives another class at draft's bracket end, 3781.25 r/min, but
    # puts the onset at 3796.875 r/min, within the 25 r/min tolerance: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        rows = whirlmap.critical(0.45, from_rpm=1000, to_rpm=5000, fidelity="draft")
    rc = rows[0]["recheck"]
    assert rc["confirmed"] is False and rc["within_tol"] is True
    assert abs(rc["relocated"]["onset_rpm"] - rows[0]["onset_rpm"]) <= 25.0
    assert rows[0]["converged"] is True
    assert rows[0]["note"].startswith("the onset holds to 25 r/min at the re-check at standard")


def test_critical_warns_when_the_re_check_does_not_confirm_the_onset() -> None:
    # At mu 0.25 the draft preset's bracket lies where standard gives pendulum on both
    # sides, 62.5 r/min below standard's onset (the tolerance is 25 r/min).
    with pytest.warns(RuntimeWarning, match="does not confirm the onset at mu 0.25"):
        rows = whirlmap.critical(
            0.25, from_rpm=10000, to_rpm=13000, resolution_rpm=250, tol_rpm=25,
            fidelity="draft",
        )  # fmt: skip
    assert rows[0]["recheck"]["confirmed"] is False
    assert rows[0]["converged"] is False
    assert rows[0]["note"].startswith("NOT CONFIRMED by the re-check at standard: ")
    # Where standard puts the onset: the search of a standard preset over the same range,
    # run here whole, finds the same.
    relocated = rows[0]["recheck"]["relocated"]
    whole = whirlmap.critical(
        0.25, from_rpm=10000, to_rpm=13000, resolution_rpm=250, tol_rpm=25,
    )  # fmt: skip
    assert relocated["onset_rpm"] == whole[0]["onset_rpm"] > rows[0]["bracket_rpm"][1]
    assert relocated["note"] in rows[0]["note"]


def test_a_preset_warns_of_the_overrides_it_replaces() -> None:
    with pytest.warns(RuntimeWarning, match="solver__rtol=1e-06 has no effect"):
        replaced = whirlmap.drop(duration_s=0.02, fidelity="draft", solver__rtol=1e-6, series=False)
    draft = whirlmap.drop(duration_s=0.02, fidelity="draft", series=False)
    assert replaced.record == draft.record
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        kept = whirlmap.drop(duration_s=0.02, fidelity="draft", unbalance_m=1e-6, series=False)
    assert kept.record["scene_hash"] != draft.record["scene_hash"]
    # A whole solver dict: only the preset's keys in it are replaced, and named.
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        whirlmap.drop(
            duration_s=0.02, fidelity="draft", solver={"max_events": 100000}, series=False
        )
    with pytest.warns(RuntimeWarning, match="so rtol of solver="):
        whirlmap.drop(duration_s=0.02, fidelity="draft", solver={"rtol": 1e-6}, series=False)
    with pytest.warns(RuntimeWarning, match="quasi_static_race=True has no effect"):
        whirlmap.critical(
            0.1, from_rpm=2000, to_rpm=3000, resolution_rpm=1000, duration_s=0.05,
            fidelity="draft", quasi_static_race=True,
        )  # fmt: skip


def test_critical_checks_before_running() -> None:
    # A stop speed above the lowest speed searched: refused there, before any drop.
    with pytest.raises(ValueError, match=r"lowest speed searched, from_rpm = 2000.*stop_speed_rpm"):
        whirlmap.critical(0.4, from_rpm=2000, to_rpm=4000, stop_speed_rpm=3000)
    # The keys the search sets, also spelled with spaces around them.
    for key in (" speed_rpm", "mu_dynamic "):
        with pytest.raises(ValueError, match="allowed no value here"):
            whirlmap.critical(0.5, from_rpm=2000, to_rpm=3000, **{key: 0.3})
    with pytest.raises(ValueError, match="to_rpm"):
        whirlmap.critical(0.4, from_rpm=5000, to_rpm=4000)
    with pytest.raises(ValueError, match="mu"):
        whirlmap.critical(3.0, from_rpm=1000, to_rpm=2000)
    with pytest.raises(ValueError, match="clearence_m"):
        whirlmap.critical(0.4, from_rpm=1000, to_rpm=2000, clearence_m=1e-4)


SPEC = {
    "duration_s": 0.1,
    "fidelity": "draft",
    "axes": {"speed_rpm": [3000, 6000], "mu": [0.1, 0.3, 0.4]},
}


def test_sweep_rows(tmp_path: Path) -> None:
    rows = whirlmap.sweep(SPEC, threads=2)
    assert len(rows) == 2 * 3
    assert [r["index"] for r in rows] == list(range(6))
    assert [(r["speed_rpm"], r["mu"]) for r in rows] == [
        (s, m) for s in (3000, 6000) for m in (0.1, 0.3, 0.4)
    ]
    for r in rows:
        assert r["status"] == "ok" and r["error"] is None
        assert r["class"] in CLASSES
        assert r["max_contact_force_n"] > 0
        assert r["energy.residual_rel"] < 0.5
        assert not any(isinstance(v, dict) for v in r.values()), "flat rows"
    # A spec file gives the same records, and nothing is written beside it.
    path = tmp_path / "tiny.json"
    path.write_text(json.dumps({"name": "tiny", **SPEC}))
    nested = whirlmap.sweep(path, flat=False)
    assert nested == whirlmap.sweep(SPEC, flat=False)
    assert [p["record"]["class"] for p in nested] == [r["class"] for r in rows]
    assert sorted(x.name for x in tmp_path.iterdir()) == ["tiny.json"]


def test_a_sweep_spec_warns_of_the_scene_values_its_preset_replaces(tmp_path: Path) -> None:
    tiny = {
        "duration_s": 0.02,
        "fidelity": "draft",
        "axes": {"speed_rpm": [2000], "mu": [0.1]},
    }
    replaced = {**tiny, "scene": {"solver": {"rtol": 1e-6}}}
    with pytest.warns(RuntimeWarning, match="scene.solver.rtol = 1e-6 has no effect"):
        rows = whirlmap.sweep(replaced)
    path = tmp_path / "replaced.json"
    path.write_text(json.dumps({"name": "replaced", **replaced}))
    with pytest.warns(RuntimeWarning, match="replaced.json: fidelity draft sets the numerics"):
        assert whirlmap.sweep(path) == rows
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert whirlmap.sweep(tiny) == rows


def test_a_bad_sweep_spec_raises() -> None:
    with pytest.raises(ValueError, match=r"axes.mu = 3|friction coefficient"):
        whirlmap.sweep({**SPEC, "axes": {"mu": [3.0]}})
    with pytest.raises(ValueError, match="clearence_m"):
        whirlmap.sweep({**SPEC, "axes": {"clearence_m": [1e-4]}})
    with pytest.raises(FileNotFoundError, match="cannot read") as e:
        whirlmap.sweep("/nonexistent/spec.json")
    assert e.value.filename == "/nonexistent/spec.json"


def test_threads_run_drops_concurrently() -> None:
    """Two Python threads run drops at the same time (the GIL is released while a drop runs)
    and get the same records as one thread does."""
    cases = [(5000 + 500 * i, 0.1 * (i % 5)) for i in range(8)]
    serial = [whirlmap.drop(s, m, duration_s=0.1, series=False).record for s, m in cases]
    with ThreadPoolExecutor(max_workers=2) as pool:
        threaded = list(
            pool.map(
                lambda c: whirlmap.drop(c[0], c[1], duration_s=0.1, series=False).record,
                cases,
            )
        )
    assert threaded == serial


def test_non_finite_values_are_refused_with_their_place() -> None:
    with pytest.raises(ValueError, match=r"nan is not a finite number; allowed \[0, 2\]|NaN is not a finite number; allowed \[0, 2\]"):
        whirlmap.drop(8000, None, mu_dynamic=float("nan"))
    with pytest.raises(ValueError, match=r"Infinity is not a finite number; allowed \(0, 0\.1\] m"):
        whirlmap.drop(8000, 0.3, clearance_m=float("inf"))
    with pytest.raises(ValueError, match=r"invalid release_offset_m\[0\] = nan: allowed a finite number"):
        whirlmap.drop(8000, 0.3, release_offset_m=[float("nan"), 0.0])
    with pytest.raises(ValueError, match=r"invalid spec\.scene\.clearance_m = nan"):
        whirlmap.sweep({**SPEC, "scene": {"clearance_m": float("nan")}})


def test_numbers_of_every_kind_and_non_numbers() -> None:
    # NumPy's wider floats are numbers (their item() is themselves): no endless recursion.
    wide = whirlmap.drop(8000, 0.3, duration_s=0.01, series=False, clearance_m=np.longdouble(2e-4))
    assert wide.scene["clearance_m"] == 2e-4
    whirlmap.drop(
        8000, 0.3, duration_s=0.01, series=False,
        release_offset_m=np.array([1e-5, 0.0], dtype=np.longdouble),
    )  # fmt: skip
    # Not numbers: strings (even of digits), bytes, complex numbers, an int past a double.
    for bad in ("8000", b"8000", 8000 + 5j, np.complex128(8000)):
        with pytest.raises(ValueError, match=r"invalid speed_rpm = .*: allowed a number"):
            whirlmap.drop(bad, 0.3, duration_s=0.01)
    with pytest.raises(ValueError, match=r"invalid duration_s = 1000.*within a double's range"):
        whirlmap.drop(8000, 0.3, duration_s=10**400)
    with pytest.raises(TypeError, match=r"invalid clearance_m = .*0\.0002\+0j.*: allowed numbers"):
        whirlmap.drop(8000, 0.3, duration_s=0.01, clearance_m=np.complex128(2e-4))


def test_an_override_the_speed_or_mu_argument_replaces_is_warned_of() -> None:
    with pytest.warns(RuntimeWarning, match=r"mu_dynamic=0\.5 has no effect: mu=0\.3"):
        r = whirlmap.drop(8000, 0.3, duration_s=0.01, series=False, mu_dynamic=0.5)
    assert r.scene["mu_dynamic"] == 0.3
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        r = whirlmap.drop(8000, None, duration_s=0.01, series=False, mu_dynamic=0.5)
    assert r.scene["mu_dynamic"] == 0.5


def test_results_compare_by_identity_and_specs_by_kind() -> None:
    a = whirlmap.drop(8000, 0.3, duration_s=0.01)
    b = whirlmap.drop(8000, 0.3, duration_s=0.01)
    assert a == a and a != b and len({a, b}) == 2
    assert a.record == b.record
    for bad in (None, 5, b"/tmp/spec.json"):
        with pytest.raises(TypeError, match="invalid spec"):
            whirlmap.sweep(bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="pass the spec as a dict"):
        whirlmap.sweep('{"duration_s": 0.05, "axes": {"mu": [0.1]}}')


def test_parameters_that_combine_past_what_can_run_are_refused_first() -> None:
    # Each in its range; together a heat network too fast to step, or a derived bearing
    # rating out of range: ValueErrors naming them, before any drop.
    with pytest.raises(ValueError, match=r"thermal network, node outer_lubricant"):
        whirlmap.drop(8000, 0.3, duration_s=0.05, thermal={"lubricant_mass_kg": 1e-45})
    with pytest.raises(ValueError, match=r"thermal.housing_length_m = 1e-30|node housing"):
        whirlmap.drop(8000, 0.3, duration_s=0.05, thermal={"housing_length_m": 1e-30})
    with pytest.raises(ValueError, match=r"bearing.static_rating_n = .*ISO 76 rating"):
        whirlmap.drop(8000, 0.3, duration_s=0.05, bearing={"young_modulus_pa": 1e9})


def test_options_are_checked_by_name() -> None:
    for bad in (-1, 0, 10**6, 2.5, True):
        with pytest.raises(ValueError, match="invalid threads"):
            whirlmap.critical(0.4, from_rpm=2000, to_rpm=3000, threads=bad)
    for bad in (-5, 0, 2.7):
        with pytest.raises(ValueError, match="invalid series_points"):
            whirlmap.drop(8000, 0.3, duration_s=0.01, series_points=bad)
    for bad in ("no", 1.0, 1, np.array([1, 0])):
        with pytest.raises(ValueError, match="invalid series"):
            whirlmap.drop(8000, 0.3, duration_s=0.01, series=bad)
    with pytest.raises(ValueError, match="invalid flat"):
        whirlmap.sweep({"duration_s": 0.05, "axes": {"mu": [0.3]}}, flat=np.array([1, 0]))
    with pytest.raises(ValueError, match="invalid fidelity"):
        whirlmap.drop(8000, 0.3, duration_s=0.01, fidelity=1)
    with pytest.raises(ValueError, match="invalid speed_rpm = 1234"):
        whirlmap.critical(0.4, from_rpm=2000, to_rpm=3000, speed_rpm=1234)


def test_a_simulation_error_crosses_process_boundaries() -> None:
    import pickle

    with pytest.raises(whirlmap.SimulationError) as e:
        whirlmap.drop(8000, 0.3, duration_s=0.01, solver__max_step_attempts=10)
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is whirlmap.SimulationError
    assert str(back) == str(e.value)
    assert whirlmap.SimulationError.__module__ == "whirlmap"


@contextlib.contextmanager
def _interrupt_after(seconds: float) -> Iterator[None]:
    """A SIGINT to this process after `seconds`, as Ctrl-C in a terminal sends it; never
    later than the block. Python's own SIGINT handler is installed for the block: a process
    started in the background by a non-interactive shell (a CI job) inherits SIGINT ignored,
    and Python then installs none."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        timer.join()
        signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_a_sweep_before_its_end() -> None:
    # 2000 one-second drops on one thread: tens of seconds, where the interrupt comes after
    # half a second. Without it reaching the engine, the call would return every record
    # and the interrupt would arrive only then, without the count.
    speeds = list(range(2000, 12000, 5))
    spec = {"duration_s": 1.0, "axes": {"speed_rpm": speeds, "mu": [0.1]}}
    with pytest.raises(KeyboardInterrupt) as info, _interrupt_after(0.5):
        whirlmap.sweep(spec, threads=1)
    m = re.fullmatch(
        r"sweep interrupted: (\d+) of 2000 points had run; nothing is returned",
        str(info.value),
    )
    assert m is not None, str(info.value)
    assert int(m.group(1)) < 2000
    # The next call runs as usual.
    assert len(whirlmap.sweep(SPEC, threads=1)) == 6


def test_ctrl_c_stops_a_critical_search_before_its_end() -> None:
    with pytest.raises(KeyboardInterrupt) as info, _interrupt_after(0.5):
        whirlmap.critical(
            [0.1, 0.2, 0.3, 0.4], from_rpm=1000, to_rpm=30000, resolution_rpm=50, threads=1
        )
    m = re.fullmatch(
        r"critical search interrupted after (\d+) drops \(its scan has (\d+), then "
        r"bisections and, with a fidelity preset, two re-check drops per onset and a window "
        r"search at the tighter preset for each onset they do not confirm\); nothing is returned",
        str(info.value),
    )
    assert m is not None, str(info.value)
    assert int(m.group(1)) < int(m.group(2)) == 4 * 581


def test_another_signal_handlers_exception_stops_a_sweep_too() -> None:
    class Timeout(Exception):
        pass

    def on_alarm(signum: int, frame: object) -> None:
        raise Timeout()

    previous = signal.signal(signal.SIGALRM, on_alarm)
    try:
        speeds = list(range(2000, 12000, 5))
        spec = {"duration_s": 1.0, "axes": {"speed_rpm": speeds, "mu": [0.1]}}
        with pytest.raises(Timeout) as info:
            signal.setitimer(signal.ITIMER_REAL, 0.5)
            whirlmap.sweep(spec, threads=1)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    # Raised inside the call (its frame is on the traceback), not after it returned.
    frames = [f.name for f in traceback.extract_tb(info.tb)]
    assert "sweep" in frames, frames
