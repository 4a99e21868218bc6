"""Two degrees of freedom: a five-bar driven by both ground cranks, against the closed form."""

import math

import numpy as np

import mbplanar


def _fivebar():
    m = mbplanar.Mechanism("fivebar")
    for name in ("1", "2", "3"):
        m.add_link(name)
    m.add_link("4", angle=("E", "B"))  # crank EB: its angle is measured from E
    o, e = np.array([0.0, 0.0]), np.array([0.4, 0.0])
    a = o + 0.15 * np.array([math.cos(1.2), math.sin(1.2)])
    b = e + 0.15 * np.array([math.cos(1.9), math.sin(1.9)])
    # coupler point P: circle intersection, upper branch
    d = b - a
    dist = np.linalg.norm(d)
    along = dist / 2
    h = math.sqrt(0.35 ** 2 - along ** 2)
    p = a + along * d / dist + h * np.array([-d[1], d[0]]) / dist
    m.add_joint("O", "R", "0", "1", at=o)
    m.add_joint("A", "R", "1", "2", at=a)
    m.add_joint("P", "R", "2", "3", at=p)
    m.add_joint("B", "R", "3", "4", at=b)
    m.add_joint("E", "R", "0", "4", at=e)
    m.add_input("O", unit="rad", drawn_at=1.2)
    m.add_input("E", unit="rad", drawn_at=1.9)
    return m


def test_fivebar_two_inputs_closed_form():
    engine = mbplanar.Engine(_fivebar())
    assert engine.topology.dof == 2
    phi = np.array([[1.2, 1.9], [1.3, 1.8], [1.5, 1.7], [1.1, 2.1]])
    m = mbplanar.analyse(engine, phi, omega=[1.0, 0.5], epsilon=[0.0, 0.0])
    assert len(m.phi) == 4
    a = 0.15 * np.stack([np.cos(phi[:, 0]), np.sin(phi[:, 0])], -1)
    b = np.array([0.4, 0.0]) + 0.15 * np.stack([np.cos(phi[:, 1]), np.sin(phi[:, 1])], -1)
    d = b - a
    dist = np.linalg.norm(d, axis=-1)
    h = np.sqrt(0.35 ** 2 - (dist / 2) ** 2)
    p = a + d / 2 + h[:, None] * np.stack([-d[:, 1], d[:, 0]], -1) / dist[:, None]
    assert np.abs(m.xy[:, m.point("P")] - p).max() < 1e-9
    # velocity of P by central differences of the closed form along (omega1, omega2) = (1, 0.5)
    step = 1e-6
    m2 = mbplanar.analyse(engine, phi + step * np.array([1.0, 0.5]))
    m0 = mbplanar.analyse(engine, phi - step * np.array([1.0, 0.5]))
    fd = (m2.xy[:, m2.point("P")] - m0.xy[:, m0.point("P")]) / (2 * step)
    assert np.abs(m.v[:, m.point("P")] - fd).max() < 1e-6
