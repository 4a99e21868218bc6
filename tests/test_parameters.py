"""Design parameters: [parameters], names in numeric fields, polar placements, units, errors."""

import math
import tomllib

import pytest

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.model._parameters import Template

BASE = """
name = "p"
links = [{ name = "1" }, { name = "2" }, { name = "3" }]
joints = [
  { name = "O", type = "R", links = ["0", "1"], at = [0.0, 0.0] },
  { name = "A", type = "R", links = ["1", "2"], at = { from = "O", length = "a", angle = "t" } },
  { name = "B", type = "R", links = ["2", "3"], at = { from = "A", length = 0.3, angle = "beta" } },
  { name = "C", type = "R", links = ["3", "0"], at = ["d", 0.0] },
]
[parameters]
a = 0.1
t = { value = 1.0, unit = "rad" }
beta = 30.0
d = { value = 300.0, unit = "mm" }
[input]
joint = "O"
"""


def test_polar_placement_is_the_seed_002_pose_to_the_last_digit():
    """The worked model of seed 002, written with parameters, has the pose the seed's formulas give
    (A = (l1, 0), C = A + l2 e(φ2), B = C + l3 e(φ3), D = B + l4 e(φ4)), bit for bit."""
    mech = mbplanar.read_model("models/crank_slider_rocker.toml")
    l1, l2, l3, l4, p2, p3, p4 = 0.5, 1.0, 1.2, 0.8, 0.5, 1.9, 3.5
    c = (l1 + l2 * math.cos(p2), 0.0 + l2 * math.sin(p2))
    b = (c[0] + l3 * math.cos(p3), c[1] + l3 * math.sin(p3))
    d = (b[0] + l4 * math.cos(p4), b[1] + l4 * math.sin(p4))
    assert mech.joints["C"].at == c and mech.joints["Cp"].at == c
    assert mech.joints["B"].at == b and mech.joints["D"].at == d


def test_units_and_values():
    t = Template(tomllib.loads(BASE), "p.toml")
    mech = mbplanar.parse_model(t.bind({"a": 0.2, "beta": 90.0}))
    assert mech.joints["A"].at == pytest.approx((0.2 * math.cos(1.0), 0.2 * math.sin(1.0)), abs=1e-15)
    assert mech.joints["B"].at == pytest.approx((mech.joints["A"].at[0], mech.joints["A"].at[1] + 0.3), abs=1e-15)
    assert mech.joints["C"].at == (0.3, 0.0)  # 300 mm in a model in metres
    assert t.used == {"a", "t", "beta", "d"}


@pytest.mark.parametrize("change, message", [
    (('"beta" }', '"gamma" }'), "'gamma' is not a number nor a parameter"),
    (('from = "A"', 'from = "B"'), "polar placements form a cycle"),
    (('length = "a"', 'length = "t"'), "parameter 't' is in rad"),
    (('d = { value = 300.0, unit = "mm" }', 'd = { value = 300.0, unit = "ft" }'), "unit must be one of"),
    (('d = { value = 300.0, unit = "mm" }', 'd = { value = 300.0, unit = [] }'), "unit must be one of"),
    (('from = "O"', 'from = "Q"'), "'from' names no joint 'Q'"),
])
def test_errors_name_the_row(change, message):
    with pytest.raises(ModelError, match=message):
        mbplanar.parse_model(BASE.replace(*change), "p.toml")


def test_unknown_parameter_value_is_refused():
    t = Template(tomllib.loads(BASE), "p.toml")
    with pytest.raises(ModelError, match="unknown parameter"):
        t.bind({"e": 1.0})


def test_commands_read_models_with_parameters(capsys):
    from mbplanar.cli import main

    assert main(["info", "models/fourbar_design.toml"]) == 0
    assert "joint B" in capsys.readouterr().out
