"""The keywords of a constraint's base class (``name``, ``baumgarte``, ``fd_length``,
``fd_time``, ``derivatives``; :data:`gmuk.constraints.base.BASE_KEYWORDS`) reach it whether
or not a user subclass's ``__init__`` forwards them (issue #26, item 6):
``Distance(..., baumgarte=...)`` with the quickstart's own ``Distance`` class, exactly as
docs/quickstart.rst writes it.
"""

from __future__ import annotations

import inspect
import pickle
import re
from pathlib import Path

import numpy as np
import pytest
from helpers import Rows, ScrewReference, random_rigid_bodies, random_state

import gmuk
from gmuk.errors import ConstraintError, DefinitionError

QUICKSTART = Path(__file__).resolve().parents[2] / "docs" / "quickstart.rst"


def python_blocks(text: str) -> list[str]:
    """The ``.. code-block:: python`` blocks of a reStructuredText page, dedented."""
    out = []
    for match in re.finditer(r"^\.\. code-block:: python\n\n((?:(?: {3}.*)?\n)+)", text, re.M):
        out.append(re.sub(r"^ {3}", "", match.group(1), flags=re.M))
    return out


def quickstart_class(name: str) -> type:
    """The class ``name`` as docs/quickstart.rst defines it (its block holds the class only)."""
    (block,) = [b for b in python_blocks(QUICKSTART.read_text()) if f"class {name}(" in b]
    namespace: dict = {"np": np, "gmuk": gmuk}
    exec(compile(block, str(QUICKSTART), "exec"), namespace)
    return namespace[name]


Distance = quickstart_class("Distance")
Distance.__module__ = __name__  # pickled by reference, as a user's module-level class is
Distance.__qualname__ = "Distance"


class ForwardingDistance(Distance):
    """A subclass that names and forwards ``baumgarte`` and ``name`` itself."""

    def __init__(self, a, b, d, *, baumgarte=None, name=None):
        super().__init__(a, b, np.zeros(3), np.zeros(3), d, baumgarte=baumgarte, name=name)


class ReadsItsGains(Distance):
    """Reads ``self.baumgarte`` in its ``__init__`` right after ``super().__init__``."""

    def __init__(self, a, b):
        super().__init__(a, b, np.zeros(3), np.zeros(3), 1.0)
        self.seen = self.baumgarte


class SetsItsOwnGains(Distance):
    """Sets ``baumgarte`` in its own ``super().__init__`` call, without naming it."""

    GAINS = gmuk.Baumgarte.critical(3.0)

    def __init__(self, a, b):
        gmuk.HolonomicConstraint.__init__(self, [a, b], baumgarte=self.GAINS)
        self.p_a = self.p_b = np.zeros(3)
        self.d = 1.0


def two_bodies(seed=3):
    rng = np.random.default_rng(seed)
    a, b = random_rigid_bodies(rng, 2)
    return rng, a, b


def rows_at(con, state):
    return tuple(np.asarray(x) for x in con.rows(state))


GAINS = gmuk.Baumgarte(alpha=4.0, beta=7.0)


def test_the_quickstart_distance_takes_the_keywords_it_does_not_forward():
    rng, a, b = two_bodies()
    p = np.array([0.1, -0.2, 0.3])
    plain = Distance(a, b, p, -p, 1.5)
    stab = Distance(a, b, p, -p, 1.5, baumgarte=GAINS, name="rod", fd_length=2.0, fd_time=3.0)
    assert plain.baumgarte is None and plain.name == "Distance"
    assert stab.baumgarte is GAINS and stab.name == "rod"
    assert (stab.fd_length, stab.fd_time) == (2.0, 3.0)
    assert "_held_keywords" not in vars(stab)  # nothing of the mechanism stays behind
    # the gains act as Eq. 4 says: b − α φ̇ − β φ, once
    state = random_state(gmuk.System([a, b], [stab]), rng)  # off the constraint
    q = (state.pose(a), state.pose(b))
    nu = (state.twist(a), state.twist(b))
    phi, rate = stab.residual(q, state.t), stab.rate(q, nu, state.t)
    assert abs(phi[0]) > 0.1 and abs(rate[0]) > 0.1
    A0, b0 = rows_at(Distance(a, b, p, -p, 1.5, fd_length=2.0, fd_time=3.0), state)
    A1, b1 = rows_at(stab, state)
    assert np.array_equal(A0, A1)
    assert np.allclose(b1, b0 - 4.0 * rate - 7.0 * phi, rtol=1e-12, atol=1e-12)
    assert not np.allclose(b1, b0 - 8.0 * rate - 14.0 * phi)


