"""Motion generation (Burmester): poses of a known four-bar's coupler, solved for 2-5 poses; every
solution analysed by mbplanar passes through its poses to 1e-9."""

import itertools
import math

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import ModelError
from mbplanar.synthesis.burmester import (_det4, burmester_points, centre_point_curve, pole,
                                          synthesise_motion)

ENGINE = mbplanar.Engine(mbplanar.read_model("models/fourbar.toml"))
_M = mbplanar.analyse(ENGINE, np.radians([10, 50, 90, 130, 170]))
A, B, M = (_M.xy[:, _M.point(n)] for n in ("A", "B", "M"))
POSES = np.column_stack([M, np.arctan2(B[:, 1] - A[:, 1], B[:, 0] - A[:, 0])])
O, C = np.array([0.0, 0.0]), np.array([0.3, 0.0])


def _through_poses(r, poses):
    """The model read back from its text passes through every pose (point and angle) to 1e-9."""
    engine = mbplanar.Engine(mbplanar.parse_model(r.toml))
    m = mbplanar.analyse(engine, r.crank_phi)
    assert len(m.phi) == len(poses)
    p, q = m.xy[:, m.point("P")], m.xy[:, m.point("Q")]
    assert np.max(np.hypot(*(p - poses[:, :2]).T)) < 1e-9
    ang = np.arctan2(q[:, 1] - p[:, 1], q[:, 0] - p[:, 0])
    assert np.max(np.abs(np.remainder(ang - poses[:, 2] + math.pi, 2 * math.pi) - math.pi)) < 1e-9
    assert np.max(r.pose_errors) < 1e-9 and np.max(np.radians(r.angle_errors_deg)) < 1e-9


def test_two_poses_with_hints():
    r = synthesise_motion(POSES[:2], circle_points=[A[0], B[0]], centre_points=[[0.01, 0.02], [0.3, 0.01]])
    _through_poses(r, POSES[:2])


def test_three_poses_recover_the_original_pivots():
    r = synthesise_motion(POSES[:3], circle_points=[A[0], B[0]])
    np.testing.assert_allclose(r.dyads[0].centre, O, atol=1e-12)
    np.testing.assert_allclose(r.dyads[1].centre, C, atol=1e-12)
    _through_poses(r, POSES[:3])


def test_three_poses_from_centre_points():
    r = synthesise_motion(POSES[:3], centre_points=[O, C])
    np.testing.assert_allclose(r.dyads[0].circle, A[0], atol=1e-12)
    _through_poses(r, POSES[:3])


def test_four_poses_curve_holds_the_poles_and_the_original_pivots():
    poses = POSES[:4]
    curve = centre_point_curve(poses)
    c = curve["centre"].reshape(-1, 2)
    c = c[np.isfinite(c).all(1)]
    scale = np.max(np.abs(_det4(poses, c + 0.05)))
    assert np.max(np.abs(_det4(poses, c))) < 1e-9 * scale          # on the cubic
    for i, j in itertools.combinations(range(4), 2):                # the six poles are on it too
        assert abs(_det4(poses, pole(poses, i, j))) < 1e-9 * scale
    assert abs(_det4(poses, O)) < 1e-9 * scale and abs(_det4(poses, C)) < 1e-9 * scale
    r = synthesise_motion(poses, centre_points=[O, C])         # hints on the curve: the pivots back
    np.testing.assert_allclose(r.dyads[0].centre, O, atol=1e-7)
    np.testing.assert_allclose(r.dyads[1].centre, C, atol=1e-7)
    _through_poses(r, poses)
    r = synthesise_motion(poses, centre_points=[[0.01, 0.01], [0.29, 0.01]])   # the nearest curve points
    _through_poses(r, poses)


def test_four_poses_automatic():
    r = synthesise_motion(POSES[:4])
    assert r.defects.ok
    _through_poses(r, POSES[:4])


