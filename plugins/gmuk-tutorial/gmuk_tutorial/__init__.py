"""gmuk's tutorial plugin: the ``linear_drag`` force model and the ``tennis-racket`` scenario.

Both are registered by entry points in this package's ``pyproject.toml``; gmuk finds them by
name once the package is installed (``gmuk plugins``, ``gmuk list``).
"""

from gmuk_tutorial.drag import LinearDrag

__all__ = ["LinearDrag"]
