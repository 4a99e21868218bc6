"""Animation of a cycle that plays in a browser without network: inline SVG + a few lines of inline JS.

`svg_animation(engine, frames)` returns an SVG element (a string) whose shapes are moved by a small
script from a JSON table of positions: the same `Scene` as the matplotlib diagram, so the drawing
conventions agree (hatched ground pivots and guides, bars, polygons, blocks, pins). No matplotlib
needed. `write_html_animation` wraps it into a one-file HTML page; `mbplanar.viz.write_gif` makes
the GIF.
"""

from __future__ import annotations

import html
import json

import numpy as np

from ._scene import build_scene

__all__ = ["svg_animation", "html_animation", "write_html_animation", "Animation"]

_SCRIPT = """
(function(){
  var root=document.getElementById('%(id)s'); var D=JSON.parse(root.querySelector('script[type="application/json"]').textContent);
  var els=D.shapes.map(function(s){return root.querySelector('[data-k="'+s+'"]');});
  var n=D.frames, i=0, playing=true, last=0, slider=root.parentNode.querySelector('input[type=range]');
  var btn=root.parentNode.querySelector('button'), out=root.parentNode.querySelector('output');
  function show(f){ for(var k=0;k<els.length;k++){ var c=D.xy[k][f], e=els[k];
      if(e.tagName==='circle'){e.setAttribute('cx',c[0]);e.setAttribute('cy',c[1]);}
      else if(e.tagName==='text'){e.setAttribute('x',c[0]);e.setAttribute('y',-c[1]);}
      else {var p=[];for(var j=0;j<c.length;j+=2)p.push(c[j]+','+c[j+1]);e.setAttribute('points',p.join(' '));}}
    if(slider)slider.value=f; if(out)out.textContent=D.phi[f]; }
  function tick(t){ if(playing&&t-last>1000/D.fps){last=t;i=(i+1)%%n;show(i);} requestAnimationFrame(tick);}
  if(slider)slider.addEventListener('input',function(){playing=false;i=+slider.value;show(i);btn.textContent='play';});
  if(btn)btn.addEventListener('click',function(){playing=!playing;btn.textContent=playing?'pause':'play';});
  show(0); requestAnimationFrame(tick);
})();
"""


def _num(x):
    return float(f"{x:.5g}")


def _flat(arr):
    """(B, n, 2) → per frame a flat list [x0, y0, x1, y1, ...] rounded to 5 digits."""
    return [[_num(v) for v in frame.reshape(-1)] for frame in np.asarray(arr)]


def _pts(xy):
    return " ".join(f"{_num(x)},{_num(y)}" for x, y in np.asarray(xy).reshape(-1, 2))


def _hatch(a, b, normal, step, depth):
    a, b, normal = np.asarray(a, float), np.asarray(b, float), np.asarray(normal, float)
    u = (b - a) / max(np.linalg.norm(b - a), 1e-12)
    n = max(int(np.linalg.norm(b - a) / step), 2)
    out = [f'<polyline points="{_pts([a, b])}" stroke-width="{depth * 0.35:.4g}"/>']
    for t in np.linspace(0, 1, n + 1)[1:]:
        p = a + t * (b - a)
        out.append(f'<polyline points="{_pts([p, p + depth * normal - depth * u])}"/>')
    return out


