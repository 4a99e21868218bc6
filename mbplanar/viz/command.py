"""The picture commands' work: `mbplanar plot`, `animate` and `report`.

Each checks its arguments first (the output's type, the picture's name, matplotlib where it draws), then
asks `load()` for the model's engine (so that a wrong argument is named before the model is read) and
writes the file. The command line (`mbplanar.cli`) parses the arguments and passes its loader; the
report's sections of the packages above this one are registered there.
"""

from __future__ import annotations

import sys

from ..errors import ModelError

__all__ = ["plot", "animate", "report", "output_kind"]


def output_kind(path, allowed) -> str:
    """The output's type from its suffix, one of `allowed`.

    Parameters
    ----------
    path : str or os.PathLike
        The output file.
    allowed : tuple of str
        The suffixes (lower case, without the dot) the command writes.

    Returns
    -------
    str
        The suffix, lower case.

    Raises
    ------
    ModelError
        A suffix not in `allowed`.

    Examples
    --------
    >>> from mbplanar.viz.command import output_kind
    >>> output_kind("cycle.GIF", ("gif", "html"))
    'gif'
    >>> output_kind("cycle.mp4", ("gif", "html"))
    Traceback (most recent call last):
    ...
    mbplanar.errors.ModelError: cycle.mp4: the output must end in .gif or .html
    """
    suffix = str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
    if suffix not in allowed:
        raise ModelError(f"{path}: the output must end in {' or '.join('.' + a for a in allowed)}")
    return suffix


def plot(args, load) -> int:
    """`mbplanar plot MODEL WHAT -o FILE`: one picture (``--at``, ``--show``, ``--points``, ``--dpi``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments (``what``, ``output``, ``at``, ``show``, ``points``, ``dpi``).
    load : callable
        ``load()`` → the model's `Engine`, called once the arguments are checked.

    Returns
    -------
    int
        0: the picture is written.

    Raises
    ------
    ModelError
        An unknown picture or output type, an option that does not apply to the picture, a force
        picture of a model without loads or masses.
    PlotUnavailable
        matplotlib is not installed.

    Examples
    --------
    >>> import argparse, mbplanar, os, tempfile
    >>> from mbplanar.viz.command import plot
    >>> out = os.path.join(tempfile.mkdtemp(), "diagram.svg")
    >>> args = argparse.Namespace(what="diagram", output=out, at="30", show=None, points=None, dpi=40)
    >>> plot(args, lambda: mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    0
    >>> os.path.getsize(out) > 1000
    True
    """
    from ..io.commands import NO_FORCE_DATA
    from ..io.inputs import at_reduced, inputs_at
    from . import _plotting as plotting
    output_kind(args.output, ("png", "svg", "pdf"))
    if args.what not in plotting.FIGURES:
        raise ModelError(plotting.unknown_picture(args.what))
    if args.show is not None and args.what != "diagram":
        raise ModelError(f"--show applies to the diagram, not to '{args.what}'")
    if args.points is not None and args.what != "trajectories":
        raise ModelError(f"--points applies to the trajectories, not to '{args.what}'")
    options = plotting.show_options(args.show) if args.what == "diagram" else {}
    if args.points is not None:
        options["points"] = [n.strip() for n in args.points.split(",") if n.strip()]
        if not options["points"]:
            raise ModelError("--points needs names of pairs or points separated by commas")
    plotting.require_matplotlib()
    engine = load()
    from ..forces import has_force_data
    if args.what in ("forces", "shaking") and not has_force_data(engine.mech):
        raise ModelError(f"nothing to draw for '{args.what}': {NO_FORCE_DATA}", source=engine.mech.source)
    at = None
    if args.at is not None:
        at = at_reduced(engine, inputs_at(engine, args.at))
        at = at[0] if len(at) == 1 else at
    plotting.save_figure(plotting.make_figure(engine, args.what, at, **options), args.output, dpi=args.dpi)
    return 0


def animate(args, load) -> int:
    """`mbplanar animate MODEL -o FILE`: a cycle as a GIF or a browser page (SVG); where the motion turns
    back at its limits, a note on standard error names them.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments (``output``, ``frames``, ``dpi``).
    load : callable
        ``load()`` → the model's `Engine`, called once the arguments are checked.

    Returns
    -------
    int
        0: the animation is written.

    Raises
    ------
    ModelError
        An output that is neither .gif nor .html, fewer than 2 frames.
    PlotUnavailable
        A GIF without matplotlib.

    Examples
    --------
    >>> import argparse, mbplanar, os, tempfile
    >>> from mbplanar.viz.command import animate
    >>> out = os.path.join(tempfile.mkdtemp(), "cycle.html")
    >>> args = argparse.Namespace(output=out, frames=4, dpi=40)
    >>> animate(args, lambda: mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    0
    >>> open(out, encoding="utf-8").read().count("<svg") >= 1
    True
    """
    from . import _plotting as plotting
    kind = output_kind(args.output, ("gif", "html"))
    if args.frames < 2:
        raise ModelError("--frames must be at least 2")
    if kind == "gif":
        plotting.require_matplotlib()
    engine = load()
    if kind == "gif":
        motion = plotting.write_gif(engine, args.output, args.frames, dpi=args.dpi)
    else:
        from ._animation import write_html_animation
        write_html_animation(engine, args.output, args.frames)
        motion = plotting.cycle_motion(engine, args.frames)
    if motion.limits:
        from ..kinematics import describe_limit
        print(f"mbplanar: {engine.mech.source}: the animation turns back at the motion limits: "
              + "; ".join(describe_limit(engine, lim) for lim in motion.limits), file=sys.stderr)
    return 0


def report(args, load) -> int:
    """`mbplanar report MODEL -o FILE.html`: one self-contained HTML report of the model, with the
    sections registered so far (`mbplanar.viz.register_section`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments (``output``, ``frames``).
    load : callable
        ``load()`` → the model's `Engine`, called once the arguments are checked.

    Returns
    -------
    int
        0: the report is written.

    Raises
    ------
    ModelError
        An output that is not .html.
    PlotUnavailable
        matplotlib is not installed.

    Examples
    --------
    >>> import argparse, mbplanar, os, tempfile
    >>> from mbplanar.viz.command import report
    >>> out = os.path.join(tempfile.mkdtemp(), "report.html")
    >>> report(argparse.Namespace(output=out, frames=4),
    ...        lambda: mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")))
    0
    >>> "fourbar" in open(out, encoding="utf-8").read()
    True
    """
    from . import _plotting as plotting
    from ._report import write_report
    output_kind(args.output, ("html",))
    plotting.require_matplotlib()
    write_report(load(), args.output, frames=args.frames)
    return 0
