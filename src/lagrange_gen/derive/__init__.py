"""Derivation stage: Model (sympy) -> Dynamics (sympy). No printing happens here."""

from .dynamics import Dynamics, derive

__all__ = ["Dynamics", "derive"]
