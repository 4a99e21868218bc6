"""Errors and warnings raised by mbplanar: every class in one place, each with its CLI exit status.

`ModelError` is bad input (a table that cannot describe a mechanism, a bad argument): exit status 2.
`MotionError` is a mechanism that cannot move as asked (cannot be assembled, locks): exit status 1.
`PlotUnavailable`: a picture was asked for without matplotlib (exit 2). `LongRun`: a request estimated
above 10 minutes, not confirmed (exit 2); `Interrupted`: Ctrl-C (exit 130). Every error carries a message
that names the file (`source`), the row, joint or link (`where`) at fault; ``str(error)`` composes
them once, as "source: where: message". `ModelWarning` flags input that is valid but probably not
what the author meant (a drawn input value far from the sketch, a length that contradicts the
coordinates, a load diagram out of scale); the CLI prints it on stderr.
"""

__all__ = ["MbplanarError", "ModelError", "MotionError", "PlotUnavailable", "LongRun", "Interrupted", "ModelWarning",
           "PrecisionWarning", "closest_names", "did_you_mean"]


class MbplanarError(Exception):
    """Base of every error mbplanar raises on purpose.

    Parameters
    ----------
    message : str
        What is wrong.
    source : str, optional
        The model file (or "<python>", "<table>").
    where : str, optional
        The row, joint, link or argument at fault, e.g. "loads[2] 'cutting'".

    Examples
    --------
    >>> import mbplanar
    >>> try:
    ...     mbplanar.read_model("models/no_such_model.toml")
    ... except mbplanar.MbplanarError as error:      # ModelError and MotionError alike
    ...     print(error)
    models/no_such_model.toml: cannot read the model file (No such file or directory)
    """

    exit_code = 1

    def __init__(self, message: str = "", *, source: str | None = None, where: str | None = None):
        self.message, self.source, self.where = str(message), source, where
        super().__init__(str(self))

    def __str__(self) -> str:
        return ": ".join(p for p in (self.source, self.where, self.message) if p)

    def __reduce__(self):
        return _rebuild, (type(self), self.message, self.source, self.where)


def _rebuild(cls, message, source, where):
    return cls(message, source=source, where=where)


class ModelError(MbplanarError, ValueError):
    """The table, the model or an argument is wrong: unknown names, bad values, wrong DOF, ...

    Examples
    --------
    >>> import mbplanar
    >>> try:
    ...     mbplanar.parse_model({"name": "empty", "ground": "0"}, source="empty.toml")
    ... except mbplanar.ModelError as error:
    ...     print(error.source)
    empty.toml
    """

    exit_code = 2


class MotionError(MbplanarError):
    """The mechanism cannot be assembled or cannot move as asked.

    Examples
    --------
    >>> import numpy as np
    >>> import mbplanar
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/crank_slider_rocker_locking.toml"))
    >>> try:
    ...     mbplanar.position(engine, np.radians(180.0))
    ... except mbplanar.MotionError as error:
    ...     print(str(error).split(":")[1])
     cannot reach t = 3.141592654 rad on the drawn branch
    """

    exit_code = 1


class PlotUnavailable(MbplanarError):
    """A picture was asked for but matplotlib (the `plot` extra) is not installed (exit code 2).

    Attributes
    ----------
    message : str
        What is missing and how to install it (``pip install mbplanar[plot]``).
    source, where : str or None
        The model file and the place in it, when known.

    Examples
    --------
    >>> from mbplanar.errors import ModelError, PlotUnavailable
    >>> issubclass(PlotUnavailable, ModelError), PlotUnavailable.exit_code
    (False, 2)
    """

    exit_code = 2


class LongRun(MbplanarError):
    """A request estimated to run longer than 10 minutes that the user did not agree to (`--yes`): exit
    status 2 (see `mbplanar._progress`)."""

    exit_code = 2


class Interrupted(MbplanarError):
    """The user stopped a long run (Ctrl-C): exit status 130, as a shell reports SIGINT. `partial` holds
    the part of the result done by then (or None)."""

    exit_code = 130

    def __init__(self, message: str = "", *, source=None, where=None, partial=None):
        super().__init__(message, source=source, where=where)
        self.partial = partial


class ModelWarning(UserWarning):
    """Valid input that is probably not what was meant; the message gives the numbers."""


class PrecisionWarning(UserWarning):
    """An answer is given with fewer correct digits than usual (e.g. an input value far out, reduced
    by whole periods of the motion)."""


ALIKE = str.maketrans("01", "ol")  # (lower case)


def closest_names(name, known, count: int = 3) -> list[str]:
    """The names of `known` closest to a misspelt `name` (difflib's similarity ratio at least 0.6, or
    0.5 for a name of up to three characters, where one wrong character halves it; case ignored), best
    first.

    Examples
    --------
    >>> closest_names("S_2", ["A", "B", "S2", "S3"])
    ['S2']
    >>> closest_names("S4", ["A", "B", "S2", "S3"])
    ['S2', 'S3']
    >>> closest_names("0", ["O", "A", "B", "C"])  # a zero for the letter O
    ['O']
    """
    from difflib import SequenceMatcher
    name = str(name).lower()
    cutoff = 0.5 if len(name) <= 3 else 0.6
    by_lower = {}
    for k in known:
        by_lower.setdefault(str(k).lower(), str(k))

    def score(low):  # also with the characters people mistype for each other read alike (0 and O, 1 and l)
        return max(SequenceMatcher(None, name, low).ratio(),
                   SequenceMatcher(None, name.translate(ALIKE), low.translate(ALIKE)).ratio())
    scored = [(score(low), k, by_lower[low]) for k, low in enumerate(by_lower)]
    scored = sorted((s for s in scored if s[0] >= cutoff), key=lambda s: (-s[0], s[1]))
    return [s[2] for s in scored[:count]]


def did_you_mean(name, known, what: str = "names", shown: int = 12) -> str:
    """The end of a message about an unknown `name`: "did you mean 'S2'?" with the closest of `known`
    (`closest_names`), else what `known` holds (its first `shown`), `what` naming them in the plural.

    Examples
    --------
    >>> did_you_mean("S_2", ["A", "B", "S2"], "points")
    "did you mean 'S2'?"
    >>> did_you_mean("Z", ["A", "B"], "points")
    'the points are A, B'
    >>> did_you_mean("Z", [], "prismatic joints")
    'there are no prismatic joints'
    """
    known = list(dict.fromkeys(str(k) for k in known))
    hits = closest_names(name, known)
    if hits:
        return "did you mean " + " or ".join(repr(h) for h in hits) + "?"
    if not known:
        return f"there are no {what}"
    more = f", … ({len(known)} in all)" if len(known) > shown else ""
    return f"the {what} are {', '.join(known[:shown])}{more}"
