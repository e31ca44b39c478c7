"""gmuk.check() / ``gmuk check``: passes on this install, fails visibly on a perturbed operator."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import gmuk.dynamics
from gmuk import cli
from gmuk.crosscheck import CheckReport, _swap_op, _swap_vec, check
from gmuk.errors import DefinitionError
from gmuk.lie import se3

QUANTITIES = [
    "so3.hat",
    "so3.exp",
    "so3.log",
    "se3.hat",
    "se3.vee",
    "se3.exp",
    "se3.log",
    "se3.inverse",
    "se3.Ad",
    "se3.ad",
    "se3.ad_star",
    "se3.ad applied",
    "se3.dexp",
    "se3.dexp_inv",
    "free_acceleration (Eq. 10b)",
    "System UK acceleration (Eq. 64)",
    "System UK multipliers (Eq. 3)",
]


@pytest.fixture(scope="module")
def report() -> CheckReport:
    return check(seed=0, n=200)


def test_every_quantity_agrees_with_pinocchio(report):
    assert [r.quantity for r in report.rows] == QUANTITIES
    assert report.ok and not report.failed, str(report)
    for row in report.rows:
        assert 0.0 <= row.error <= row.tolerance <= 1e-10
        assert row.samples == (20 if row.quantity.startswith("System") else 200)
    assert report.pinocchio_version == pin.__version__


def test_the_table_names_every_row_and_the_verdict(report):
    text = str(report)
    for quantity in QUANTITIES:
        line = next(ln for ln in text.splitlines() if ln.startswith(quantity + " "))
        assert line.endswith("pass")
    assert "all 17 quantities agree with Pinocchio" in text
    assert f"seed 0, 200 samples per quantity ({report.elapsed_s:.2f} s)" in text


def test_gmuk_check_command_passes(capsys):
    assert cli.main(["check", "--samples", "50", "--seed", "3"]) == 0
    out = capsys.readouterr().out
    assert "seed 3, 50 samples per quantity" in out and "FAIL" not in out


def test_a_perturbed_Ad_fails_visibly(monkeypatch, capsys):
    """Ad off by 1e-9 in one entry: the check exits 1 and names that row, only that row."""
    exact = se3.Ad

    def slightly_wrong(g):
        out = exact(g).copy()
        out[..., 4, 1] += 1e-9
        return out

    monkeypatch.setattr(se3, "Ad", slightly_wrong)
    assert cli.main(["check", "--samples", "30"]) == 1
    lines = capsys.readouterr().out.splitlines()
    failing = [ln for ln in lines if ln.endswith("FAIL")]
    assert len(failing) == 1 and failing[0].startswith("se3.Ad ")
    assert "1.00e-09" in failing[0]
    assert lines[-1] == "1 of 17 quantities FAIL: se3.Ad"


def test_a_perturbed_free_acceleration_fails(monkeypatch):
    """The dynamics rows catch a dropped gyroscopic term (Eq. 10b without ad*_V 𝕀V)."""
    monkeypatch.setattr(
        gmuk.dynamics,
        "free_acceleration",
        lambda V, inertia, wrench: np.linalg.solve(inertia, wrench),
    )
    report = check(n=20)
    assert [r.quantity for r in report.failed] == ["free_acceleration (Eq. 10b)"]
    assert report.failed[0].error > 1e-3


def test_an_operator_that_raises_is_a_failed_row_not_a_crash(monkeypatch):
    def broken(xi):
        raise RuntimeError("kernel missing")

    monkeypatch.setattr(se3, "dexp", broken)
    report = check(n=10)
    (row,) = report.failed
    assert row.quantity == "se3.dexp" and math.isinf(row.error)
    assert row.note == "RuntimeError: kernel missing"
    assert "FAIL (RuntimeError: kernel missing)" in str(report)


def test_check_is_reproducible_and_rejects_bad_arguments():
    a, b = check(seed=5, n=10), check(seed=5, n=10)
    assert [r.error for r in a.rows] == [r.error for r in b.rows]
    for kwargs in ({"n": 0}, {"n": 2.5}, {"seed": -1}, {"n": True}):
        with pytest.raises(DefinitionError, match="must be an integer"):
            check(**kwargs)


def test_the_ordering_helper_maps_gmuk_twists_to_pinocchio_motions():
    rng = np.random.default_rng(0)
    V = rng.normal(size=6)  # gmuk [ω; v]
    motion = pin.Motion(_swap_vec(V))
    assert np.array_equal(motion.angular, V[:3]) and np.array_equal(motion.linear, V[3:])
    assert np.array_equal(_swap_vec(_swap_vec(V)), V)
    A = rng.normal(size=(6, 6))
    np.testing.assert_allclose(_swap_op(A) @ _swap_vec(V), _swap_vec(A @ V), rtol=0, atol=1e-14)
