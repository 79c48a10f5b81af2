"""whirlmap: rotor drops onto AMB touchdown bearings, from Python.

The same engine as the ``whirlmap`` command, built from the same Rust crates:

- :func:`drop` runs one drop and returns its record (the JSON record of
  ``whirlmap drop --json``, as a dict) and its time series as NumPy arrays;
- :func:`critical` searches the critical speed of backward whirl per friction
  coefficient (the rows of ``whirlmap critical --json``);
- :func:`sweep` runs the grid of a sweep spec in memory and returns one flat row per
  grid point, ready for ``pandas.DataFrame(rows)``.

Scene parameters are keyword arguments named as the command line's ``--set`` keys; a
dotted key is written with ``__`` for each dot (``solver__rtol=1e-7``) or passed as
``**{"solver.rtol": 1e-7}``. A bad parameter raises ``ValueError`` naming the field,
the value and the allowed range; a drop the solver cannot finish raises
:class:`SimulationError`. The GIL is released while drops run, so Python threads run
drops concurrently. See docs/python.md.
"""

from __future__ import annotations

import json
import os
import warnings
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _whirlmap
from ._whirlmap import MODEL_VERSION as _MODEL_VERSION
from ._whirlmap import SimulationError

#: The model version of this build: a drop record's ``model_version`` (its results change only
#: with it; docs/results-format.md).
MODEL_VERSION: int = _MODEL_VERSION

__all__ = [
    "DropResult",
    "MODEL_VERSION",
    "SimulationError",
    "critical",
    "default_scene",
    "drop",
    "sweep",
]

#: The time series of a drop, in the order :attr:`DropResult.series` holds them.
SERIES_NAMES: Tuple[str, ...] = (
    "t_s",
    "x_rotor_m",
    "y_rotor_m",
    "x_race_m",
    "y_race_m",
    "x_rel_m",
    "y_rel_m",
    "contact_force_n",
    "slip_m_s",
    "heat_power_w",
    "rotor_speed_rad_s",
    "race_speed_rad_s",
)


@dataclass(frozen=True, eq=False)
class DropResult:
    """One drop's outputs.

    Attributes:
        record: The drop record, exactly the JSON object ``whirlmap drop --json`` prints
            (``class``, ``max_contact_force_n``, ``energy``, ``features``,
            ``model_version``, ...; docs/results-format.md#the-drop-record).
        series: The recorded time series (``None`` when run with ``series=False``), each a
            1-D float array of the same length, in increasing time: ``t_s`` (s since
            release); the rotor centre ``x_rotor_m``, ``y_rotor_m`` and the race centre
            ``x_race_m``, ``y_race_m`` relative to the housing (m, up is +y); the rotor
            relative to the race ``x_rel_m``, ``y_rel_m`` (m: the Fig. 3 view, inside the
            clearance circle); ``contact_force_n`` (N); ``slip_m_s``, the slip velocity at
            the contact (m/s, zero while it rolls); ``heat_power_w`` (W); and both spins
            ``rotor_speed_rad_s``, ``race_speed_rad_s`` (rad/s).
        clearance_m: The radial clearance (m): the radius of the clearance circle.
        scene: The scene that ran, as a dict (the JSON of ``whirlmap scene``).

    Results compare (``==``) and hash by identity: NumPy arrays have no single truth value,
    so two drops are compared by their ``record`` dicts (equal for the same scene and build).
    """

    record: Dict[str, Any]
    series: Optional[Dict[str, np.ndarray]]
    clearance_m: float
    scene: Dict[str, Any]


