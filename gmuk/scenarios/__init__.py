"""Thesis scenarios, runnable from Python or as ``gmuk run NAME``.

A scenario is a :class:`Scenario`: its name, a one-line description, the options it takes
(each an :class:`Option`, which the ``gmuk`` command turns into a flag with help text), a
``run(**options) -> ScenarioResult``, a ``figures(result, out_dir, formats) -> list[Path]``
and optionally ``write_data(result, out_dir) -> list[Path]``. Each module of this package
defines one as ``SCENARIO`` and keeps its functions and ``NAME``/``DESCRIPTION`` importable::

    from gmuk.scenarios import fcei
    result = fcei.run(orbits=0.5)  # or: scenarios.get("fcei").run(orbits=0.5)

Adding a scenario
-----------------
Write a module that defines ``SCENARIO = Scenario(...)`` and register it: in gmuk, one line
in :data:`SCENARIOS`; in another package, an entry point of the group ``gmuk.scenarios``
naming the object::

    [project.entry-points."gmuk.scenarios"]
    tumble = "my_package.tumble:SCENARIO"

Discovery runs once and is cached (:func:`refresh` forgets it). A plugin that fails to load,
does not name a :class:`Scenario`, or takes a name already used is skipped with a
:class:`gmuk.errors.PluginWarning` saying why; it never breaks gmuk.

Options
-------
``Option(name, type, default, help, choices=None)``: ``name`` is the keyword of ``run`` and,
with ``_`` written ``-``, the flag (``thesis_normalization`` → ``--thesis-normalization``);
``type`` turns the command-line text into the value (``int``, ``float``, ``str``, or a
parser such as :func:`positive_float`, :func:`comma_separated` or :func:`boolean`); a bad
value raises :class:`OptionError` naming the flag and what came in. The command line passes
every declared option to ``run``, the defaults for those not given.
"""

from __future__ import annotations

import functools
import keyword
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from gmuk._plugins import entry_point_plugins, load_target
from gmuk.errors import DefinitionError, GmukError
from gmuk.trajectory import Trajectory

__all__ = [
    "ENTRY_POINT_GROUP",
    "SCENARIOS",
    "Option",
    "OptionError",
    "Scenario",
    "ScenarioResult",
    "available",
    "boolean",
    "comma_separated",
    "describe",
    "get",
    "non_negative_float",
    "positive_float",
    "refresh",
]

#: gmuk's scenarios: name → ``"module:attribute"`` of its :class:`Scenario`, thesis order.
SCENARIOS: dict[str, str] = {
    "apollo16": "gmuk.scenarios.apollo16:SCENARIO",
    "fccn": "gmuk.scenarios.fccn:SCENARIO",
    "fcei": "gmuk.scenarios.fcei:SCENARIO",
    "fceim": "gmuk.scenarios.fceim:SCENARIO",
    "ucei": "gmuk.scenarios.ucei:SCENARIO",
    "uceis": "gmuk.scenarios.uceis:SCENARIO",
    "uceim": "gmuk.scenarios.uceim:SCENARIO",
    "fccl": "gmuk.scenarios.fccl:SCENARIO",
    "unmodeled": "gmuk.scenarios.unmodeled:SCENARIO",
    "smd-gt": "gmuk.scenarios.smd:GT",
    "smd-lt": "gmuk.scenarios.smd:LT",
    "smd-bi": "gmuk.scenarios.smd:BI",
    "smd-compare": "gmuk.scenarios.smd_compare:SCENARIO",
    "maintenance": "gmuk.scenarios.maintenance:SCENARIO",
    "rw-pointing": "gmuk.scenarios.rw_pointing:SCENARIO",
    "lunar-rcs": "gmuk.scenarios.lunar_rcs:SCENARIO",
    "lunar-flyby": "gmuk.scenarios.lunar_flyby:SCENARIO",
    "four-bar": "gmuk.scenarios.four_bar:SCENARIO",
    "stewart": "gmuk.scenarios.stewart:SCENARIO",
    "panda": "gmuk.scenarios.panda:SCENARIO",
    "quadruped": "gmuk.scenarios.quadruped:SCENARIO",
}

