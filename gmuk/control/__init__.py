"""Controllers: feedback wrenches on the plant, with internal states."""

from gmuk.control.base import Controller
from gmuk.control.morse_lyapunov import (
    MorseLyapunovController,
    TrackingErrors,
    morse_s,
    morse_s_rate_matrix,
)
from gmuk.control.mrp import MRPFeedback

__all__ = [
    "Controller",
    "MRPFeedback",
    "MorseLyapunovController",
    "TrackingErrors",
    "morse_s",
    "morse_s_rate_matrix",
]