def _json_default(value: Any) -> Any:
    """JSON for NumPy scalars and arrays (``np.float64(0.3)``, ``np.array([0, 1e-5])``).
    A real scalar of any width becomes a Python number (``np.longdouble`` too, whose
    ``item()`` is itself); a complex one, or any other object, is no JSON value."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not a JSON value: {value!r}")


def _nonfinite_path(value: Any, path: str) -> Optional[Tuple[str, Any]]:
    """The first NaN or infinity in ``value`` (a JSON-like value), as (dotted path, value)."""
    if isinstance(value, (float, np.floating)) and not np.isfinite(value):
        return path, value
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, Mapping):
        for key, inner in value.items():
            found = _nonfinite_path(inner, f"{path}.{key}" if path else str(key))
            if found:
                return found
    elif isinstance(value, (list, tuple)):
        for i, inner in enumerate(value):
            found = _nonfinite_path(inner, f"{path}[{i}]")
            if found:
                return found
    return None


def _json(value: Any, what: str) -> str:
    """``value`` as JSON text; a NaN or infinity in it (JSON has neither) is a ``ValueError``
    naming its place in ``what``."""
    found = _nonfinite_path(value, "")
    if found:
        path, bad = found
        place = f"{what}.{path}" if path and not path.startswith("[") else f"{what}{path}"
        raise ValueError(f"invalid {place} = {bad}: allowed a finite number")
    try:
        return json.dumps(value, default=_json_default, allow_nan=False)
    except ValueError:
        # A NumPy long double past a double's range, infinite once a float.
        raise ValueError(
            f"invalid {what} = {value!r}: allowed finite numbers within a double's range"
        ) from None
    except TypeError as e:
        raise TypeError(
            f"invalid {what} = {value!r}: allowed numbers, strings, booleans, None, lists and"
            f" dicts of them, and NumPy real numbers and arrays ({e})"
        ) from None


def _dotted(key: str) -> str:
    """An override's keyword as the scene key it names: ``solver__rtol`` is ``solver.rtol``;
    spaces around it are dropped, as the engine drops them."""
    return key.replace("__", ".").strip()


def _overrides(overrides: Mapping[str, Any]) -> List[Tuple[str, str]]:
    """Scene overrides as ``(dotted key, value as JSON text)`` pairs, in the order given. A
    single non-finite number goes as ``NaN`` or ``Infinity``, which the scene refuses with the
    field's range; one inside a list or dict is refused here, naming its place."""
    pairs = []
    for key, value in overrides.items():
        dotted = _dotted(key)
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value.item()
        if isinstance(value, (float, np.floating)) and not np.isfinite(value):
            pairs.append((dotted, json.dumps(float(value))))
        else:
            pairs.append((dotted, _json(value, dotted)))
    return pairs