#: Entry-point group through which other packages register scenarios.
ENTRY_POINT_GROUP = "gmuk.scenarios"

#: Option names the ``gmuk run`` command keeps for itself (its common flags).
RESERVED_OPTIONS = frozenset({"out", "no_plots", "format", "help"})

T = TypeVar("T")

# How parse errors name the built-in types.
_WHAT: dict[Any, str] = {int: "an integer", float: "a number"}
_PLURAL: dict[Any, str] = {int: "integers", float: "numbers"}


class OptionError(GmukError, ValueError):
    """A scenario option got a value it cannot take (the message names the flag)."""


@dataclass(frozen=True)
class ScenarioResult:
    """What a scenario run produces.

    Attributes
    ----------
    name : str
    trajectories : dict of str → Trajectory
        Every run of the scenario (e.g. "fcei" and "fceim" for a comparison).
    primary : str
        The key of the trajectory saved as ``trajectory.npz``.
    summary : dict
        Headline figures (JSON-serialisable), with units in the keys.
    data : dict
        Further results for the figures and for Python users (e.g. the
        :class:`gmuk.kkt.KKTDiagnostics` of each run, the Systems); the command line saves
        only what the scenario's ``write_data`` writes.
    """

    name: str
    trajectories: dict[str, Trajectory]
    primary: str
    summary: dict[str, Any] = field(default_factory=dict)
    data: dict[str, Any] = field(default_factory=dict)


FigureFn = Callable[[ScenarioResult, Path, tuple[str, ...]], list[Path]]
DataFn = Callable[[ScenarioResult, Path], list[Path]]


# --- parsers for Option.type -------------------------------------------------------------------


def positive_float(text: str) -> float:
    """A finite number > 0, e.g. ``"0.5"``."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and value != float("inf")):
        raise ValueError("must be a finite number > 0")
    return value


def non_negative_float(text: str) -> float:
    """A finite number ≥ 0, e.g. ``"0"`` or ``"1e-8"``."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value >= 0 and value != float("inf")):
        raise ValueError("must be a finite number >= 0")
    return value


def boolean(text: str) -> bool:
    """``true``/``false``, ``yes``/``no``, ``on``/``off`` or ``1``/``0`` (any case)."""
    word = text.strip().lower()
    if word in ("true", "yes", "on", "1"):
        return True
    if word in ("false", "no", "off", "0"):
        return False
    raise ValueError("must be true or false (yes/no, on/off, 1/0)")


def comma_separated(item: Callable[[str], T]) -> Callable[[str], tuple[T, ...]]:
    """A parser of comma-separated values, each parsed by ``item``: with ``int``,
    ``"2,10,50"`` → ``(2, 10, 50)``. At least one value is required."""

    def parse(text: str) -> tuple[T, ...]:
        parts = [p.strip() for p in text.split(",")]
        if not any(parts) or not all(parts):
            raise ValueError("must be one or more comma-separated values, e.g. 2,10,50")
        try:
            return tuple(item(p) for p in parts)
        except (ValueError, TypeError):
            what = _PLURAL.get(item) or f"values {getattr(item, '__name__', repr(item))} accepts"
            raise ValueError(f"must be comma-separated {what}, e.g. 2,10,50") from None

    parse.__name__ = f"comma_separated({getattr(item, '__name__', 'value')})"
    return parse


