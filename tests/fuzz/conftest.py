"""Report how many inputs each fuzzed entry point received (issue #15)."""

from __future__ import annotations


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    from fuzz_inputs import COUNTS

    if not COUNTS:
        return
    terminalreporter.write_sep("-", "fuzz: inputs per entry point")
    for entry, n in sorted(COUNTS.items()):
        terminalreporter.write_line(f"{entry:<32} {n:>7}")
    terminalreporter.write_line(f"{'total':<32} {sum(COUNTS.values()):>7}")
