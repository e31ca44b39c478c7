"""The docs' result figures are the code's (issue #26, item 5; the registry and its rules are
in tests/docs_figures.py).

* every registered text is printed in its doc (all entries, fast);
* every source is rerun once per session and each text equals what it renders now (one test
  per run; runs over :data:`docs_figures.SLOW_S` seconds are marked slow);
* the coverage guard: every result-like number of the guarded pages is registered, allowed
  or a timing.
"""

from __future__ import annotations

import functools
import re
import string
from typing import Any

import pytest
from docs_figures import (
    ALLOWED,
    DERIVED,
    FIGURES,
    GUARDED,
    NOT_YET_GUARDED,
    ROOT,
    RUNS,
    TIMINGS,
    UNREGENERATED,
    WINDOW,
    bound_of,
    render,
    result_like_numbers,
    summary_keys,
)


@functools.cache
def _lines(doc: str) -> tuple[str, ...]:
    return tuple((ROOT / doc).read_text(encoding="utf-8").splitlines())


def _where(doc: str, text: str, near: str = "") -> list[int]:
    """Line indices of ``doc`` where ``text`` is printed, with ``near`` on that line or up to
    WINDOW lines before it."""
    lines = _lines(doc)
    out = []
    for i, line in enumerate(lines):
        if text in line and (
            not near or any(near in lines[j] for j in range(max(0, i - WINDOW), i + 1))
        ):
            out.append(i)
    return out


@functools.cache
def _source(name: str) -> tuple[dict[str, Any], Any]:
    """(summary, ScenarioResult or None) of one run, computed once per session."""
    run = RUNS[name]
    if run.function is not None:
        return run.function(), None
    import gmuk.scenarios

    scenario = gmuk.scenarios.get(run.scenario)
    result = scenario.run(**scenario.parse_options(run.options))
    return result.summary, result


def _value(summary: dict[str, Any], result: Any, key: str) -> float:
    """The figure ``key`` names: a summary key ("/" into nested blocks), "fn:NAME[:ARG]" a
    derived figure, either with "*FACTOR" appended (e.g. "*100" for a percentage)."""
    key, _, factor = key.partition("*")
    value = _raw_value(summary, result, key)
    return value * float(factor) if factor else value


def _raw_value(summary: dict[str, Any], result: Any, key: str) -> float:
    if key.startswith("fn:"):
        name, _, arg = key[3:].partition(":")
        return DERIVED[name](result, arg)
    if key in summary:  # flat keys may contain "/" (the script tables')
        return summary[key]
    value: Any = summary
    for part in key.split("/"):
        value = value[part]
    return value


def test_the_registry_is_well_formed():
    problems = []
    seen = set()
    for f in FIGURES:
        fields = [x for x in string.Formatter().parse(f.fmt) if x[1] is not None]
        if f.run not in RUNS:
            problems.append(f"{f.text!r}: unknown run {f.run!r}")
        if len(fields) != 1:
            problems.append(f"{f.text!r}: fmt {f.fmt!r} must have exactly one field")
        if f.kind not in ("equal", "below"):
            problems.append(f"{f.text!r}: kind {f.kind!r}")
        if f.key.startswith("fn:") and f.key[3:].partition(":")[0] not in DERIVED:
            problems.append(f"{f.text!r}: no derived figure {f.key!r}")
        if "\n" in f.text:
            problems.append(f"{f.text!r}: one line only")
        if (f.doc, f.text, f.near, f.run, f.key) in seen:
            problems.append(f"{f.text!r} registered twice in {f.doc}")
        seen.add((f.doc, f.text, f.near, f.run, f.key))
    assert not problems, "\n".join(problems)


def test_every_registered_text_is_in_its_doc():
    missing = [
        f"{f.doc}: {f.text!r}" + (f" (within {WINDOW} lines after {f.near!r})" if f.near else "")
        for f in FIGURES
        if not _where(f.doc, f.text, f.near)
    ]
    missing += [
        f"{d}: {t!r} ({why})" for d, t, why in ALLOWED + TIMINGS + UNREGENERATED if not _where(d, t)
    ]
    assert not missing, "registered but not printed:\n" + "\n".join(missing)


def _params() -> list[Any]:
    used = sorted({f.run for f in FIGURES})
    return [
        pytest.param(name, marks=[pytest.mark.slow] if RUNS[name].slow else [], id=name)
        for name in used
    ]


@pytest.mark.parametrize("run_name", _params())
def test_the_printed_figures_are_the_codes(run_name):
    summary, result = _source(run_name)
    wrong = []
    for f in (f for f in FIGURES if f.run == run_name):
        value = _value(summary, result, f.key)
        if f.kind == "below":
            bound = bound_of(f.text)
            shown = render(bound, f.fmt)
            if shown != f.text or not abs(value - (f.offset or 0.0)) < bound:
                wrong.append(f"{f.doc}: {f.text!r} but {f.key} = {value!r} (bound {shown!r})")
        else:
            shown = render(value, f.fmt, f.offset)
            if shown != f.text:
                wrong.append(f"{f.doc}: prints {f.text!r}, {f.key} gives {shown!r} ({value!r})")
    assert not wrong, f"{RUNS[run_name]}:\n" + "\n".join(wrong)


def test_every_result_like_number_is_registered():
    """The coverage guard (docs_figures.result_like_numbers): a number that looks like a
    result on a guarded page must lie, character by character, within registered figures,
    allowed constants, timings or unregenerated history printed on that line."""
    keys = summary_keys()
    covered: dict[tuple[str, int], set[int]] = {}  # (doc, line) → covered columns
    texts = [(f.doc, f.text, f.near) for f in FIGURES]
    texts += [(d, t, "") for d, t, _ in ALLOWED + TIMINGS + UNREGENERATED]
    for doc, text, near in texts:
        for i in _where(doc, text, near):
            for m in re.finditer(re.escape(text), _lines(doc)[i]):
                covered.setdefault((doc, i), set()).update(range(m.start(), m.end()))
    loose = []
    for doc in GUARDED:
        lines = _lines(doc)
        for i, start, number in result_like_numbers(doc, keys):
            columns = covered.get((doc, i), set())
            if not all(start + k in columns for k, c in enumerate(number) if not c.isspace()):
                loose.append(f"{doc}:{i + 1}: {number!r}   | {lines[i].strip()[:90]}")
    assert not loose, (
        "result-like numbers that no registered figure covers (register them in "
        "tests/docs_figures.py, or list a non-result in ALLOWED):\n" + "\n".join(loose)
    )


def test_the_guard_skips_only_the_listed_pages():
    """Every page it skips exists and has result-like numbers (else it should be guarded)."""
    keys = summary_keys()
    stale = [
        doc
        for doc in NOT_YET_GUARDED
        if not (ROOT / doc).exists() or not result_like_numbers(doc, keys)
    ]
    assert not stale, f"guard these pages (remove them from NOT_YET_GUARDED): {stale}"
