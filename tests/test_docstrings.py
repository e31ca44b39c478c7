"""Every public name of gmuk has a docstring that gives the units, shapes and frames of its
array arguments.

The rule, precisely (names walked: ``gmuk.__all__`` and, one level down, the ``__all__`` of
each public submodule it lists):

1. Every module, class and function has a docstring of its own (a class's own, not one it
   inherits). Data (``INERTIAL``, ``__version__``) cannot carry one: their type must.
2. An *array argument* is a parameter of a function, or of a class's constructor (for a
   dataclass, a field), whose annotation names an array type (``ndarray``, ``FloatArray``,
   ``ArrayLike``) or whose entry in the numpy-style ``Parameters`` (or ``Attributes``)
   section says ``ndarray`` or ``array_like``. Each array argument must have an entry
   there; the entry must give its shape (a parenthesised shape with a comma such as
   ``(3,)``, ``(N, 6)``, ``(..., 4, 4)`` or the word "shape"; for elementwise functions the
   docstring may say instead that the arguments broadcast); and the docstring must state a
   unit somewhere (an SI unit such as m, s, kg, rad, N, in parentheses or as a word, or
   "dimensionless").
3. An array argument whose entry gives a 3- or 6-vector shape (``(3,)``, ``(N, 6)``,
   ``(..., 3)``) and a unit of a vector in space — position, velocity, acceleration, force
   or torque: (m), (m/s), (m/s²), (rad/s), (rad/s²), (N), (N·m) — needs a frame: its name
   carries one by gmuk's naming convention (``r_N``, ``V_B``, ``R_NB``: an upper-case
   suffix) or its entry says one ("frame", "in N", "in B", "body", "inertial"). Scalars
   such as lengths, gains, weights and matrices have no frame to state.
"""

from __future__ import annotations

import inspect
import re
import types

import numpy as np

import gmuk

ARRAY_ANNOTATION = re.compile(r"ndarray|FloatArray|ArrayLike")
ARRAY_ENTRY = re.compile(r"\b(ndarray|array_like|array-like)\b")
SHAPE = re.compile(r"\(\s*[\w.…+\-*]+(\s*,\s*[\w.…+\-*]*)+\s*\)|\bshape\b")
UNIT = re.compile(
    r"\b(m|s|kg|rad|N|m/s|m/s²|rad/s|rad/s²|N·m|kg·m²|m³/s²|Hz|deg|dimensionless|unitless)\b"
    r"|\((m|s|kg|rad|N)[^)]*\)"
)
#: Units of quantities that are vectors in space: position, velocity, acceleration, force, torque.
SPATIAL_UNIT = re.compile(r"\((?:m|m/s|m/s²|rad/s|rad/s²|N|N·m)(?:\)|,|;| for)")
#: A trailing 3- or 6-vector shape: (3,), (N, 6), (..., 3).
VECTOR_SHAPE = re.compile(r"\((?:[^()]*,\s*)?[36]\s*,?\s*\)")
FRAME_SUFFIX = re.compile(r"_[A-Z]{1,2}(_|$)")
FRAME_WORDS = re.compile(r"frame|\bin [NBFLPd]\b|\bbody\b|inertial|\bworld\b|\bN\b|\bB\b", re.I)


def public_objects():
    """(qualified name, object) of every name walked by the rule."""
    seen: dict[int, str] = {}
    out = []
    for name in gmuk.__all__:
        obj = getattr(gmuk, name)
        out.append((f"gmuk.{name}", obj))
        if isinstance(obj, types.ModuleType):
            for sub in getattr(obj, "__all__", []):
                inner = getattr(obj, sub)
                if id(inner) not in seen and not isinstance(inner, types.ModuleType):
                    seen[id(inner)] = sub
                    out.append((f"{obj.__name__}.{sub}", inner))
    return out


def own_doc(obj) -> str:
    if isinstance(obj, type):
        return obj.__dict__.get("__doc__") or ""
    return getattr(obj, "__doc__", None) or ""


