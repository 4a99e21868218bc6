"""Mechanisms of growing size for the scaling benchmark and the structure tests: a crank and k stacked
dyads, a crank and k class IV groups."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import mbplanar
from mbplanar.model import Mechanism

MODELS = Path(__file__).resolve().parent.parent / "models"


def dyad_chain(k):
    """A crank and k stacked dyads (class II groups): dyad j couples the previous rocker (point E at
    0.1 m from its pivot) to a new rocker pivoted 0.3 m further along x; every stage is the four-bar
    0.1 / 0.3 / 0.25 / 0.3, drawn on its upper branch."""
    m = Mechanism(f"chain{k}")
    m.add_link("c")
    m.add_joint("O", "R", "0", "c", at=(0.0, 0.0))
    prev_link, pivot, tip = "c", np.array([0.0, 0.0]), np.array([0.05, 0.0866025403784])
    for j in range(1, k + 1):
        coupler, rocker = f"u{j}", f"r{j}"
        m.add_link(coupler)
        m.add_link(rocker)
        c_j = pivot + np.array([0.3, 0.0])
        d = c_j - tip
        dist = float(np.hypot(*d))
        ang = math.atan2(d[1], d[0]) + math.acos((0.3 ** 2 + dist ** 2 - 0.25 ** 2) / (2 * 0.3 * dist))
        b_j = tip + 0.3 * np.array([math.cos(ang), math.sin(ang)])
        m.add_joint(f"E{j}", "R", prev_link, coupler, at=tuple(tip))
        m.add_joint(f"B{j}", "R", coupler, rocker, at=tuple(b_j))
        m.add_joint(f"C{j}", "R", rocker, "0", at=tuple(c_j))
        prev_link, pivot = rocker, c_j
        tip = c_j + 0.1 * (b_j - c_j) / np.hypot(*(b_j - c_j))
    m.add_input("O", drawn_at=60.0)
    return m


def class4_chain(k):
    """A crank and k class IV groups, each a copy of models/class4_group.toml's group (seed 004): copy j + 1
    is the model moved so that its crank centre O sits on the ground pivot C of copy j, and its pin A is a
    point of copy j's rocker 7, 0.15 m from C as the model's crank pin is from O. Every group is driven by
    the previous group's output rocker (which swings 24°), and stays far from its dead points."""
    model = mbplanar.read_model(MODELS / "class4_group.toml")
    at = {name: np.array(j.at) for name, j in model.joints.items()}
    m = Mechanism(f"class4_chain{k}")
    m.add_link("1")
    m.add_joint("O", "R", "0", "1", at=tuple(at["O"]))
    driver, origin = "1", np.zeros(2)
    for i in range(1, k + 1):
        for link in "234567":
            m.add_link(f"{link}_{i}")
        for name, joint in model.joints.items():
            if name == "O":
                continue
            a, b = (x if x == model.ground else driver if x == "1" else f"{x}_{i}" for x in joint.links)
            m.add_joint(f"{name}_{i}", "R", a, b, at=tuple(origin + at[name]))
        driver, origin = f"7_{i}", origin + at["C"] - at["O"]
    m.add_input("O", drawn_at=30.0)
    return m
