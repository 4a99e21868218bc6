"""Errors raised by mbplanar.

`ModelError` is bad input (a table that cannot describe a mechanism): the CLI exits with status 2.
`MotionError` is a mechanism that cannot move as asked (cannot be assembled, locks): exit status 1.
Both carry a message that names the file, row, joint or link at fault.
"""

__all__ = ["MbplanarError", "ModelError", "MotionError", "PrecisionWarning"]


class MbplanarError(Exception):
    """Base of every error mbplanar raises on purpose."""

    exit_code = 1


class ModelError(MbplanarError, ValueError):
    """The table or the model is wrong: unknown names, bad values, wrong DOF, ..."""

    exit_code = 2


class MotionError(MbplanarError):
    """The mechanism cannot be assembled or cannot move as asked."""

    exit_code = 1


class PrecisionWarning(UserWarning):
    """An answer is given with fewer correct digits than usual (e.g. an input value far out, reduced
    by whole periods of the motion)."""