def _threads(threads: Optional[int]) -> Optional[int]:
    """``threads`` checked: ``None``, or a whole number in [1, 4096]."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)):
        raise ValueError(f"invalid threads = {threads!r}: allowed a whole number in [1, 4096] or None")
    if not 1 <= int(threads) <= 4096:
        raise ValueError(f"invalid threads = {threads}: allowed [1, 4096] (or None)")
    return int(threads)


def _fidelity(fidelity: Optional[str]) -> Optional[str]:
    """``fidelity`` checked to be ``None`` or a preset's name (the name itself is checked by
    the engine)."""
    if fidelity is not None and not isinstance(fidelity, str):
        raise ValueError(
            f"invalid fidelity = {fidelity!r}: allowed \"draft\", \"standard\", \"reference\" or None"
        )
    return fidelity


def _ndim(value: Any) -> int:
    """NumPy's number of dimensions of ``value``, or -1 for a ragged list (NumPy's own error
    there would not name the argument)."""
    try:
        return int(np.ndim(value))
    except ValueError:
        return -1


def _number(value: Any, name: str) -> float:
    """``value`` as a float, or a ``ValueError`` naming ``name``: a string, ``None``, a
    boolean, a complex number, an integer past a double's range or an array of more than one
    number is no number here (the engine checks the range)."""
    if (
        isinstance(value, (bool, np.bool_, str, bytes, complex, np.complexfloating))
        or _ndim(value) != 0
    ):
        raise ValueError(f"invalid {name} = {value!r}: allowed a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"invalid {name} = {value!r}: allowed a number") from None
    except OverflowError:
        # A Python int past a double's range: the engine's own message would say which
        # range, but the number cannot reach it.
        raise ValueError(
            f"invalid {name} = {value!r}: allowed a number within a double's range (|x| < 1.8e308)"
        ) from None
    return number


def _warn_preset_overrides(fidelity: Optional[str], overrides: Dict[str, Any]) -> None:
    """Warns of each override a fidelity preset replaces: the preset is applied after the
    overrides and sets the numerics (``solver__rtol``, ``solver__method``, ... and
    ``quasi_static_race``, also inside a whole ``solver`` dict), so they would otherwise
    vanish without a word."""
    if fidelity is None:
        return
    for key, value in overrides.items():
        dotted = _dotted(key)
        if dotted in _whirlmap.PRESET_KEYS:
            warnings.warn(
                f"fidelity={fidelity!r} sets the numerics, so {key}={value!r} has no effect"
                " (leave out fidelity to choose them yourself)",
                RuntimeWarning,
                stacklevel=3,
            )
        elif dotted == "solver" and isinstance(value, Mapping):
            # A whole section: the preset replaces its keys of the preset's, the rest stay.
            replaced = [k for k in value if f"solver.{k}" in _whirlmap.PRESET_KEYS]
            if replaced:
                warnings.warn(
                    f"fidelity={fidelity!r} sets the numerics, so {', '.join(replaced)} of"
                    f" {key}={value!r} has no effect (its other keys do; leave out fidelity"
                    " to choose them yourself)",
                    RuntimeWarning,
                    stacklevel=3,
                )


def _warn_spec_preset_overrides(spec_text: str, where: str) -> None:
    """Warn (``RuntimeWarning``) of each value of a sweep spec's ``scene`` that its
    ``fidelity`` preset replaces: the preset is applied after them, so they would otherwise
    vanish without a word. An axis is applied after the preset and may still set them."""
    replaced = _whirlmap.replaced_by_fidelity(spec_text)
    preset = json.loads(spec_text.lstrip("\ufeff")).get("fidelity") if replaced else None
    for key, value in replaced:
        warnings.warn(
            f"{where}: fidelity {preset} sets the numerics, so {key} = {value} has no effect"
            " (leave out fidelity to choose them yourself, or give the value on an axis,"
            " which is applied after the preset)",
            RuntimeWarning,
            stacklevel=3,
        )


def default_scene() -> Dict[str, Any]:
    """The default (paper) scene as a dict: every key a scene override may name.

    Returns:
        The JSON of ``whirlmap scene --all``, parsed: the ``thermal`` and ``bearing``
        sections at their defaults, though a drop runs without them unless they are given.
    """
    return json.loads(_whirlmap.default_scene())


def drop(
    speed_rpm: Optional[float] = None,
    mu: Optional[float] = None,
    *,
    duration_s: float = 1.0,
    fidelity: Optional[str] = None,
    series: bool = True,
    series_points: int = 20_000,
    **overrides: Any,
) -> DropResult:
    """Simulate one drop, as ``whirlmap drop`` does.

    The scene is the paper's, then each override in the order given, then ``speed_rpm``
    and ``mu`` (an override ``speed_rpm`` or ``mu_dynamic`` beside them has no effect: a
    ``RuntimeWarning`` says so); it is validated, then the fidelity preset is applied.

    Args:
        speed_rpm: Rotor speed at release (r/min); ``None``: the scene's (8000).
        mu: Dynamic friction coefficient rotor-race, in [0, 2] (the scene's
            ``mu_dynamic``); ``None``: the scene's (0.1).
        duration_s: Simulated time after release (s), in (0, 3600]; a drop whose class
            has not settled is extended (scene ``classification.max_extension_s``).
        fidelity: ``"draft"``, ``"standard"`` or ``"reference"``: the numerics preset;
            ``None``: the scene's own solver settings.
        series: Record the time series.
        series_points: The series' density, a whole number in [1, 1e7]: a sample is taken at
            an accepted solver step at least ``duration_s / series_points`` after the last
            one. So about ``series_points`` samples cover the requested duration where the
            steps are shorter than that spacing, fewer where they are longer, more when the
            drop is extended for its class to settle; they are unevenly spaced in time
            (resample before an FFT).
        **overrides: Scene parameters by their ``--set`` key: ``clearance_m=2e-4``,
            ``solver__rtol=1e-7`` (``__`` for each dot), ``friction_law="switched"``,
            ``release_offset_m=[1e-5, 0]``, ``thermal={}``.

    Returns:
        The record, the time series, the clearance and the scene.

    Raises:
        ValueError: A bad parameter or option; the message names the field, the value and
            the allowed range (or, for an unknown key, the known ones).
        SimulationError: The solver failed (its kind and the simulated time are in the
            message).
    """
    # Not `in (True, False)`: 1.0 equals True, and an array has no single truth value.
    if not isinstance(series, (bool, np.bool_)):
        raise ValueError(f"invalid series = {series!r}: allowed True or False")
    whole = isinstance(series_points, (int, np.integer)) or (
        isinstance(series_points, (float, np.floating)) and float(series_points).is_integer()
    )
    if series and (
        isinstance(series_points, bool) or not whole or not 1 <= series_points <= 10_000_000
    ):
        raise ValueError(
            f"invalid series_points = {series_points!r}: allowed a whole number in [1, 1e7]"
        )
    record, scene, arrays, clearance_m = _whirlmap.drop(
        None if speed_rpm is None else _number(speed_rpm, "speed_rpm"),
        None if mu is None else _number(mu, "mu"),
        _number(duration_s, "duration_s"),
        _fidelity(fidelity),
        int(series_points) if series else None,
        _overrides(overrides),
    )
    # After the drop: a call refused for a bad value says only that (a drop takes a second).
    _warn_preset_overrides(fidelity, overrides)
    for key, arg, given in (("speed_rpm", "speed_rpm", speed_rpm), ("mu_dynamic", "mu", mu)):
        for name, value in overrides.items():
            if given is not None and _dotted(name) == key:
                warnings.warn(
                    f"{name}={value!r} has no effect: {arg}={given!r} is applied after the"
                    " overrides",
                    RuntimeWarning,
                    stacklevel=2,
                )
    return DropResult(
        record=json.loads(record),
        series=None if arrays is None else {k: arrays[k] for k in SERIES_NAMES},
        clearance_m=clearance_m,
        scene=json.loads(scene),
    )


def critical(
    mu: Union[float, Sequence[float], "np.ndarray[Any, Any]"],
    *,
    from_rpm: float = 1000.0,
    to_rpm: float = 30000.0,
    resolution_rpm: float = 250.0,
    tol_rpm: float = 25.0,
    duration_s: float = 1.0,
    fidelity: Optional[str] = None,
    threads: Optional[int] = None,
    **overrides: Any,
) -> List[Dict[str, Any]]:
    """Search the critical speed of backward whirl, as ``whirlmap critical`` does.

    For each friction coefficient: a scan over every multiple of ``resolution_rpm`` in
    ``[from_rpm, to_rpm]`` (and both ends), then a bisection of every class transition down
    to ``tol_rpm`` (docs/critical-speed.md). With a ``fidelity`` preset, the onset bracket is
    re-checked at the next tighter preset (the row's ``recheck``); a row without one at the
    end of the range that decides it (the top for no whirl, the bottom for whirl from the
    start).

    Args:
        mu: One friction coefficient or several, each in [0, 2].
        from_rpm: Lowest release speed searched (r/min), in [0, 1e6).
        to_rpm: Highest release speed searched (r/min), in (from_rpm, 1e6].
        resolution_rpm: Lattice step of the scan (r/min).
        tol_rpm: Bisect each transition until its bracket is this narrow (r/min), at most
            ``resolution_rpm``.
        duration_s: Simulated time of each drop (s).
        fidelity: ``"draft"``, ``"standard"`` or ``"reference"``, or ``None``.
        threads: Worker threads, in [1, 4096]; ``None``: one per core (or
            ``RAYON_NUM_THREADS``).
        **overrides: Scene parameters, as for :func:`drop`, but for ``speed_rpm`` and
            ``mu_dynamic``, which the search sets for every drop (refused here).

    Returns:
        One dict per friction coefficient, in the order given: the ``CriticalRow`` schema
        of a sweep's ``critical.json`` (``mu``, ``onset_rpm``, ``bracket_rpm``,
        ``class_below``, ``class_above``, ``whirl_intervals_rpm``, ``converged``,
        ``drops``, ``note``, ``scan``, ``bisections``, ...). ``pandas.DataFrame(rows)``
        reads them. A failed drop is recorded in its row; when failed drops leave a row's
        onset undecided (every scan drop failed, or one failed below the onset, or any
        when no whirl was found), or drops that did not settle (class ``unresolved``) do
        (below the onset, or any when no whirl was found), the row has ``undecided`` true
        (the key is there only then) and ``converged`` false.

    Warns:
        RuntimeWarning: Some row is undecided (the command line exits 1 then); the message
            names the friction coefficients and their failed or unsettled drops. Every row
            is returned.
            Also when, with a ``fidelity`` preset, the re-check at the next tighter preset
            does not confirm some row's onset bracket (or, for a row without one, the end of
            the range that decides it: its highest speed when it found no whirl, its lowest
            when whirl starts there) and does not find that preset's onset within
            ``tol_rpm`` of it (``within_tol``; the command line exits 1 then too);
            that row's ``converged`` is then false and its ``note`` says ``NOT CONFIRMED by
            the re-check`` (at its head, or at the end of an undecided row's note, which
            starts with ``UNDECIDED``). The search then runs again at the tighter preset
            over at least two lattice steps either side of the cells re-run (within the
            range), and
            ``recheck["relocated"]`` says where that preset puts the onset (``onset_rpm``,
            null when not in that window, and a ``note`` that the row's note repeats).

    Raises:
        ValueError: A bad option, friction coefficient or scene parameter (named, with its
            value and allowed range); nothing has run.
        KeyboardInterrupt: Ctrl-C (or a notebook's "interrupt kernel") while the search
            runs, when called from Python's main thread: the drops not yet started are
            skipped, the running ones finish (at most a drop's time: at the tighter preset
            for a re-check), and no row is returned; the message says how many drops had
            run. An exception another signal handler raises stops it the same way.
    """
    mu_ndim = _ndim(mu)
    if mu_ndim == 0:
        mus = [_number(mu, "mu")]
    elif mu_ndim == 1:
        mus = [_number(m, "mu") for m in mu]  # type: ignore[union-attr]
    else:
        raise ValueError(f"invalid mu = {mu!r}: allowed a number or a list of numbers")
    # The search sets the speed and the friction coefficient of every drop itself.
    for key, by in (("speed_rpm", "from_rpm and to_rpm"), ("mu_dynamic", "mu")):
        for given, value in overrides.items():
            if _dotted(given) == key:
                raise ValueError(
                    f"invalid {key} = {value!r}: allowed no value here, {by} set it "
                    "for every drop of the search"
                )
    _warn_preset_overrides(fidelity, overrides)
    text = _whirlmap.critical(
        mus,
        _number(from_rpm, "from_rpm"),
        _number(to_rpm, "to_rpm"),
        _number(resolution_rpm, "resolution_rpm"),
        _number(tol_rpm, "tol_rpm"),
        _number(duration_s, "duration_s"),
        _fidelity(fidelity),
        _overrides(overrides),
        _threads(threads),
    )
    rows: List[Dict[str, Any]] = json.loads(text)
    def unsettled(r: Dict[str, Any]) -> int:
        # The unsettled drops that could hide the onset: below it, or any without one.
        probes = list(r.get("scan", [])) + list(r.get("bisections", []))
        onset = r.get("onset_rpm")
        return sum(
            1
            for p in probes
            if p.get("class") == "unresolved" and (onset is None or p["speed_rpm"] < onset)
        )

    undecided = [
        f"mu {r['mu']} ({r['failed_drops']} of {r['drops']} drops failed"
        + (f", {unsettled(r)} did not settle)" if unsettled(r) else ")")
        for r in rows
        if r.get("undecided")
    ]
    if undecided:
        warnings.warn(
            "failed or unsettled drops leave the critical speed undecided at "
            + ", ".join(undecided)
            + "; every row is returned and its note says why",
            RuntimeWarning,
            stacklevel=2,
        )
    unconfirmed = [
        f"mu {r['mu']}"
        for r in rows
        if r.get("recheck")
        and not (r["recheck"]["confirmed"] or r["recheck"].get("within_tol", False))
    ]
    if unconfirmed:
        warnings.warn(
            "the re-check at the next tighter preset does not confirm the onset at "
            + ", ".join(unconfirmed)
            + "; do not use this preset's onset there (each row's recheck says where"
            + " the tighter preset puts it)",
            RuntimeWarning,
            stacklevel=2,
        )
    return rows


def _flatten(prefix: str, value: Any, row: Dict[str, Any]) -> None:
    """Adds ``value`` to ``row`` under ``prefix``, nested dicts as dotted column names."""
    if isinstance(value, dict):
        for key, inner in value.items():
            _flatten(f"{prefix}.{key}" if prefix else key, inner, row)
    else:
        row.setdefault(prefix, value)


def sweep(
    spec: Union[Mapping[str, Any], str, "os.PathLike[str]"],
    *,
    threads: Optional[int] = None,
    flat: bool = True,
) -> List[Dict[str, Any]]:
    """Run the grid of a sweep spec in memory; nothing is written.

    Every grid point's scene is checked before any drop runs. Only the grid runs: the
    spec's ``critical``, ``orbits``, ``probability`` and ``charts`` sections are checked but
    not run (use :func:`critical` for the search).

    Args:
        spec: A sweep spec (docs/sweeps.md) as a dict, or the path of a sweep JSON file. A
            dict may leave out ``name``.
        threads: Worker threads, in [1, 4096]; ``None``: one per core (or
            ``RAYON_NUM_THREADS``).
        flat: Return flat rows (below); ``False``: the points' records as a sweep writes
            them to ``points.jsonl`` (nested dicts).

    Returns:
        One row per grid point, in grid order (the first axis varying slowest). A flat row
        holds ``index``, ``key``, ``status`` (``"ok"`` or ``"failed"``), the axis values by
        axis name, ``duration_s``, ``model_version``, ``scene_hash``, ``error_kind`` and
        ``error`` (``None`` when ok), and every field of the drop record, nested ones as
        dotted names (``energy.residual_rel``, ``features.window.contact_duty``); a
        record field named as an axis keeps the axis value. ``pandas.DataFrame(rows)``
        reads them.

    Raises:
        ValueError: The spec is invalid (the message names the field, the value and the
            allowed range), or is a str of JSON text rather than a path; nothing has run.
        OSError: The spec file cannot be read (``FileNotFoundError`` when it does not
            exist, with its ``filename``); nothing has run.
        TypeError: ``spec`` is neither a dict nor a path (``str`` or ``os.PathLike``).
        KeyboardInterrupt: Ctrl-C (or a notebook's "interrupt kernel") while the grid runs,
            when called from Python's main thread: the points not yet started are skipped,
            the running ones finish (at most a drop's time), and no record is returned; the
            message says how many points had run. An exception another signal handler
            raises stops it the same way.
    """
    if not isinstance(flat, (bool, np.bool_)):
        raise ValueError(f"invalid flat = {flat!r}: allowed True or False")
    if isinstance(spec, Mapping):
        spec_dict = dict(spec)
        spec_dict.setdefault("name", "python")
        spec_text = _json(spec_dict, "spec")
        _warn_spec_preset_overrides(spec_text, "the spec")
        text = _whirlmap.sweep(spec_text, None, _threads(threads))
    else:
        if not isinstance(spec, (str, os.PathLike)) or isinstance(spec, bytes):
            raise TypeError(
                f"invalid spec = {spec!r}: allowed a dict (a sweep spec) or the path of a sweep"
                " JSON file (str or os.PathLike)"
            )
        path = os.fspath(spec)
        if isinstance(path, bytes):
            raise TypeError(f"invalid spec = {spec!r}: allowed a path as str, not bytes")
        if path.lstrip().startswith("{"):
            raise ValueError(
                "invalid spec: a str is the path of a sweep JSON file, and this one is JSON"
                " text; pass the spec as a dict (json.loads(text))"
            )
        try:
            with open(path, encoding="utf-8") as f:
                _warn_spec_preset_overrides(f.read(), path)
        except (OSError, UnicodeDecodeError):
            pass  # the sweep below reads it again and raises the error
        text = _whirlmap.sweep(None, path, _threads(threads))
    points = json.loads(text)
    if not flat:
        return points
    rows = []
    for p in points:
        error = p.get("error") or {}
        row: Dict[str, Any] = {
            "index": p["index"],
            "key": p["key"],
            "status": p["status"],
            **p["inputs"],
            "duration_s": p["duration_s"],
            "model_version": p["model_version"],
            "scene_hash": p["scene_hash"],
            "error_kind": error.get("kind"),
            "error": error.get("message"),
        }
        _flatten("", p.get("record") or {}, row)
        rows.append(row)
    return rows