def svg_animation(engine, frames: int = 72, *, fps: float = 12, element_id: str = "mbanim", trajectories=True,
                  width: int = 640, motion=None, controls: bool = True) -> str:
    """An inline SVG animation of the cycle with its player (play/pause, a position slider, a frame counter).

    No matplotlib and no network: the SVG and a short script. The shapes are drawn at the first
    position, so the picture shows without its script.

    Parameters
    ----------
    engine : Engine
        The model.
    frames : int
        Positions over the cycle (`cycle_motion`), when `motion` is not given.
    fps : float
        Frames per second.
    element_id : str
        The SVG element's id (unique on a page showing several).
    trajectories : bool
        Draw the points' paths.
    width : int
        Width in pixels (the height follows the drawing).
    motion : Motion, optional
        The positions to animate instead of the cycle's.
    controls : bool
        False: no player and no script, a still diagram of the first position.

    Returns
    -------
    str
        HTML: a <div> holding the <svg> (and its <script>).

    Raises
    ------
    MotionError
        No position of the cycle can be reached.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import svg_animation
    >>> engine = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
    >>> text = svg_animation(engine, frames=4)
    >>> text.startswith('<div class="mbanim"><svg id="mbanim"'), "<script>" in text
    (True, True)
    >>> "<script>" in svg_animation(engine, frames=4, controls=False)       # a still picture
    False
    """
    from ._plotting import cycle_motion  # matplotlib-free part of plotting
    motion = cycle_motion(engine, frames) if motion is None else motion
    sc = build_scene(engine, motion, motion)
    size = sc.size
    x0, x1, y0, y1 = sc.extent()
    lw = 0.012 * size
    static, moving, shapes, xy = [], [], [], []

    def dyn(tag, arr, attrs):
        k = f"s{len(shapes)}"
        shapes.append(k)
        xy.append(_flat(arr) if tag != "circle" else [[_num(v) for v in f] for f in np.asarray(arr)])
        first = np.asarray(arr)[0]
        if tag == "circle":
            at = f'cx="{_num(first[0])}" cy="{_num(first[1])}" '
        elif tag == "text":
            at = f'x="{_num(first[0])}" y="{_num(-first[1])}" '
        else:
            at = f'points="{_pts(first)}" '
        moving.append(f'<{tag} data-k="{k}" {at}{attrs}/>' if tag != "text" else
                      f'<text data-k="{k}" {at}{attrs}</text>')

    if trajectories:
        from ._plotting import COLORS, _point_xy, moving_points
        for k, name in enumerate(moving_points(engine, sc)):
            static.append(f'<polyline points="{_pts(_point_xy(sc, name))}" fill="none" '
                          f'stroke="{COLORS[k % len(COLORS)]}" stroke-width="{lw * 0.35:.4g}" opacity="0.8"/>')
    for s in sc.sliders:
        g = s.guide[0]
        if s.grounded:
            u = (g[1] - g[0]) / np.linalg.norm(g[1] - g[0])
            n = np.array([-u[1], u[0]])
            if n[1] > 1e-9 or (abs(n[1]) <= 1e-9 and n[0] > 0):
                n = -n
            off = 0.032 * size * n
            static.append(f'<polyline points="{_pts(g)}" stroke-width="{lw * 0.3:.4g}" '
                          f'stroke-dasharray="{size * 0.03:.4g} {size * 0.01:.4g}"/>')
            static += _hatch(g[0] + off, g[1] + off, n, 0.022 * size, 0.025 * size)
        else:
            dyn("polyline", s.guide, f'stroke-width="{lw * 0.8:.4g}" stroke-linecap="round"')
    for name in sc.pivots:
        x, y = sc.joint_xy[0, sc.joint_names.index(name)]
        h, w = 0.055 * size, 0.032 * size
        static.append(f'<polygon points="{_pts([[x, y], [x - w, y - h], [x + w, y - h]])}" fill="white"/>')
        static += _hatch((x - 1.6 * w, y - h), (x + 1.6 * w, y - h), (0, -1), 0.35 * w, 0.45 * w)
    from ._plotting import CONTACT_COLOR, PAIR_STYLES
    for pair in sc.pairs:
        for kind, _, line, closed in pair.lines:
            width, dash, fill = PAIR_STYLES[kind]
            dashes = f' stroke-dasharray="{size * 0.03:.4g} {size * 0.01:.4g}"' if dash else ""
            fills = f' fill="{fill}"' if fill is not None and closed else ""
            dyn("polygon" if closed else "polyline", line, f'stroke-width="{lw * width:.4g}"{dashes}{fills}')
        for m in range(pair.marks.shape[1]):
            dyn("polyline", pair.marks[:, m], f'stroke-width="{lw * 0.12:.4g}"')
    for link in sc.links:
        if link.kind == "bar":
            dyn("polyline", link.outline, f'stroke-width="{lw:.4g}" stroke-linecap="round"')
            for m in range(link.stubs.shape[1]):
                dyn("polyline", link.stubs[:, m], f'stroke-width="{lw * 0.8:.4g}" stroke-linecap="round"')
        elif link.kind == "polygon":
            dyn("polygon", link.outline, f'fill="#cfe0f3" stroke-width="{lw * 0.75:.4g}" stroke-linejoin="round"')
    for s in sc.sliders:
        dyn("polygon", s.corners, f'fill="#f3e3c3" stroke-width="{lw * 0.5:.4g}"')
    for name in sc.revolute:
        dyn("circle", sc.joint_xy[:, sc.joint_names.index(name)], f'r="{0.016 * size:.4g}" fill="white" '
            f'stroke-width="{lw * 0.4:.4g}"')
    for k, name in enumerate(sc.point_names):
        dyn("circle", sc.point_xy[:, k], f'r="{0.009 * size:.4g}" fill="#1a1a1a"')
    for pair in sc.pairs:
        dyn("circle", pair.contact, f'r="{0.008 * size:.4g}" fill="{CONTACT_COLOR}" stroke="none"')
    for name in sc.joint_names:
        if sc.labels.get(name):
            dyn("text", sc.joint_xy[:, sc.joint_names.index(name)] + 0.025 * size,
                f'font-style="italic">{html.escape(name)}')
    for link in sc.links:
        if np.all(np.isfinite(link.label)):
            dyn("text", link.label, f'font-weight="bold" fill="#1f4e8c" text-anchor="middle" '
                f'dominant-baseline="middle">{html.escape(link.name)}')
    from ._plotting import input_label
    data = {"shapes": shapes, "xy": xy, "frames": sc.batch, "fps": fps,
            "phi": [input_label(engine, row, ".2f") for row in motion.phi]}
    texts = [m for m in moving if m.startswith("<text")]
    shapes_svg = [m for m in moving if not m.startswith("<text")]
    height = int(width * (y1 - y0) / (x1 - x0))
    table = f'<script type="application/json">{json.dumps(data, separators=(",", ":"))}</script>' if controls else ""
    svg = (f'<svg id="{element_id}" width="{width}" '
           f'height="{height}" viewBox="{_num(x0)} {_num(-y1)} {_num(x1 - x0)} {_num(y1 - y0)}">' + table +
           f'<g transform="scale(1,-1)" stroke="#1a1a1a" fill="none" stroke-width="{lw * 0.3:.4g}">'
           + "".join(static) + "".join(shapes_svg) + "</g>"
           f'<g font-family="sans-serif" font-size="{0.045 * size:.4g}" fill="#1a1a1a">' + "".join(texts)
           + "</g></svg>")
    if not controls:
        return f'<div class="mbdiagram">{svg}</div>'
    return (f'<div class="mbanim">{svg}<div><button type="button">pause</button> '
            f'<input type="range" min="0" max="{sc.batch - 1}" value="0" style="width:60%"> '
            f'<output>{html.escape(data["phi"][0])}</output>'
            f"</div><script>{_SCRIPT % {'id': element_id}}</script></div>")


