"""gmuk: geometric-mechanics Udwadia–Kalaba constrained motion of rigid bodies on SE(3).

Implements McCann (2020), *Constrained Motion of Rigid Bodies in the Geometric Mechanics
Framework with Udwadia–Kalaba Formulation* (master's thesis), with the corrections listed
in the documentation's errata page.
"""

from gmuk import errors, lie
from gmuk.dynamics import spatial_inertia

__version__ = "0.1.0"

__all__ = ["__version__", "errors", "lie", "spatial_inertia"]
