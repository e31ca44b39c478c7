"""The forms of a part: what a force model, constraint or controller declares about itself.

A part's physics is written once, as its *numeric* definition: for a built-in model with a
compiled form, a numba kernel beside its class that both its Python methods and the compiled
step loop call. Beside it a part may have a *symbolic* (CasADi) form for
:mod:`gmuk.optimize`. Every part has its Python form (its ``wrench``/``force``, ``rows``,
``control`` …); a built-in class states in its own body which of the other two it has
(:class:`Forms`), and ``tests/test_part_contract.py`` discovers every built-in part and holds
the forms it declares to the same numbers.

A compiled or symbolic form belongs to the class that defines it and to the numeric methods of
that class (:attr:`DeclaresForms._numeric_methods`): a subclass that overrides none of them
inherits the forms; a subclass that overrides one of them (it changed the physics) does not,
until it defines its own (:meth:`DeclaresForms._declared_form`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Literal

__all__ = ["FORMS", "DeclaresForms", "Forms"]

#: The forms beside the Python one that a part class declares.
FORMS = ("compiled", "symbolic")


@dataclass(frozen=True)
class Forms:
    """Which forms a part class has beside its Python methods.

    Each field is ``True`` when the class has that form, or a sentence saying why it has
    none (an empty answer is not accepted: an absent form is declared with its reason).

    Parameters
    ----------
    compiled : True or str
        A compiled form the step loop calls through its address: the kernel of a part's
        ``_compiled_term`` (a force model's or constraint's ``_kernel``, with the signature
        :data:`~gmuk.forces.base.FORCE_KERNEL` or :data:`~gmuk.constraints.base.ROWS_KERNEL`;
        a controller's, :data:`~gmuk.control.base.CONTROL_KERNEL`).
    symbolic : True or str
        A CasADi form for :mod:`gmuk.optimize` (``casadi_force``, ``casadi_wrench``,
        ``casadi_wrenches``, ``casadi_value``, ``casadi_residual``; see
        :mod:`gmuk.optimize.parts`).

    Examples
    --------
    >>> Forms(compiled=True, symbolic="gmuk.optimize transcribes no controller")
    Forms(compiled=True, symbolic='gmuk.optimize transcribes no controller')
    """

    compiled: Literal[True] | str
    symbolic: Literal[True] | str

    def __post_init__(self) -> None:
        for form in FORMS:
            value = getattr(self, form)
            if value is not True and not (isinstance(value, str) and value.strip()):
                raise TypeError(
                    f"Forms.{form} must be True or the reason the part has no {form} form; "
                    f"got {value!r}"
                )

    def has(self, form: str) -> bool:
        """Whether the class has ``form`` ("compiled" or "symbolic")."""
        if form not in FORMS:
            raise ValueError(f"form must be one of {FORMS}; got {form!r}")
        return getattr(self, form) is True


class DeclaresForms:
    """Mixin of the part base classes: the inheritance rule of compiled and symbolic forms."""

    #: The methods that define a part's numbers. A compiled or symbolic form belongs to them:
    #: a subclass that overrides one of them does not inherit the forms of the class above.
    _numeric_methods: ClassVar[tuple[str, ...]] = ()
    #: Which forms the class has (built-in classes declare it in their own body).
    _forms: ClassVar[Forms | None] = None

    def _methods_are(self, cls: type) -> bool:
        """Whether this object's numeric methods (:attr:`_numeric_methods`) are those of
        ``cls`` (a subclass that overrides any of them gets no compiled or symbolic form of
        ``cls``)."""
        t = type(self)
        return all(getattr(t, k, None) is getattr(cls, k, None) for k in self._numeric_methods)

    def _declared_form(self, name: str) -> Any:
        """Attribute ``name`` (a compiled or symbolic form) of this object when the class that
        defines it also defines every numeric method this object has; None when no class
        defines it or when a subclass below that class overrode a numeric method."""
        for klass in type(self).__mro__:
            if name in vars(klass):
                return getattr(self, name) if self._methods_are(klass) else None
        return None

    def _cut_off_form(self, name: str) -> type | None:
        """The class whose form ``name`` this object does not inherit because it overrides a
        numeric method of that class (for error messages); None otherwise."""
        for klass in type(self).__mro__:
            if name in vars(klass):
                return None if self._methods_are(klass) else klass
        return None
