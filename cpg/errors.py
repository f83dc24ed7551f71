"""Errors raised for bad user input.

Every error a user can cause (unknown gait, NaN weights, wrong shapes, ...) is an
``InputError``: the command-line front end prints its message on one line and exits
non-zero. Anything else escaping the library is a bug.
"""


class InputError(ValueError):
    """Bad input from the user: the message names the problem in one line."""


class NotOscillatingError(InputError):
    """The parameter set produces no rhythm (fixed point or divergence)."""
