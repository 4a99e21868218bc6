"""Tests of mbplanar.structure: Assur-group decomposition (Artobolevsky)."""

import json
import math
import random
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import mbplanar
from conftest import linkage_models
from mbplanar.cli import main
from mbplanar.errors import ModelError
from mbplanar.structure import AssurGroup, Structure, decompose, roman

MODELS = Path(__file__).resolve().parent.parent / "models"
sys.path.insert(0, str(MODELS.parent / "benchmarks"))
from chains import class4_chain  # noqa: E402  (benchmarks/chains.py: the scaling mechanisms)


def links(n):
    return [str(i) for i in range(1, n + 1)]


# name -> (links, joints, inputs, expected)
# expected: dof, loops, formula, [(group links, class, order, kind, internal, external)]
# Every row was checked by hand against the textbook decomposition.
MECHANISMS = {
    "shaper (seed 000)": (
        links(5),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("Ap", "P", "3", "2"), ("C", "R", "0", "3"),
         ("D", "R", "3", "4"), ("Dp", "P", "5", "4"), ("F", "P", "0", "5")],
        ["O"],
        (1, 2, "I(0,1) → II(2,3) → II(4,5)", [
            (("2", "3"), 2, 2, "RPR", ("Ap",), ("A", "C")),
            (("4", "5"), 2, 2, "RPP", ("Dp",), ("D", "F")),
        ]),
    ),
    "six-bar press (seed 003)": (
        links(5),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("C", "R", "0", "3"),
         ("D", "R", "3", "4"), ("H", "R", "4", "5"), ("Hp", "P", "0", "5")],
        ["O"],
        (1, 2, "I(0,1) → II(2,3) → II(4,5)", [
            (("2", "3"), 2, 2, "RRR", ("B",), ("A", "C")),
            (("4", "5"), 2, 2, "RRP", ("H",), ("D", "Hp")),
        ]),
    ),
    "seed 002": (
        links(5),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("C", "R", "2", "3"), ("C5", "R", "2", "5"),
         ("Cp", "P", "0", "5"), ("B", "R", "3", "4"), ("D", "R", "4", "0")],
        ["O"],
        (1, 2, "I(0,1) → II(2,5) → II(3,4)", [
            (("2", "5"), 2, 2, "RRP", ("C5",), ("A", "Cp")),
            (("3", "4"), 2, 2, "RRR", ("B",), ("C", "D")),
        ]),
    ),
    "class IV group (seed 004)": (
        links(7),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("D", "R", "2", "3"), ("G", "R", "2", "4"),
         ("E", "R", "3", "5"), ("K", "R", "4", "5"), ("F", "R", "5", "6"), ("B", "R", "6", "0"),
         ("L", "R", "5", "7"), ("C", "R", "7", "0")],
        ["O"],
        (1, 3, "I(0,1) → IV(2,3,4,5,6,7)", [
            (("2", "3", "4", "5", "6", "7"), 4, 3, None, ("D", "G", "E", "K", "F", "L"), ("A", "B", "C")),
        ]),
    ),
    "class III triad": (
        links(5),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "4"), ("C", "R", "4", "3"),
         ("D", "R", "3", "0"), ("E", "R", "4", "5"), ("F", "R", "5", "0")],
        ["O"],
        (1, 2, "I(0,1) → III(2,3,4,5)", [
            (("2", "3", "4", "5"), 3, 3, None, ("B", "C", "E"), ("A", "D", "F")),
        ]),
    ),
    "four-bar": (
        links(3),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("C", "R", "3", "0")],
        ["O"],
        (1, 1, "I(0,1) → II(2,3)", [(("2", "3"), 2, 2, "RRR", ("B",), ("A", "C"))]),
    ),
    "slider-crank": (
        links(3),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("Bp", "P", "3", "0")],
        ["O"],
        (1, 1, "I(0,1) → II(2,3)", [(("2", "3"), 2, 2, "RRP", ("B",), ("A", "Bp"))]),
    ),
    "Scotch yoke (PRP)": (
        links(3),
        [("O", "R", "0", "1"), ("A", "P", "1", "2"), ("B", "R", "2", "3"), ("Bp", "P", "3", "0")],
        ["O"],
        (1, 1, "I(0,1) → II(2,3)", [(("2", "3"), 2, 2, "PRP", ("B",), ("A", "Bp"))]),
    ),
    "five-bar with two ground inputs": (
        links(4),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("C", "R", "3", "4"),
         ("E", "R", "4", "0")],
        ["O", "E"],
        (2, 1, "I(0,1) → I(0,4) → II(2,3)", [(("2", "3"), 2, 2, "RRR", ("B",), ("A", "C"))]),
    ),
    "five-bar with a crank and a motor between links 2 and 3": (
        links(4),
        [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("C", "R", "3", "4"),
         ("E", "R", "4", "0")],
        ["O", "B"],
        # 2 and 3 are one body: body dyad {2,3} + {4}, read A–C–E.
        (2, 1, "I(0,1) → II(2,3,4)", [(("2", "3", "4"), 2, 2, "RRR", ("B", "C"), ("A", "E"))]),
    ),
    "excavator: two hydraulic cylinders": (
        links(6),
        [("J1", "R", "0", "1"), ("J2", "R", "0", "2"), ("Q1", "P", "2", "3"), ("J3", "R", "3", "1"),
         ("J4", "R", "1", "4"), ("J5", "R", "1", "5"), ("Q2", "P", "5", "6"), ("J6", "R", "6", "4")],
        ["Q1", "Q2"],
        (2, 2, "II(1,2,3) → II(4,5,6)", [
            (("1", "2", "3"), 2, 2, "RRR", ("Q1", "J3"), ("J1", "J2")),
            (("4", "5", "6"), 2, 2, "RRR", ("Q2", "J6"), ("J4", "J5")),
        ]),
    ),
    "actuator on an input link": (
        links(4),
        [("O", "R", "0", "1"), ("Q", "P", "1", "2"), ("A", "R", "2", "3"), ("B", "R", "3", "4"),
         ("C", "R", "4", "0")],
        ["O", "Q"],
        (2, 1, "I(0,1) → I(1,2) → II(3,4)", [(("3", "4"), 2, 2, "RRR", ("B",), ("A", "C"))]),
    ),
}


