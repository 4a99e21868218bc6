"""Pictures: the scene (links and joints placed for drawing), matplotlib figures (`make_figure`,
`register_figure`), force pictures, the SVG/HTML animation (`Animation` plays inline in Jupyter), what
Jupyter shows for each result (`_notebook`) and the HTML report (`write_report`,
`register_section`).

matplotlib is imported only when a picture is drawn.
"""

from ._animation import Animation, html_animation, svg_animation, write_html_animation
from ._forceplots import reaction_label
from ._plotting import (COLORS, FIGURES, INK, PlotUnavailable, cycle_motion, draw_mechanism, figure_bytes, lean_ticks,
                        make_figure, moving_points, position_motion, register_figure, require_matplotlib, save_figure,
                        write_gif)
from ._report import SECTIONS, Section, html_table, register_section, report_html, write_report
from ._scene import Scene, build_scene

__all__ = ["Scene", "build_scene", "cycle_motion", "position_motion", "moving_points", "reaction_label", "FIGURES",
           "PlotUnavailable", "require_matplotlib", "register_figure", "make_figure", "save_figure", "figure_bytes",
           "write_gif", "draw_mechanism", "lean_ticks", "COLORS", "INK", "Animation", "svg_animation",
           "html_animation", "write_html_animation", "Section", "SECTIONS", "register_section", "html_table",
           "report_html", "write_report"]