def _show(value: Any) -> str:
    """A value as it would be typed on the command line."""
    if isinstance(value, (tuple, list)):
        return ",".join(_show(v) for v in value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


@dataclass(frozen=True)
class Option:
    """An option of a scenario: a keyword of its ``run`` and a flag of ``gmuk run NAME``.

    Parameters
    ----------
    name : str
        Keyword of ``run`` (a Python identifier); the flag is ``--name`` with ``_`` → ``-``.
    type : callable str → value
        Parses the command-line text; raises ``ValueError`` (or ``TypeError``) on bad text.
        ``bool`` is refused (``bool("false")`` is True): use :func:`boolean`.
    default : object
        The value ``run`` gets when the flag is not given (keep it equal to ``run``'s own
        default, so Python and the command line agree).
    help : str
        One line for ``gmuk run NAME --help``, with units.
    choices : sequence, optional
        The allowed values (after parsing).
    """

    name: str
    type: Callable[[str], Any]
    default: Any
    help: str
    choices: tuple[Any, ...] | None = None

    def __post_init__(self) -> None:
        if not (self.name.isidentifier() and not keyword.iskeyword(self.name)):
            raise DefinitionError(f"option name must be a Python identifier; got {self.name!r}")
        if self.type is bool:
            raise DefinitionError(
                f"option {self.name!r}: type=bool would read 'false' as True; "
                "use gmuk.scenarios.boolean"
            )
        if not callable(self.type):
            raise DefinitionError(f"option {self.name!r}: type must be callable; got {self.type!r}")
        if self.choices is not None:
            object.__setattr__(self, "choices", tuple(self.choices))
            if self.default not in self.choices:
                raise DefinitionError(
                    f"option {self.name!r}: default {self.default!r} is not one of the "
                    f"choices {self.choices!r}"
                )

    @property
    def flag(self) -> str:
        """The command-line flag, e.g. ``--thesis-normalization``."""
        return "--" + self.name.replace("_", "-")

    @property
    def help_text(self) -> str:
        """``help`` with the choices and the default appended."""
        text = self.help
        if self.choices is not None:
            text += f" (one of {', '.join(_show(c) for c in self.choices)})"
        return f"{text} (default: {_show(self.default)})"

    def show(self, value: Any) -> str:
        """``value`` as it would be typed after the flag (tuples comma-separated)."""
        return _show(value)

    def parse(self, text: str) -> Any:
        """The value of the command-line text ``text``.

        Raises
        ------
        OptionError
            The text does not parse, or the value is not one of :attr:`choices`; the
            message names the flag and quotes the text.
        """
        try:
            value = self.type(text)
        except (ValueError, TypeError) as exc:
            reason = str(exc)
            if self.type in _WHAT:
                reason = f"must be {_WHAT[self.type]}"
            elif not reason.startswith("must"):
                name = getattr(self.type, "__name__", repr(self.type))
                reason = f"must be a value {name} accepts" + (f" ({reason})" if reason else "")
            raise OptionError(f"{self.flag} {reason}; got {text!r}") from None
        if self.choices is not None and value not in self.choices:
            raise OptionError(
                f"{self.flag} must be one of {', '.join(_show(c) for c in self.choices)}; "
                f"got {text!r}"
            )
        return value


@dataclass(frozen=True)
class Scenario:
    """A runnable scenario: what ``gmuk list`` shows and ``gmuk run NAME`` runs.

    Parameters
    ----------
    name : str
        Lower-case name for ``gmuk run NAME``.
    description : str
        One line for ``gmuk list``.
    run : callable
        ``run(**options) -> ScenarioResult``: takes every declared option as a keyword.
    figures : callable
        ``figures(result, out_dir, formats) -> list[Path]``: writes the figures
        (``formats`` e.g. ``("png", "pdf")``) and returns their paths.
    options : sequence of Option
        The options ``run`` takes from the command line.
    write_data : callable, optional
        ``write_data(result, out_dir) -> list[Path]``: writes further data files beside
        ``trajectory.npz`` and ``summary.json``.
    central_radius : float, optional
        Radius (m) of the central body the scenario's bodies orbit, drawn as a sphere by
        the 3-D views (:mod:`gmuk.view`, ``gmuk view``); None when there is none.
    """

    name: str
    description: str
    run: Callable[..., ScenarioResult]
    figures: FigureFn
    options: tuple[Option, ...] = ()
    write_data: DataFn | None = None
    central_radius: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "options", tuple(self.options))
        problems = []
        if not self.name or self.name != self.name.lower() or any(c.isspace() for c in self.name):
            problems.append(f"name must be lower case without spaces; got {self.name!r}")
        for o in self.options:
            if not isinstance(o, Option):
                problems.append(f"options must be gmuk.scenarios.Option; got {o!r}")
            elif o.name in RESERVED_OPTIONS:
                problems.append(
                    f"option {o.name!r} is reserved for the gmuk run command "
                    f"({', '.join(sorted(RESERVED_OPTIONS))})"
                )
        names = [o.name for o in self.options if isinstance(o, Option)]
        dups = sorted({n for n in names if names.count(n) > 1})
        if dups:
            problems.append(f"options declared twice: {', '.join(dups)}")
        for label in ("run", "figures"):
            if not callable(getattr(self, label)):
                problems.append(f"{label} must be callable")
        if self.write_data is not None and not callable(self.write_data):
            problems.append("write_data must be callable or None")
        r = self.central_radius
        if r is not None and not (isinstance(r, (int, float)) and 0 < r < float("inf")):
            problems.append(f"central_radius must be a finite number > 0 (m) or None; got {r!r}")
        if problems:
            raise DefinitionError([f"scenario {self.name!r}: {p}" for p in problems])

    def option(self, name: str) -> Option:
        """The declared option ``name``."""
        for o in self.options:
            if o.name == name:
                return o
        raise OptionError(
            f"scenario {self.name!r} has no option {name!r}; it takes "
            f"{', '.join(o.name for o in self.options) or 'none'}"
        )

    def parse_options(self, given: Mapping[str, str]) -> dict[str, Any]:
        """Every declared option's value: parsed from ``given`` (option name → text), the
        default for those not given.

        Raises
        ------
        OptionError
            An unknown option name, or a value that does not parse.
        """
        for name in given:
            self.option(name)
        return {
            o.name: o.parse(given[o.name]) if o.name in given else o.default for o in self.options
        }