@pytest.mark.parametrize("name", list(MECHANISMS))
def test_decomposition_matches_hand_checked_table(name):
    link_names, joints, inputs, (dof, loops, formula, expected) = MECHANISMS[name]
    structure = decompose("0", link_names, joints, inputs)
    assert isinstance(structure, Structure)
    assert (structure.dof, structure.loops, structure.formula) == (dof, loops, formula)
    assert structure.inputs == tuple(inputs)
    got = [(g.links, g.group_class, g.order, g.kind, g.internal, g.external) for g in structure.groups]
    assert got == expected
    for group in structure.groups:
        assert group.joints == group.internal + group.external
    assert structure.mechanism_class == max(e[1] for e in expected)


def test_shaper_fields():
    link_names, joints, inputs, _ = MECHANISMS["shaper (seed 000)"]
    structure = decompose("0", link_names, joints, inputs)
    assert structure.input_links == ("1",)
    assert structure.input_mechanisms == (("0", "1"),)
    first, second = structure.groups
    assert first == AssurGroup(("2", "3"), ("Ap", "A", "C"), ("Ap",), ("A", "C"), 2, 2, "RPR",
                               inputs=(), attached_to=("0", "1"))
    assert second.attached_to == ("0", "3")
    assert first.label == "II(2,3)"


