"""Nonsmooth elements: the Saint-Venant return map and the play operator (the lecture's experiments
are analysis/nonsmooth_experiments.py).

The model elements themselves (SaintVenant, DryFriction) are declared in lagrange_gen.model; the
time stepper that treats them is steppers/methods/nonsmooth_euler.py.
"""

from .play import loop_area, play_operator, return_map

__all__ = ["return_map", "play_operator", "loop_area"]
