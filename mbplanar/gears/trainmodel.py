"""A planetary train (optionally followed by a pair on fixed axes) written as a model table with `gear`
joints, which the engine reads as higher pairs (docs/gears.md, "The model of a train").

The train's axis is at the origin, the planet's at (a_w, 0). Links: "1" gear 1, "2" the planet (one
planet; the other k − 1 are kinematically redundant and are recorded in `[gears.train]`), "H" the
carrier; the fixed central gear belongs to the frame "0". A `gear` row names its two links, their
`teeth` and `module` (or `radii`, the working pitch radii, for a shifted pair), `mesh = "external"` or
`"internal"` (the second link then has the internal teeth), the `carrier` on which both gears' axes are
fixed, the `pressure_angle` of the line of action (degrees; a shifted pair's working one, α_w) and `at`,
the pitch point in the drawing. The relation it stands for is
r₁(θ₁ − θ_c) = ∓r₂(θ₂ − θ_c) (− external, + internal).

    >>> from mbplanar.gears import planetary_trains
    >>> from mbplanar.gears.trainmodel import train_model
    >>> text = train_model(planetary_trains(4.0, "A", planets=4, min_teeth=16, tolerance=0).trains[0])
    >>> 'type = "gear"' in text and 'carrier = "H"' in text
    True
"""

from __future__ import annotations

from dataclasses import dataclass

from .planetary import SCHEMES, Train

__all__ = ["train_model", "write_train_model", "Stage"]


@dataclass(frozen=True)
class Stage:
    """A pair on fixed axes after the train's output: gear `teeth[0]` on the output shaft drives gear
    `teeth[1]` (link "out"), whose axis is `centre_distance` below the train's.

    Attributes
    ----------
    teeth : (z₁, z₂)
    module : m (m)
    radii : the working pitch radii (m)
    centre_distance : a_w (m)
    shifts : (x₁, x₂), recorded
    pressure_angle : the working pressure angle α_w, degrees (the line of action's)

    Examples
    --------
    >>> from mbplanar.gears import gear_pair
    >>> from mbplanar.gears.trainmodel import Stage
    >>> s = Stage.from_pair(gear_pair(10e-3, (12, 30), (0.6, 0.5)))
    >>> s.teeth, abs(sum(s.radii) - s.centre_distance) < 1e-15
    ((12, 30), True)
    """

    teeth: tuple
    module: float
    radii: tuple
    centre_distance: float
    shifts: tuple = (0.0, 0.0)
    pressure_angle: float = 20.0

    @classmethod
    def from_pair(cls, pair):
        """The stage of a designed external `GearPair`."""
        z1, z2 = (g.teeth for g in pair.gears)
        radii = tuple(g.working_diameter / 2 for g in pair.gears)
        return cls((z1, z2), pair.module, radii, pair.centre_distance, pair.shifts, pair.working_pressure_angle_deg)


def _num(v: float) -> str:
    return repr(float(v)) if v != int(v) or abs(v) > 1e15 else f"{float(v):.1f}"