def test_input_links_and_actuator_groups():
    s = decompose("0", *MECHANISMS["five-bar with two ground inputs"][:3])
    assert s.input_links == ("1", "4")
    s = decompose("0", *MECHANISMS["five-bar with a crank and a motor between links 2 and 3"][:3])
    assert s.input_links == ("1",)
    assert s.groups[0].inputs == ("B",)
    s = decompose("0", *MECHANISMS["excavator: two hydraulic cylinders"][:3])
    assert s.input_links == () and s.mechanism_class == 2
    assert [g.inputs for g in s.groups] == [("Q1",), ("Q2",)]
    s = decompose("0", *MECHANISMS["actuator on an input link"][:3])
    assert s.input_links == ("1",)
    assert s.input_mechanisms == (("0", "1"), ("1", "2"))
    assert s.groups[0].attached_to == ("0", "2")


def test_structure_without_groups():
    s = decompose("0", ["1"], [("O", "R", "0", "1")], ["O"])
    assert (s.groups, s.mechanism_class, s.formula) == ((), 1, "I(0,1)")


def test_result_does_not_depend_on_the_order_of_the_table():
    link_names, joints, inputs, (_, _, formula, expected) = MECHANISMS["seed 002"]
    rng = random.Random(1)
    for _ in range(20):
        shuffled = joints[:]
        rng.shuffle(shuffled)
        s = decompose("0", link_names, shuffled, inputs)
        assert s.formula == formula
        assert [(set(g.internal), set(g.external), g.kind) for g in s.groups] == [
            (set(e[4]), set(e[5]), e[3]) for e in expected]


def test_roman_numerals():
    assert [roman(n) for n in (1, 2, 3, 4, 5, 6, 9, 10, 14, 40)] == \
        ["I", "II", "III", "IV", "V", "VI", "IX", "X", "XIV", "XL"]


# ---------------------------------------------------------------------------------------
# Errors
# ---------------------------------------------------------------------------------------

FOUR_BAR = [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("C", "R", "3", "0")]


def test_wrong_dof_names_the_dof_found():
    with pytest.raises(ModelError, match=r"DOF = .* = 1 .*n = 3 .*p = 4.*0 input"):
        decompose("0", links(3), FOUR_BAR, [])
    with pytest.raises(ModelError, match=r"= 1 .*2 input joint"):
        decompose("0", links(3), FOUR_BAR, ["O", "B"])


def test_link_not_connected_to_ground():
    with pytest.raises(ModelError, match=r"link 4 not connected to ground '0'"):
        decompose("0", links(4), FOUR_BAR, ["O"])
    joints = FOUR_BAR + [("X", "R", "4", "5")]
    with pytest.raises(ModelError, match=r"links 4, 5 not connected"):
        decompose("0", links(5), joints, ["O"])


def test_rigid_triangle_sub_chain_is_named():
    # Links 2, 3 pinned to ground and to each other, link 4 closes a triangle on them:
    # 3·3 = 9 < 2·5 = 10.  The DOF count balances only because link 5 hangs free on the crank.
    joints = [("O", "R", "0", "1"), ("P1", "R", "0", "2"), ("P2", "R", "0", "3"), ("T1", "R", "2", "3"),
              ("T2", "R", "3", "4"), ("T3", "R", "4", "2"), ("A", "R", "1", "5")]
    with pytest.raises(ModelError) as error:
        decompose("0", links(5), joints, ["O"])
    message = str(error.value)
    assert "over-constrained" in message and "links 2, 3, 4 " in message
    assert "9 < 2·p = 2·5 = 10" in message
    assert "link 5 " in message


def test_sub_chain_with_its_own_mobility_is_named():
    # A four-bar 2-3-4 on ground with no input; link 5 locks the crank in a triangle.
    joints = [("O", "R", "0", "1"), ("F1", "R", "0", "2"), ("F2", "R", "2", "3"), ("F3", "R", "3", "4"),
              ("F4", "R", "4", "0"), ("E", "R", "0", "5"), ("G", "R", "5", "1")]
    with pytest.raises(ModelError) as error:
        decompose("0", links(5), joints, ["O"])
    message = str(error.value)
    assert "links 2, 3, 4 with a mobility of their own" in message
    assert "cannot be decomposed" in message
    assert "link 5 with joints E, G" in message


