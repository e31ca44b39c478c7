"""The engine: everything between the parts and the Trajectory.

* :mod:`gmuk.engine.system`: :class:`~gmuk.System`, which checks the parts once, assembles the
  block-diagonal inertia and the stacked constraint rows A, b across the bodies, and builds its
  compiled program from the parts' declarations;
* :mod:`gmuk.engine.solvers` and :mod:`gmuk.engine.uk`: the Udwadia–Kalaba solve strategies and
  the formula they share (McCann 2020, Eqs. 32 and 80);
* :mod:`gmuk.engine._uk_kernels`: their compiled kernels (free acceleration, fused solve, QR);
* :mod:`gmuk.engine.integrators`: the Runge–Kutta–Munthe-Kaas methods as objects, and
  ``_program`` (the typed program a System hands the loop) and ``_compiled`` (the one loop);
* :mod:`gmuk.engine.integrate`: :func:`~gmuk.engine.integrate.simulate`, which drives that loop.

The parts' physics is not here: each force model, constraint and controller carries its own
kernel beside its class (:mod:`gmuk.forces`, :mod:`gmuk.constraints`, :mod:`gmuk.control`).
Before this package existed these modules lived at ``gmuk.system``, ``gmuk.solvers``,
``gmuk.uk``, ``gmuk.integrate`` and ``gmuk.integrators``; those names still import the same
module objects (:mod:`gmuk` registers them).

The package imports none of its modules itself, so that a part's module can use the engine's
formulas (``gmuk.engine.uk``) without importing the System.
"""