# --- registry ----------------------------------------------------------------------------------


@functools.cache
def _discover() -> dict[str, tuple[Scenario, str]]:
    """name → (scenario, source): gmuk's first, then plugins'."""
    found: dict[str, tuple[Scenario, str]] = {}
    for name, target in SCENARIOS.items():
        scenario = load_target(target)
        if not isinstance(scenario, Scenario) or scenario.name != name:
            raise DefinitionError(
                f"SCENARIOS[{name!r}] = {target!r} must name a Scenario called {name!r}"
            )
        found[name] = (scenario, "gmuk")

    def rejects(name: str, obj: Any) -> str | None:
        if isinstance(obj, Scenario) and obj.name == name:
            return None
        if isinstance(obj, Scenario):
            return f"it names a Scenario named {obj.name!r}"
        return f"it names {obj!r}, not a gmuk.scenarios.Scenario"

    for name, obj, dist, _ in entry_point_plugins(
        ENTRY_POINT_GROUP,
        "scenario plugin",
        lambda n: found[n][1] if n in found else None,
        rejects,
    ):
        found[name] = (obj, dist)
    return found


def refresh() -> None:
    """Forget the cached discovery (after installing or removing a plugin, or editing
    :data:`SCENARIOS`)."""
    _discover.cache_clear()


def available() -> list[tuple[Scenario, str]]:
    """(scenario, source) of every scenario, gmuk's first in thesis order, then plugins by
    name; source is ``"gmuk"`` or the plugin's distribution name."""
    found = _discover()
    builtin = [found[n] for n in SCENARIOS if n in found]
    plugins = sorted((v for v in found.values() if v[1] != "gmuk"), key=lambda v: v[0].name)
    return [*builtin, *plugins]


def get(name: str) -> Scenario:
    """The scenario called ``name`` (case-insensitive).

    Raises
    ------
    DefinitionError
        No such scenario; the message lists the available ones.
    """
    found = _discover()
    key = name.lower()
    if key not in found:
        names = ", ".join(s.name for s, _ in available())
        raise DefinitionError(f"unknown scenario {name!r}; available: {names}")
    return found[key][0]


def describe() -> list[tuple[str, str]]:
    """(name, one-line description) of every scenario, as :func:`available` orders them."""
    return [(s.name, s.description) for s, _ in available()]