def test_the_quickstart_distance_takes_the_derivatives_keyword_it_does_not_forward():
    """``derivatives="fd"`` reaches the residual kind: its rows are the finite differences',
    which differ from the exact (jet) rows by their truncation error, and no more."""
    rng, a, b = two_bodies()
    p = np.array([0.1, -0.2, 0.3])
    exact, fd = Distance(a, b, p, -p, 1.5), Distance(a, b, p, -p, 1.5, derivatives="fd")
    assert (exact.derivatives, fd.derivatives) == ("jets", "fd")
    state = random_state(gmuk.System([a, b], [exact]), rng)
    (A0, b0), (A1, b1) = rows_at(exact, state), rows_at(fd, state)
    assert not np.array_equal(b0, b1)  # another method ...
    np.testing.assert_allclose(A1, A0, rtol=1e-7, atol=1e-7)  # ... for the same rows
    np.testing.assert_allclose(b1, b0, rtol=1e-6, atol=1e-6)
    with pytest.raises(ConstraintError, match="derivatives must be 'jets' or 'fd'"):
        Distance(a, b, p, -p, 1.5, derivatives="symbolic")


def test_a_subclass_that_forwards_the_keywords_gets_them_once():
    rng, a, b = two_bodies()
    fwd = ForwardingDistance(a, b, 1.0, baumgarte=GAINS, name="fwd")
    assert fwd.baumgarte is GAINS and fwd.name == "fwd"
    assert "_held_keywords" not in vars(fwd)
    ref = Distance(a, b, np.zeros(3), np.zeros(3), 1.0, baumgarte=GAINS)
    state = random_state(gmuk.System([a, b], [fwd]), rng)
    assert all(
        np.array_equal(x, y) for x, y in zip(rows_at(fwd, state), rows_at(ref, state), strict=True)
    )
    # what it does not name (fd_length) reaches the base class through it
    assert ForwardingDistance(a, b, 1.0, fd_length=5.0).fd_length == 5.0
    assert ForwardingDistance(a, b, 1.0).baumgarte is None


def test_the_keywords_are_there_when_super_init_returns():
    _, a, b = two_bodies()
    assert ReadsItsGains(a, b, baumgarte=GAINS).seen is GAINS
    assert ReadsItsGains(a, b).seen is None


def test_a_keyword_the_subclass_sets_itself_is_not_overridden_silently():
    _, a, b = two_bodies()
    assert SetsItsOwnGains(a, b).baumgarte is SetsItsOwnGains.GAINS
    assert SetsItsOwnGains(a, b, baumgarte=SetsItsOwnGains.GAINS).baumgarte is SetsItsOwnGains.GAINS
    with pytest.raises(DefinitionError, match=r"SetsItsOwnGains sets baumgarte=.* given"):
        SetsItsOwnGains(a, b, baumgarte=GAINS)


def test_help_and_ides_see_the_keywords():
    params = inspect.signature(Distance).parameters
    assert list(params) == [
        "a",
        "b",
        "p_a",
        "p_b",
        "d",
        "name",
        "baumgarte",
        "fd_length",
        "fd_time",
        "derivatives",
    ]
    assert all(params[k].kind is inspect.Parameter.KEYWORD_ONLY for k in list(params)[5:])
    assert params["fd_length"].default == 1.0 and params["baumgarte"].default is None
    assert list(inspect.signature(ForwardingDistance).parameters) == [
        "a", "b", "d", "baumgarte", "name", "fd_length", "fd_time", "derivatives",
    ]  # fmt: skip
    assert list(inspect.signature(Rows).parameters) == ["bodies", "A", "b", "name"]


def test_pickling_repr_and_freezing_keep_working():
    _, a, b = two_bodies()
    con = Distance("b0", "b1", np.zeros(3), np.zeros(3), 1.0, baumgarte=GAINS, name="rod")
    assert repr(con) == "Distance(bodies=['b0', 'b1'], name='rod')"
    back = pickle.loads(pickle.dumps(con))
    assert type(back) is Distance and back.name == "rod"
    assert np.array_equal(back.baumgarte.alpha, GAINS.alpha)
    assert np.array_equal(back.baumgarte.beta, GAINS.beta)
    gmuk.System([a, b], [con])
    with pytest.raises(AttributeError, match="frozen"):
        con.baumgarte = None


def test_the_gains_are_checked_as_before():
    _, a, b = two_bodies()
    with pytest.raises(DefinitionError, match="Baumgarte beta must be a finite"):
        Distance(a, b, np.zeros(3), np.zeros(3), 1.0, baumgarte=gmuk.Baumgarte(1.0, -1.0))
    with pytest.raises(DefinitionError, match=r"baumgarte of Distance must be a gmuk\.Baumgarte"):
        Distance(a, b, np.zeros(3), np.zeros(3), 1.0, baumgarte=(1.0, 2.0))
    with pytest.raises(gmuk.errors.ConstraintError, match="fd_length and fd_time must be > 0"):
        Distance(a, b, np.zeros(3), np.zeros(3), 1.0, fd_length=0.0)


