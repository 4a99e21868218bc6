"""Circuit, branch and order defects on constructed four-bars, found by mbplanar's engine."""

import math

import numpy as np

import mbplanar
from mbplanar.synthesis._models import fourbar_toml, read_design
from mbplanar.synthesis.defects import check_defects


def _fourbar(a, b, c, d, phi0, mode=1):
    """A four-bar (ground d on x) drawn at crank angle φ0 in assembly `mode`, and a function giving the
    rocker joint B at crank angles φ in either mode."""
    def joint_b(phi, m):
        ax, ay = a * np.cos(phi), a * np.sin(phi)
        dx, dy = d - ax, -ay
        dist = np.hypot(dx, dy)
        along = (b * b - c * c + dist * dist) / (2 * dist)
        with np.errstate(invalid="ignore"):      # NaN past a dead point: the node cannot be met
            h = m * np.sqrt(b * b - along * along)
        return np.column_stack([ax + along * dx / dist - h * dy / dist, ay + along * dy / dist + h * dx / dist])
    a1 = (a * math.cos(phi0), a * math.sin(phi0))
    text = fourbar_toml((0, 0), a1, joint_b(np.array([phi0]), mode)[0], (d, 0), {})
    return mbplanar.Engine(read_design(text)), joint_b


def test_crank_rocker_through_its_own_positions_has_no_defect():
    engine, joint_b = _fourbar(0.2, 1.0, 0.9, 1.0, 0.3)
    phi = np.array([0.3, 1.5, 3.0, 4.5])
    d = check_defects(engine, phi, {"B": joint_b(phi, 1)}, full_turn=True)
    assert d.ok and d.full_turn and d.sense == 1


def test_circuit_defect_a_node_on_the_other_assembly():
    engine, joint_b = _fourbar(0.2, 1.0, 0.9, 1.0, 0.3)
    phi = np.array([0.3, 1.5, 3.0])
    wanted = joint_b(phi, 1)
    wanted[1] = joint_b(phi[1:2], -1)[0]                # node 2 on the other circuit
    d = check_defects(engine, phi, {"B": wanted})
    assert d.circuit == (2,) and not d.ok


def test_branch_defect_a_dead_point_between_nodes():
    # a triple rocker (not Grashof): its input rocks between two dead points
    engine, joint_b = _fourbar(0.8, 0.5, 0.9, 1.0, math.radians(60))
    m = mbplanar.analyse(engine, np.radians(np.arange(0, 360, 1.0)))
    assert m.limits                                      # it does not turn fully
    stop = max(lim.phi[0] for lim in m.limits)
    phi = np.array([math.radians(60), stop + 0.2])
    d = check_defects(engine, phi, {"B": joint_b(phi, 1)}, periodic=False)
    assert d.branch and not d.ok
    assert "at" in d.describe()


def test_order_defect_nodes_not_met_in_either_sense():
    engine, joint_b = _fourbar(0.2, 1.0, 0.9, 1.0, 0.0)
    phi = np.radians([0.0, 180.0, 90.0, 270.0])
    d = check_defects(engine, phi, {"B": joint_b(phi, 1)})
    assert d.order and not d.ok and d.circuit == ()
    clockwise = np.radians([0.0, -90.0, -180.0, -270.0])
    d = check_defects(engine, clockwise, {"B": joint_b(clockwise, 1)})
    assert d.ok and d.sense == -1
