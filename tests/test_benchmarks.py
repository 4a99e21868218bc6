"""The benchmark's verdict on issue 7's targets (`benchmarks/run.py`, `check_targets`): every target is
read from the cases it names and compared with its limit; a missing case is a miss, never a pass."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
import run  # noqa: E402


def case(name, work, us, n=3600, closed=None, **extra):
    return dict(name=name, work=work, n=n, mbplanar_us=us, closed_form_us=closed, fsolve_us=None, **extra)


def test_targets_read_their_cases_and_limits():
    cases = [case("fourbar", "kinematics", 0.8, closed=0.2), case("shaper", "reactions", 1.4),
             case("six_bar_press", "reactions", 1.6), case("class4_group", "reactions", 2.9),
             case("fourbar", "one position", 40.0, n=1), case("shaper", "one position", 55.0, n=1),
             case("shaper", "mbplanar solve (CLI, end to end)", 4.2e5, n=1),
             case("shaper", "kinematics, scaling in N", 1.0, n=10 ** 6, peak_MB=1500.0)]
    best = run.BEST
    verdict = {t["target"]: t for t in run.check_targets(cases, {best: 0.9}, {best: 1.2})}
    met = {name: t["met"] for name, t in verdict.items()}
    assert verdict["four-bar kinematics / closed form"]["value"] == 4.0
    assert met == {"four-bar kinematics / closed form": True, "shaper with reactions, µs/position": True,
                   "six-bar press with reactions, µs/position": False,
                   "class IV model with reactions, µs/position": True,
                   "one position, worst of three models, µs": False, "mbplanar solve end to end, s": True,
                   "shaper sweep of 1000000 positions, peak MB": True,
                   "time per position vs chained dyads, exponent": True,
                   "time per position vs chained class IV groups, exponent": False}


def test_a_missing_case_is_a_miss():
    verdict = run.check_targets([], None, None)
    assert len(verdict) == 9 and not any(t["met"] for t in verdict)
    assert all(t["value"] is None for t in verdict)
