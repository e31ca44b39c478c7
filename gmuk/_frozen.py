"""Parts that become read-only once handed to a System."""

from __future__ import annotations

from typing import Any


class FreezesInSystem:
    """Mixin: attributes can be set until the System calls :meth:`_freeze`, never after.

    Subclasses provide ``name``; ``_frozen`` starts False (set it in ``__init__`` with
    ``object.__setattr__`` or let it default).
    """

    _frozen: bool = False
    name: Any

    def _freeze(self) -> None:
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, key: str, value: Any) -> None:
        if self._frozen:
            raise AttributeError(
                f"{self.name} is frozen: it belongs to a System; build a new one instead"
            )
        object.__setattr__(self, key, value)