def train_model(train: Train, *, name: str | None = None, title: str | None = None, omega: float | None = None,
                stage: Stage | None = None, pressure_angle: float = 20.0) -> str:
    """The TOML text of a model of `train` with `gear` joints.

    Parameters
    ----------
    train : Train
        from `planetary_trains`.
    name, title : str, optional
    omega : float, optional
        the input speed (rad/s) for `[input]`.
    stage : Stage, optional
        a pair on fixed axes after the output (link "out").
    pressure_angle : float
        the train's (unshifted) meshes' pressure angle, degrees: the direction of the contact force along
        the line of action.

    Returns
    -------
    str
        the model; lengths in metres.

    Examples
    --------
    >>> from mbplanar.gears import planetary_trains
    >>> from mbplanar.gears.trainmodel import train_model
    >>> import tomllib
    >>> t = planetary_trains(4.0, "A", planets=4, min_teeth=16, tolerance=0).trains[0]
    >>> table = tomllib.loads(train_model(t))
    >>> [j["name"] for j in table["joints"]], table["input"]["joint"]
    (['O1', 'OH', 'O2', 'G12', 'G23'], 'O1')
    """
    sch = SCHEMES[train.scheme]
    m, alpha = train.module, pressure_angle
    z1, z2, z3, z4 = (train.teeth[0], train.teeth[1], train.teeth[1], train.teeth[2]) if not sch.two_rows \
        else train.teeth
    aw = train.centre_distance
    r1, r4 = m * z1 / 2, m * z4 / 2
    second = "G23" if not sch.two_rows else "G34"
    name = name or f"planetary_{train.scheme}_" + "_".join(str(z) for z in train.teeth)
    title = title or (f"2K-H train, scheme {train.scheme} ({sch.title}), z = "
                      + ", ".join(str(z) for z in train.teeth) + f", {train.planets} planets")
    out_link = "1" if sch.driven_by_carrier else "H"
    lines = [
        f"# {title}",
        "# Written by `mbplanar gear planetary`: one planet is modelled; the other planets, equally spaced,",
        "# are kinematically redundant ([gears.train] planets). The engine reads the gear joints as higher",
        "# pairs (docs/gears.md, docs/format.md).",
        f'name = "{name}"',
        f'title = "{title}"',
        'ground = "0"',
        "",
        "links = [",
        '  { name = "1" },     # gear 1 (' + ("sun" if sch.first == "external" else "ring") + ")",
        '  { name = "2" },     # the planet' + (" block (two rows)" if sch.two_rows else ""),
        '  { name = "H" },     # the carrier',
    ]
    if stage is not None:
        lines.append('  { name = "out" },   # the driven gear of the pair after the train')
    lines += [
        "]",
        "",
        "joints = [",
        '  { name = "O1", type = "R", links = ["0", "1"], at = [0.0, 0.0] },',
        '  { name = "OH", type = "R", links = ["0", "H"], at = [0.0, 0.0] },',
        f'  {{ name = "O2", type = "R", links = ["H", "2"], at = [{_num(aw)}, 0.0] }},',
        f'  {{ name = "G12", type = "gear", links = ["1", "2"], teeth = [{z1}, {z2}], module = {_num(m)}, '
        f'mesh = "{sch.first}", carrier = "H", pressure_angle = {_num(alpha)}, at = [{_num(r1)}, 0.0] }},',
        f'  {{ name = "{second}", type = "gear", links = ["2", "0"], teeth = [{z3}, {z4}], module = {_num(m)}, '
        f'mesh = "{sch.second}", carrier = "H", pressure_angle = {_num(alpha)}, at = [{_num(r4)}, 0.0] }},',
    ]
    total = train.ratio
    if stage is not None:
        za, zb = stage.teeth
        ra, rb = stage.radii
        a = stage.centre_distance
        lines += [
            f'  {{ name = "Oout", type = "R", links = ["0", "out"], at = [0.0, {_num(-a)}] }},',
            f'  {{ name = "G56", type = "gear", links = ["{out_link}", "out"], teeth = [{za}, {zb}], '
            f'radii = [{_num(ra)}, {_num(rb)}], mesh = "external", carrier = "0", '
            f'pressure_angle = {_num(stage.pressure_angle)}, at = [0.0, {_num(-ra)}] }},',
        ]
        total = train.ratio * (-zb / za)
    lines += ["]", "", "[input]", f'joint = "{"OH" if sch.driven_by_carrier else "O1"}"', 'name = "phi"']
    if omega is not None:
        lines.append(f"omega = {_num(omega)}")
    lines += [
        "",
        "[gears.train]",
        f'scheme = "{train.scheme}"',
        "teeth = [" + ", ".join(str(z) for z in train.teeth) + "]",
        f"planets = {train.planets}",
        f"module = {_num(m)}",
        f'output = "{"out" if stage is not None else out_link}"',
        f"ratio = {_num(total)}            # input speed / output speed",
        f"willis = {_num(train.willis)}    # u^H_14: gear 1 relative to the fixed gear, carrier held",
    ]
    if stage is not None:
        lines += [f"stage = [{stage.teeth[0]}, {stage.teeth[1]}]",
                  f"stage_shifts = [{_num(stage.shifts[0])}, {_num(stage.shifts[1])}]",
                  f"stage_module = {_num(stage.module)}"]
    return "\n".join(lines) + "\n"


def write_train_model(train: Train, path, **options) -> None:
    """Write `train_model(train, **options)` to `path`."""
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(train_model(train, **options))
