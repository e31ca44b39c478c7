"""Runge–Kutta methods for :func:`gmuk.engine.integrate.simulate`, as objects.

Each method is a subclass of :class:`RungeKuttaMethod` that owns its Butcher tableau
(A, b, c, order, embedded error weights E, FSAL flag) and its method-specific behaviour:
the error norm, whether it is adaptive, whether it has a continuous extension (and how its
error is checked) or steps exactly onto output times. The integrator asks the method object
and has no special case for any method.

Built-in methods
----------------
:class:`DOP853` (default)
    Dormand–Prince 8(5,3), adaptive, continuous extension of order 7 whose error is
    controlled too.
:class:`DOPRI5`
    Dormand–Prince 5(4), adaptive, steps onto output times.
:class:`RK4`
    Classical Runge–Kutta of order 4, fixed step.

Adding a method
---------------
Subclass :class:`RungeKuttaMethod` with the tableau and a ``name``: the class registers
itself, and ``simulate(..., method="name")`` accepts it (names are case-insensitive). A
method shipped with gmuk goes in its own module of this package, imported below.
"""

from gmuk.engine.integrators._base import METHODS, RungeKuttaMethod, get_method, method_names
from gmuk.engine.integrators.dop853 import DOP853
from gmuk.engine.integrators.dopri5 import DOPRI5
from gmuk.engine.integrators.rk4 import RK4

__all__ = [
    "DOP853",
    "DOPRI5",
    "METHODS",
    "RK4",
    "RungeKuttaMethod",
    "get_method",
    "method_names",
]