def test_five_poses_burmester_points_include_the_pivots():
    pts = burmester_points(POSES)
    centres = np.array([m for m, _ in pts])
    assert 2 <= len(pts) <= 4
    for pivot in (O, C):
        assert np.min(np.hypot(*(centres - pivot).T)) < 1e-9
    r = synthesise_motion(POSES)
    _through_poses(r, POSES)


def test_bad_poses_are_clear_errors():
    with pytest.raises(ModelError, match="2 to 5 poses"):
        synthesise_motion(POSES[:1])
    with pytest.raises(ModelError, match="2 to 5 poses"):
        synthesise_motion(np.vstack([POSES, POSES[:1] + 0.1]))
    with pytest.raises(ModelError, match="inconsistent poses"):
        synthesise_motion(np.vstack([POSES[:2], POSES[:1]]), circle_points=[A[0], B[0]])
    with pytest.raises(ModelError, match="centre-point hint"):
        synthesise_motion(POSES[:2], circle_points=[A[0], B[0]])
    translated = np.column_stack([POSES[:4, :2], np.zeros(4)])
    with pytest.raises(ModelError, match="pure translations"):
        synthesise_motion(translated)


_S = mbplanar.analyse(mbplanar.Engine(mbplanar.read_model("models/slider_crank.toml")), np.radians([10, 60, 110, 160, 210]))
SA, SB = (_S.xy[:, _S.point(n)] for n in ("A", "B"))
SLIDER_POSES = np.column_stack([0.5 * (SA + SB), np.arctan2(SB[:, 1] - SA[:, 1], SB[:, 0] - SA[:, 0])])


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_crank_and_slider_through_the_poses(n):
    """Poses of the slider-crank's rod: a crank and a slider dyad; 4 and 5 poses find the slider point."""
    poses = SLIDER_POSES[:n]
    if n == 2:
        r = synthesise_motion(poses, circle_points=[SA[0]], centre_points=[[0.001, 0.001]], slider_points=[SB[0]])
    elif n == 3:
        other = synthesise_motion(poses, circle_points=[SA[0]], slider_points=[SB[0] + 0.01])
        _through_poses(other, poses)                                  # another point of the slider circle
        assert abs(other.dyads[1].direction[1]) > 1e-6
        r = synthesise_motion(poses, circle_points=[SA[0]], slider_points=[SB[0]])
    else:
        r = synthesise_motion(poses, slider_points=[SB[0]])
        np.testing.assert_allclose(r.dyads[1].point, SB[0], atol=1e-9)
    assert abs(r.dyads[1].direction[1]) < 1e-9                      # the guide is the x axis
    _through_poses(r, poses)


def test_slider_point_that_is_not_one_is_refused():
    from mbplanar.synthesis.burmester import slider_dyad
    with pytest.raises(ModelError, match="not in line"):
        slider_dyad(SLIDER_POSES[:3], SA[0])


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from mbplanar.synthesis.burmester import dyad_from_centre_point, dyad_from_circle_point, positions, to_body  # noqa: E402


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=9, max_size=9), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_three_pose_dyads_are_equidistant_and_invert(raw, zx, zy):
    """For any 3 poses and circle point, the centre is equally far from its three positions, and the
    centre's own circle point is the one we started from."""
    poses = np.array(raw).reshape(3, 3) * [1.0, 1.0, 2.0]
    z = np.array([zx, zy])
    try:
        d = dyad_from_circle_point(poses, z)
        back = dyad_from_centre_point(poses, d.centre)
    except ModelError:
        return                                        # a degenerate draw (collinear positions, a pole)
    r = np.hypot(*(positions(poses, to_body(poses, z)) - d.centre).T)
    if np.max(r) > 1e6:
        return
    assert np.ptp(r) <= 1e-9 * max(1.0, np.max(r)) ** 2
    np.testing.assert_allclose(back.circle, z, atol=1e-7 * max(1.0, np.max(r)) ** 2)