def test_internally_over_constrained_pair_is_named():
    joints = [("O", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"), ("Bp", "P", "3", "2")]
    with pytest.raises(ModelError, match=r"links 2, 3 with joints B, Bp: 3·\(n − 1\) = 3 < 2·p = 4"):
        decompose("0", links(3), joints, ["O"])


@pytest.mark.parametrize("joints, inputs, message", [
    ([("O", "R", "0", "1"), ("A", "R", "1", "9")], ["O"], r"joint 'A' names unknown link '9'"),
    ([("O", "X", "0", "1")], ["O"], r"joint 'O': kind 'X'"),
    ([("O", "R", "0", "1"), ("O", "R", "1", "2")], ["O"], r"joint name\(s\) given more than once: O"),
    ([("O", "R", "1", "1")], ["O"], r"joint 'O' joins link '1' to itself"),
    ([("O", "R", "0", "1")], ["Z"], r"input 'Z' is not a joint"),
    ([("O", "R", "0", "1")], ["O", "O"], r"input name\(s\) given more than once"),
    ([("O", "R", "0", "1", "x")], ["O"], r"must be \(name, kind, link_a, link_b\)"),
])
def test_bad_tables(joints, inputs, message):
    with pytest.raises(ModelError, match=message):
        decompose("0", ["1", "2"], joints, inputs)


def test_duplicate_and_ground_link_names():
    with pytest.raises(ModelError, match=r"link name\(s\) given more than once: 1"):
        decompose("0", ["1", "1"], [], [])
    with pytest.raises(ModelError, match=r"link name\(s\) given more than once: 0"):
        decompose("0", ["0", "1"], [], [])


def test_input_loop():
    joints = [("O", "R", "0", "1"), ("O2", "R", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3"),
              ("C", "R", "3", "4")]
    with pytest.raises(ModelError, match=r"input joints O, O2 close a loop"):
        decompose("0", links(4), joints, ["O", "O2"])


def test_extra_pair_between_known_links():
    # the input crank is also held by a slider; the free chain 2-3 makes the DOF count balance
    joints = [("O", "R", "0", "1"), ("X", "P", "0", "1"), ("A", "R", "1", "2"), ("B", "R", "2", "3")]
    with pytest.raises(ModelError, match=r"joint 'X' joins links '0' and '1'.*over-constrained"):
        decompose("0", links(3), joints, ["O"])


def test_prismatic_contour():
    joints = [("O", "P", "0", "1"), ("A", "P", "1", "2"), ("B", "P", "2", "0")]
    with pytest.raises(ModelError, match=r"joints O, A, B form a closed contour of prismatic pairs"):
        decompose("0", links(2), joints, ["O"])


# ---------------------------------------------------------------------------------------
# Property: stacked dyads
# ---------------------------------------------------------------------------------------


@st.composite
def dyad_chains(draw):
    """A crank 1 and k dyads; dyad i = links (a_i, b_i), each pinned/slid to earlier links."""
    k = draw(st.integers(1, 12))
    link_names, joints, dyads = ["1"], [("O", "R", "0", "1")], []
    for i in range(k):
        earlier = ["0", *link_names]
        a, b = f"a{i}", f"b{i}"
        kinds = draw(st.tuples(*[st.sampled_from("RP")] * 3))
        ext_a, ext_b = draw(st.sampled_from(earlier)), draw(st.sampled_from(earlier))
        joints += [(f"E{i}", kinds[0], ext_a, a), (f"M{i}", kinds[1], a, b), (f"F{i}", kinds[2], b, ext_b)]
        link_names += [a, b]
        dyads.append(((a, b), kinds, set(earlier)))
    return link_names, joints, dyads


def has_prismatic_contour(joints):
    parent = {}

    def root(x):
        while parent.get(x, x) != x:
            x = parent[x]
        return x

    for _, kind, a, b in joints:
        if kind == "P":
            if root(a) == root(b):
                return True
            parent[root(a)] = root(b)
    return False


@settings(max_examples=150, deadline=None)
@given(dyad_chains(), st.randoms(use_true_random=False))
def test_stacked_dyads_decompose_into_the_same_dyads(chain, rnd):
    link_names, joints, dyads = chain
    assume(not has_prismatic_contour(joints))
    shuffled = joints[:]
    rnd.shuffle(shuffled)
    s = decompose("0", link_names, shuffled, ["O"])
    assert s.dof == 1 and s.input_links == ("1",)
    assert len(s.groups) == len(dyads)
    assert all(g.group_class == 2 and g.order == 2 and len(g.internal) == 1 for g in s.groups)
    expected = {frozenset(d[0]): "".join(d[1]) for d in dyads}
    assert {frozenset(g.links): g.kind for g in s.groups} == {
        links_: max(kind, kind[::-1]) for links_, kind in expected.items()}
    known = {"0", "1"}
    for group in s.groups:
        assert set(group.attached_to) <= known
        known |= set(group.links)
    assert known == {"0", *link_names}
    assert s.formula.startswith("I(0,1) → II(") and s.formula.count("II(") == len(dyads)


# ---------------------------------------------------------------------------------------
# Property: stacked groups of classes II, III and IV (exercises the incremental search)
# ---------------------------------------------------------------------------------------

# template: (class, number of links, internal pairs, links carrying the external pairs)
TEMPLATES = {
    "II": (2, 2, [(0, 1)], [0, 1]),
    "III": (3, 4, [(0, 2), (2, 1), (2, 3)], [0, 1, 3]),
    "IV": (4, 6, [(0, 1), (0, 2), (1, 3), (2, 3), (3, 4), (3, 5)], [0, 4, 5]),
}


def stack_groups(shapes, choose):
    """Crank 1, then groups of the given shapes; choose(earlier links) picks an attachment."""
    link_names, joints, groups = ["1"], [("O", "R", "0", "1")], []
    for i, shape in enumerate(shapes):
        group_class, size, internal, outer = TEMPLATES[shape]
        earlier = ["0", *link_names]
        names = [f"g{i}_{k}" for k in range(size)]
        joints += [(f"I{i}_{k}", "R", names[a], names[b]) for k, (a, b) in enumerate(internal)]
        joints += [(f"X{i}_{k}", "R", choose(earlier), names[a]) for k, a in enumerate(outer)]
        link_names += names
        groups.append((frozenset(names), group_class))
    return link_names, joints, groups


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from(sorted(TEMPLATES)), min_size=1, max_size=10), st.randoms(use_true_random=False))
def test_stacked_groups_of_mixed_classes(shapes, rnd):
    link_names, joints, groups = stack_groups(shapes, rnd.choice)
    rnd.shuffle(joints)
    s = decompose("0", link_names, joints, ["O"])
    assert {(frozenset(g.links), g.group_class) for g in s.groups} == set(groups)
    assert all(g.order == 3 for g in s.groups if g.group_class > 2)
    known = {"0", "1"}
    for group in s.groups:
        assert set(group.attached_to) <= known
        known |= set(group.links)


def test_long_chains_decompose():
    # each group hangs on the previous one (and the first on the crank and ground)
    for shape, count in (("II", 32), ("IV", 32), ("III", 16)):
        link_names, joints, groups = stack_groups([shape] * count, lambda earlier: earlier[-1])
        s = decompose("0", link_names, joints, ["O"])
        assert [(frozenset(g.links), g.group_class) for g in s.groups] == groups


def test_smaller_group_found_first_does_not_hide_a_pending_one():
    # After the class IV group, a dyad and a triad both hang on it: the dyad is found first,
    # the triad must still be found at the next stage (it became solvable with the IV group).
    link_names, joints, groups = stack_groups(["IV", "II", "III"], lambda earlier: earlier[-1])
    joints = [j if not j[0].startswith("X2_") else (j[0], j[1], "g0_5", j[3]) for j in joints]
    s = decompose("0", link_names, joints, ["O"])
    assert s.formula.split(" → ")[1:] == [
        "IV(g0_0,g0_1,g0_2,g0_3,g0_4,g0_5)", "II(g1_0,g1_1)", "III(g2_0,g2_1,g2_2,g2_3)"]


# ---------------------------------------------------------------------------------------
# The bundled models: `mbplanar info --json` against a hand-checked table
# ---------------------------------------------------------------------------------------

# model -> (dof, loops, mechanism class, formula, [(class, order, kind, links, internal, external)])
# Read off each model's table of pairs by hand (the textbook decomposition).
MODEL_STRUCTURES = {
    "fourbar": (1, 1, 2, "I(0,1) → II(2,3)", [(2, 2, "RRR", ["2", "3"], ["B"], ["A", "C"])]),
    "fourbar_design": (1, 1, 2, "I(0,1) → II(2,3)", [(2, 2, "RRR", ["2", "3"], ["B"], ["A", "C"])]),
    "five_bar": (2, 1, 2, "I(0,1) → I(0,4) → II(2,3)", [(2, 2, "RRR", ["2", "3"], ["P"], ["A", "B"])]),
    "fourbar_loaded": (1, 1, 2, "I(0,1) → II(2,3)", [(2, 2, "RRR", ["2", "3"], ["B"], ["A", "C"])]),
    "heavy_fourbar": (1, 1, 2, "I(0,1) → II(2,3)", [(2, 2, "RRR", ["2", "3"], ["B"], ["A", "C"])]),
    "slider_crank": (1, 1, 2, "I(0,1) → II(2,3)", [(2, 2, "RRP", ["2", "3"], ["B"], ["A", "Bp"])]),
    "crank_slider_rocker": (1, 2, 2, "I(0,1) → II(2,5) → II(3,4)", [
        (2, 2, "RRP", ["2", "5"], ["C5"], ["A", "Cp"]),
        (2, 2, "RRR", ["3", "4"], ["B"], ["C", "D"])]),
    "crank_slider_rocker_locking": (1, 2, 2, "I(0,1) → II(2,5) → II(3,4)", [
        (2, 2, "RRP", ["2", "5"], ["C5"], ["A", "Cp"]),
        (2, 2, "RRR", ["3", "4"], ["B"], ["C", "D"])]),
    "shaper": (1, 2, 2, "I(0,1) → II(2,3) → II(4,5)", [
        (2, 2, "RPR", ["2", "3"], ["Ap"], ["A", "C"]),
        (2, 2, "RPP", ["4", "5"], ["Dp"], ["D", "F"])]),
    "six_bar_press": (1, 2, 2, "I(0,1) → II(2,3) → II(4,5)", [
        (2, 2, "RRR", ["2", "3"], ["B"], ["A", "C"]),
        (2, 2, "RRP", ["4", "5"], ["H"], ["D", "Hp"])]),
    # triad: base link 4 carries B, C, E; rods 2 (to the crank pin A), 3 (to D), 5 (to F)
    "class3_triad": (1, 2, 3, "I(0,1) → III(2,3,4,5)", [
        (3, 3, None, ["2", "3", "4", "5"], ["B", "C", "E"], ["A", "D", "F"])]),
    # Jansen's leg: three RRR dyads, the last one driven by the first two (D on bde, C2 on c)
    "jansen": (1, 3, 2, "I(0,crank) → II(j,bde) → II(k,c) → II(f,ghi)", [
        (2, 2, "RRR", ["j", "bde"], ["B"], ["A1", "P1"]),
        (2, 2, "RRR", ["k", "c"], ["C1"], ["A2", "P2"]),
        (2, 2, "RRR", ["f", "ghi"], ["E"], ["C2", "D"])]),
    # seed 004: contour D–E–K–G of links 2, 3, 5, 4; rods 6, 7 to the ground pivots B, C
    "class4_group": (1, 3, 4, "I(0,1) → IV(2,3,4,5,6,7)", [
        (4, 3, None, ["2", "3", "4", "5", "6", "7"], ["D", "G", "E", "K", "F", "L"], ["A", "B", "C"])]),
    # Andrews' squeezer: three RRR dyads, each hung on rod 2's point E (three pairs at one place) and the frame
    "squeezer": (1, 3, 2, "I(0,1) → II(2,3) → II(4,5) → II(6,7)", [
        (2, 2, "RRR", ["2", "3"], ["E23"], ["F", "B"]),
        (2, 2, "RRR", ["4", "5"], ["G"], ["A5", "E24"]),
        (2, 2, "RRR", ["6", "7"], ["H"], ["A7", "E26"])]),
    # the higher pairs: each replaced by a link (its name primed) with two pairs at the contact's centres of
    # curvature (named pair:link): a roller on an eccentric is the four-bar O–E–B–C's dyad RRR, a
    # translating roller a slider-crank's RRP, a pin in an arc RRR, a pin in a straight slot RPP
    "cam_eccentric": (1, 1, 2, "I(0,cam) → II(arm,K')", [(2, 2, "RRR", ["arm", "K'"], ["K:arm"], ["C", "K:cam"])]),
    "cam_follower": (1, 1, 2, "I(0,cam) → II(f,K')", [(2, 2, "RRP", ["f", "K'"], ["K:f"], ["F", "K:cam"])]),
    "slot_arc": (1, 1, 2, "I(0,1) → II(2,S')", [(2, 2, "RRR", ["2", "S'"], ["S:2"], ["C", "S:1"])]),
    "scotch_yoke": (1, 1, 2, "I(0,1) → II(2,S')", [(2, 2, "RPP", ["2", "S'"], ["S:2"], ["Y", "S:1"])]),
    # gears: the pinion EB and the link of the mesh close the loop with the frame, then the couplers' dyad
    "geared_five_bar": (1, 2, 2, "I(0,1) → II(4,G') → II(2,3)", [
        (2, 2, "RRR", ["4", "G'"], ["G:4"], ["E", "G:1"]),
        (2, 2, "RRR", ["2", "3"], ["P"], ["A", "B"])]),
    # 2K-H: the planet is a base link with three pairs (its axle on the carrier, both meshes): class III
    "planetary": (1, 2, 3, "I(0,1) → III(2,H,G12',G23')", [
        (3, 3, None, ["2", "H", "G12'", "G23'"], ["O2", "G12:2", "G23:2"], ["OH", "G12:1", "G23:0"])]),
    # the rack is a slider-crank's slider; the pinion's group: its axle R, R on the pinion, P on the rack
    "rack_pinion": (1, 2, 2, "I(0,1) → II(2,3) → II(4,K')", [
        (2, 2, "RRP", ["2", "3"], ["B"], ["A", "Bp"]),
        (2, 2, "RRP", ["4", "K'"], ["K:4"], ["Q", "K:3"])]),
    # the shaper's two dyads, and a dyad per mesh down the train from the crank to the motor
    "shaper_geared": (1, 5, 2, "I(0,1) → II(2,3) → II(i2,G56') → II(4,5) → II(i1,G34') → II(m,G12')", [
        (2, 2, "RPR", ["2", "3"], ["Ap"], ["A", "C"]),
        (2, 2, "RRR", ["i2", "G56'"], ["G56:i2"], ["Oi2", "G56:1"]),
        (2, 2, "RPP", ["4", "5"], ["Dp"], ["D", "F"]),
        (2, 2, "RRR", ["i1", "G34'"], ["G34:i1"], ["Oi1", "G34:i2"]),
        (2, 2, "RRR", ["m", "G12'"], ["G12:m"], ["Om", "G12:i1"])]),
}


def test_every_bundled_model_is_in_the_table():
    assert set(MODEL_STRUCTURES) == {path.stem for path in linkage_models()}


@pytest.mark.parametrize("name", sorted(MODEL_STRUCTURES))
def test_info_json_of_every_model_matches_the_hand_checked_table(name, capsys):
    assert main(["info", str(MODELS / f"{name}.toml"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    dof, loops, mechanism_class, formula, groups = MODEL_STRUCTURES[name]
    assert (doc["dof"], doc["loops"], doc["mechanism_class"], doc["formula"]) == (dof, loops, mechanism_class, formula)
    got = [(g["class"], g["order"], g["kind"], g["links"], g["joints"], g["external"]) for g in doc["groups"]]
    assert got == [(c, o, k, links_, internal + external, external)
                   for c, o, k, links_, internal, external in groups]


# ---------------------------------------------------------------------------------------
# Group-by-group solving = the global Newton on all loops
# ---------------------------------------------------------------------------------------


# Both solutions stop once every closure residual is below solver.TOL = 1e-13 (relative to the size), and
# positions already below it are polished to 1e-14 while others iterate, so they agree to 1e-12·(1 + size).


def _compare_grouped_with_global(grouped, whole, phi, position_tol=1e-12):
    a, b = mbplanar.analyse(grouped, phi), mbplanar.analyse(whole, phi)
    common, ia, ib = np.intersect1d(a.phi[:, 0], b.phi[:, 0], return_indices=True)
    assert len(common) >= min(len(a.phi), len(b.phi)) - 1 and len(common) > 0
    assert np.abs(a.xy[ia] - b.xy[ib]).max() < position_tol * (1 + grouped.size)
    va, vb, aa, ab = (a.vq, b.vq, a.aq, b.aq) if a.vq is not None else (a.v, b.v, a.a, b.a)  # several inputs
    assert np.abs(va[ia] - vb[ib]).max() < 1e-9 * (1 + np.abs(va[ia]).max())
    assert np.abs(aa[ia] - ab[ib]).max() < 1e-9 * (1 + np.abs(aa[ia]).max())
    return a


@pytest.mark.parametrize("name", sorted(MODEL_STRUCTURES))
def test_group_by_group_equals_global_newton_on_every_model(name):
    # fresh engines: the walk over ±180° would leave limits in the atlas of the shared `engine_of` ones
    grouped = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"))
    whole = mbplanar.Engine(mbplanar.read_model(MODELS / f"{name}.toml"), grouped=False)
    assert sum(bp.m > 0 for bp in whole.blocks) == 1
    assert sum(bp.m > 0 for bp in grouped.blocks) == len(MODEL_STRUCTURES[name][4])
    # several inputs: every input along the same path (the five-bar's cranks turn together)
    phi = grouped.phi_drawn[None, :] + np.radians(np.arange(-180.0, 180.0, 2.0))[:, None]
    _compare_grouped_with_global(grouped, whole, phi if len(grouped.inputs) > 1 else phi[:, 0])


def test_class4_chain_is_solved_group_by_group_as_the_global_newton_does():
    grouped, whole = mbplanar.Engine(class4_chain(3)), mbplanar.Engine(class4_chain(3), grouped=False)
    assert [g.group_class for g in grouped.topology.structure.groups] == [4, 4, 4]
    assert [bp.m for bp in grouped.blocks if bp.m] == [6, 6, 6]
    assert [bp.m for bp in whole.blocks if bp.m] == [18]
    phi = grouped.phi_drawn[0] + np.radians(np.arange(0.0, 360.0, 3.0))
    motion = _compare_grouped_with_global(grouped, whole, phi)
    assert motion.success and math.isclose(grouped.phi_drawn[0], math.radians(30.0))
