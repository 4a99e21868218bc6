"""The report's Gears section: present when the model has a `[gears]` section (the drive of the
mechanism): the pair's geometry, checks, block contour and meshing, the planetary train's best tooth
numbers and velocity diagram, and a train recorded by `mbplanar gear planetary -o` (`[gears.train]`)."""

from __future__ import annotations

import html

__all__ = ["report_section", "register"]


def report_section(engine, ctx):
    """The section's HTML, or None without a `[gears]` section."""
    extras = getattr(engine.mech, "extras", {})
    if "gears" not in extras:
        return None
    from ..viz import html_table
    from . import plots
    from .command import design_pair, pair_text, planetary_text, search_trains
    from .profile import gear_profile
    from .spec import parse_gears
    spec = parse_gears({"gears": extras["gears"]}, str(engine.mech.source))
    parts = [f"<p>{html.escape(spec.title)}</p>"] if spec.title else []
    stage = None
    if spec.pair is not None:
        pair, choice, contour = design_pair(spec.pair)
        profiles = (gear_profile(pair, 1), gear_profile(pair, 2))
        stage = pair
        parts.append("<h3>Spur pair</h3><pre>" + html.escape(pair_text(pair, choice, profiles)) + "</pre>")
        parts.append(ctx.figure(plots.contour_figure(contour, pair.shifts), "block contour"))
        parts.append(ctx.figure(plots.mesh_figure(pair, profiles), "meshing pair"))
    if spec.planetary is not None:
        search = search_trains(spec.planetary, stage if spec.planetary.stage else None)
        parts.append("<h3>Planetary train</h3>")
        if search.trains:
            chosen = search.trains[min(spec.planetary.choose, len(search.trains)) - 1]
            parts.append("<pre>" + html.escape(planetary_text(search, chosen, stage if spec.planetary.stage
                                                              else None)) + "</pre>")
            parts.append(ctx.figure(plots.velocity_figure(chosen), "planetary train and velocity diagram"))
        else:
            parts.append(f'<p class="warn">{html.escape(search.message)}</p>')
    if spec.train is not None:
        rows = [(k, ", ".join(map(str, v)) if isinstance(v, list) else v) for k, v in spec.train.items()]
        parts.append(html_table(("key", "value"), rows, "The train recorded in [gears.train]"))
    return "\n".join(parts)


def register() -> None:
    """Add the Gears section to `mbplanar report` (after the cam's, else after the flywheel)."""
    from ..viz import SECTIONS, register_section
    register_section("gears", "Gears", report_section, after="cam" if "cam" in SECTIONS else "flywheel")