def html_animation(engine, frames: int = 72, **kw) -> str:
    """The animation as a one-file HTML page (no external resource), what ``mbplanar animate -o FILE.html``
    writes.

    Parameters
    ----------
    engine : Engine
        The model.
    frames : int
        Positions over the cycle.
    **kw
        Passed to `svg_animation` (``fps``, ``trajectories``, ``width``, ...).

    Returns
    -------
    str
        The page, titled with the model's title.

    Raises
    ------
    MotionError
        No position of the cycle can be reached.

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import html_animation
    >>> page = html_animation(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), frames=4)
    >>> page.splitlines()[0], "<title>Crank-rocker four-bar</title>" in page
    ('<!DOCTYPE html>', True)
    """
    title = html.escape(engine.mech.title or engine.mech.name)
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + title +
            "</title><style>body{font-family:sans-serif;margin:1.5em}</style></head><body><h1>" + title +
            "</h1>" + svg_animation(engine, frames, **kw) + "</body></html>\n")


def write_html_animation(engine, path, frames: int = 72, **kw):
    """Write the animation's one-file HTML page (`html_animation`) to a file.

    Parameters
    ----------
    engine : Engine
        The model.
    path : str or Path
        The HTML file.
    frames : int
        Positions over the cycle.
    **kw
        Passed to `svg_animation`.

    Returns
    -------
    None

    Raises
    ------
    MotionError
        No position of the cycle can be reached.
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import os, tempfile, mbplanar
    >>> from mbplanar.viz import write_html_animation
    >>> path = os.path.join(tempfile.mkdtemp(), "fourbar.html")
    >>> write_html_animation(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), path, frames=4)
    >>> open(path, encoding="utf-8").read(15)
    '<!DOCTYPE html>'
    """
    with open(path, "w", encoding="utf-8") as f:
        f.write(html_animation(engine, frames, **kw))


class Animation:
    """The cycle's animation for Jupyter: shown as the last expression of a cell, it plays inline.

    An SVG with its player (play/pause, a position slider and a frame counter), offline, as
    ``mbplanar animate`` makes it; each one shown gets an element id of its own.

    Parameters
    ----------
    engine : Engine
        The mechanism to animate.
    frames : int
        Positions over the cycle (up to a motion limit, if the mechanism meets one).
    **options
        Passed to `svg_animation` (``fps``, ``trajectories``, ``width``).

    Examples
    --------
    >>> import mbplanar
    >>> from mbplanar.viz import Animation
    >>> animation = Animation(mbplanar.Engine(mbplanar.read_model("models/fourbar.toml")), frames=4, fps=6)
    >>> html = animation._repr_html_()                  # what Jupyter shows
    >>> html.startswith('<div class="mbanim"><svg id="mbplanar-animation-')
    True
    """

    _ids = 0

    def __init__(self, engine, frames: int = 72, **options):
        self.engine, self.frames, self.options = engine, frames, options

    def _repr_html_(self) -> str:
        Animation._ids += 1
        return svg_animation(self.engine, self.frames, element_id=f"mbplanar-animation-{Animation._ids}",
                             **self.options)
