"""Report how many inputs each fuzzed entry point received (issue #15) and the calls that
overran the wall-clock guard (issue #25)."""

from __future__ import annotations


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    from fuzz_inputs import COUNTS, FAILURE_COUNTS, FAILURES, HANG_S, HANGS

    if not COUNTS:
        return
    terminalreporter.write_sep("-", "fuzz: inputs per entry point")
    for entry, n in sorted(COUNTS.items()):
        terminalreporter.write_line(f"{entry:<40} {n:>7}")
    terminalreporter.write_line(f"{'total':<40} {sum(COUNTS.values()):>7}")
    hung = ", ".join(f"{entry} ({n})" for entry, n in sorted(HANGS.items())) or "none"
    terminalreporter.write_line(f"hangs (calls over {HANG_S:g} s): {hung}")
    if not FAILURE_COUNTS:
        return
    terminalreporter.write_sep("-", "fuzz: failing examples by check and class")
    for (check, kind), n in sorted(FAILURE_COUNTS.items()):
        terminalreporter.write_line(f"{check:<40} {kind:<14} {n:>6}")
        for value, message in FAILURES[(check, kind)]:
            terminalreporter.write_line(f"    {message}")
            terminalreporter.write_line(f"      input: {value}")
    by_kind: dict[str, int] = {}
    for (_, kind), n in FAILURE_COUNTS.items():
        by_kind[kind] = by_kind.get(kind, 0) + n
    terminalreporter.write_line(
        "total: " + ", ".join(f"{k} {n}" for k, n in sorted(by_kind.items()))
    )