def test_a_kind_that_gives_its_rows_refuses_baumgarte_and_names_those_that_take_it():
    with pytest.raises(
        DefinitionError, match=r"Rows takes no baumgarte=.*gmuk\.HolonomicConstraint"
    ):
        Rows(["a"], np.eye(6)[:3], np.zeros(3), baumgarte=GAINS)
    with pytest.raises(DefinitionError, match="Rows takes no fd_length=: a Constraint has no"):
        Rows(["a"], np.eye(6)[:3], np.zeros(3), fd_length=2.0)
    assert Rows(["a"], np.eye(6)[:3], np.zeros(3), name="lock").name == "lock"

    class Tangent(gmuk.TangentBundleConstraint):
        def __init__(self, body):
            super().__init__([body])

        def tangent_rows(self, state):
            return np.eye(4), np.eye(4), np.zeros((4, 4))

    with pytest.raises(DefinitionError, match="a TangentBundleConstraint gives its rows itself"):
        Tangent("a", baumgarte=GAINS)
    # unknown keywords stay Python's TypeError
    with pytest.raises(TypeError, match="unexpected keyword argument 'gains'"):
        Rows(["a"], np.eye(6)[:3], np.zeros(3), gains=GAINS)


def test_a_subclass_that_never_calls_super_init_says_so():
    class Forgetful(gmuk.HolonomicConstraint):
        def __init__(self, bodies):
            object.__setattr__(self, "_bodies", tuple(bodies))

        def residual(self, q, t):
            return np.zeros(1)

    assert Forgetful(["a"]).bodies == ("a",)
    with pytest.raises(DefinitionError, match="did not call super"):
        Forgetful(["a"], baumgarte=GAINS)


def test_an_inequality_subclass_names_its_slack_coordinates_by_the_name_it_was_given():
    class Floor(gmuk.InequalityConstraint):
        def __init__(self, body):
            super().__init__([body], lower=0.0, unit="m")

        def value(self, q, nu, t):
            return q[0][2]

    floor = Floor("p", name="floor", baumgarte=GAINS, fd_length=10.0)
    assert floor.name == "floor" and floor.baumgarte is GAINS and floor.fd_length == 10.0
    assert [c.name for c in floor.owned_bodies] == ["floor.lower"]


def _screw():
    return ScrewReference(np.eye(4), np.array([0.01, 0.02, -0.03, 1.0, 0.0, 0.5]))


class SubRelative(gmuk.RelativeConstraint):
    def __init__(self, a, b):
        super().__init__(b, a, free_axes=[0])


class SubTracking(gmuk.ConfigurationTracking):
    def __init__(self, a, b):
        super().__init__(a, _screw())


class SubTrackingT2(gmuk.ConfigurationTrackingT2):
    def __init__(self, a, b):
        super().__init__(a, _screw())


class SubPairT2(gmuk.VirtualPairT2):
    def __init__(self, a, b):
        super().__init__(b, a, _screw())


class SideSlip(gmuk.NonholonomicConstraint):
    """v_y = 0 in the body frame of the first body; names and forwards baumgarte."""

    def __init__(self, a, b, baumgarte=None):
        super().__init__([a, b], baumgarte=baumgarte)

    def residual(self, q, nu, t):
        return np.array([nu[0][4]])


class SubSideSlip(SideSlip):
    def __init__(self, a, b):
        super().__init__(a, b)


#: Each of gmuk's kinds that applies baumgarte: the kind given the gains directly, and a user
#: subclass whose __init__ does not take them.
KINDS = {
    "RelativeConstraint": (
        lambda a, b, **kw: gmuk.RelativeConstraint(b, a, free_axes=[0], **kw),
        SubRelative,
    ),
    "ConfigurationTracking": (
        lambda a, b, **kw: gmuk.ConfigurationTracking(a, _screw(), **kw),
        SubTracking,
    ),
    "ConfigurationTrackingT2": (
        lambda a, b, **kw: gmuk.ConfigurationTrackingT2(a, _screw(), **kw),
        SubTrackingT2,
    ),
    "VirtualPairT2": (lambda a, b, **kw: gmuk.VirtualPairT2(b, a, _screw(), **kw), SubPairT2),
    "NonholonomicConstraint": (SideSlip, SubSideSlip),
}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_kind_that_applies_gains_takes_them_from_a_subclass_that_does_not_forward_them(kind):
    rng, a, b = two_bodies(11)
    direct_of, Sub = KINDS[kind]
    gains = gmuk.Baumgarte(alpha=0.7, beta=0.2) if "T2" in kind else GAINS
    plain, direct, sub = (
        direct_of(a, b),
        direct_of(a, b, baumgarte=gains),
        Sub(a, b, baumgarte=gains, name="sub"),
    )
    assert sub.baumgarte is gains and sub.name == "sub" and Sub(a, b).baumgarte is None
    state = random_state(gmuk.System([a, b], [direct]), rng)
    _, b0 = rows_at(plain, state)
    A1, b1 = rows_at(direct, state)
    A2, b2 = rows_at(sub, state)
    assert not np.allclose(b0, b1)  # the gains change the rows at this state
    assert np.array_equal(A1, A2) and np.array_equal(b1, b2)
