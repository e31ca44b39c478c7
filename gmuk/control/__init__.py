"""Controllers: feedback wrenches on the plant, with internal states."""

from gmuk.control.base import Controller

__all__ = ["Controller"]