def parameter_entries(doc: str) -> dict[str, str]:
    """name → text of each entry of the numpy-style Parameters section (names that share an
    entry, ``a, b : float``, each get it)."""
    lines = inspect.cleandoc(doc).splitlines()
    entries: dict[str, str] = {}
    in_section = False
    current: list[str] = []
    for k, line in enumerate(lines):
        if line.strip() in ("Parameters", "Other Parameters", "Attributes") and k + 1 < len(lines):
            in_section = lines[k + 1].startswith("---")
            continue
        if not in_section or line.startswith("---"):
            continue
        if (
            line
            and not line.startswith(" ")
            and k + 1 < len(lines)
            and lines[k + 1].startswith("---")
        ):
            in_section = False  # the next section
            continue
        if line and not line.startswith(" "):
            head, _, kind = line.partition(":")
            current = [n.strip().lstrip("*") for n in head.split(",")]
            for n in current:
                entries[n] = kind
        elif current:
            for n in current:
                entries[n] += " " + line.strip()
    return entries


def signature_of(obj):
    try:
        return inspect.signature(obj)
    except (TypeError, ValueError):
        return None


def array_arguments(obj, entries: dict[str, str]) -> list[str]:
    sig = signature_of(obj)
    if sig is None:
        return []
    names = []
    for p in sig.parameters.values():
        if p.name in ("self", "cls") or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        annotation = p.annotation if isinstance(p.annotation, str) else repr(p.annotation)
        entry = entries.get(p.name, "")
        callable_ = annotation.startswith(
            ("Callable", "collections.abc.Callable", "typing.Callable")
        )
        array_annotated = ARRAY_ANNOTATION.search(annotation) and not callable_
        if array_annotated or ARRAY_ENTRY.search(entry.split(".")[0]):
            names.append(p.name)
    return names


def problems_of(name: str, obj) -> list[str]:
    if isinstance(obj, (types.ModuleType, type, types.FunctionType)):
        doc = own_doc(obj)
        if not doc.strip():
            return [f"{name}: no docstring"]
    else:
        if not (type(obj).__doc__ or "").strip():
            return [f"{name}: its type {type(obj).__name__} has no docstring"]
        return []
    if isinstance(obj, types.ModuleType) or not callable(obj):
        return []
    entries = parameter_entries(doc)
    arrays = array_arguments(obj, entries)
    out = []
    for arg in arrays:
        entry = entries.get(arg)
        if entry is None:
            out.append(f"{name}: array argument {arg!r} has no entry under Parameters")
            continue
        if not (SHAPE.search(entry) or "broadcast" in doc.lower()):
            out.append(f"{name}: array argument {arg!r}: no shape in {entry.strip()!r}")
        if (
            VECTOR_SHAPE.search(entry)
            and SPATIAL_UNIT.search(entry)
            and not (FRAME_SUFFIX.search(arg) or FRAME_WORDS.search(entry))
        ):
            out.append(f"{name}: vector argument {arg!r}: no frame in {entry.strip()!r}")
    if arrays and not UNIT.search(doc):
        out.append(f"{name}: array arguments {arrays} but no unit anywhere in the docstring")
    return out


def test_every_public_name_documents_units_shapes_and_frames():
    problems = [p for name, obj in public_objects() for p in problems_of(name, obj)]
    assert not problems, f"{len(problems)} problem(s):\n" + "\n".join(problems)


def test_the_rule_catches_what_it_should():
    def bare(x):
        pass

    def no_shape(r: np.ndarray):
        """Parameters
        ----------
        r : ndarray
            A position (m) in N.
        """

    def no_frame(w):
        """Parameters
        ----------
        w : ndarray (3,)
            Angular velocity (rad/s).
        """

    def gain(k):
        """Parameters
        ----------
        k : array_like (3,)
            Diagonal gains (1/s): no frame needed.
        """

    def no_unit(x_N):
        """Parameters
        ----------
        x_N : array_like (3,)
            A vector.
        """

    def good(r_N, q):
        """Parameters
        ----------
        r_N : array_like (..., 3)
            Positions (m).
        q : ndarray (4,)
            A quaternion (dimensionless).
        """

    assert problems_of("bare", bare) == ["bare: no docstring"]
    assert "no shape" in problems_of("no_shape", no_shape)[0]
    assert "no frame" in problems_of("no_frame", no_frame)[0]
    assert "no unit" in problems_of("no_unit", no_unit)[0]
    assert problems_of("good", good) == []
    assert problems_of("gain", gain) == []
