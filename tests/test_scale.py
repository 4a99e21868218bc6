"""Scale: every model, scaled by 1e-12 or 1e12 (and 1e±90), gives the same dimensionless answers
(positions / size, angles, analogues / size); sizes beyond 1e±100 m are refused as out of range."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import mbplanar
from mbplanar.errors import ModelError

MODELS = sorted(Path(__file__).resolve().parent.parent.joinpath("models").glob("*.toml"))
# six_bar_press's rocker is a straight triangle (B the midpoint of CD): the sketch fixes B's place on it
# only to √(assembly tolerance), ~1e-8 of the size, at any scale (scaled by 1.1 it moves as much)
# cam_follower's profile is a spline through 1440 points: its contact parameter, settled to the closure
# tolerance, moves the accelerations by ~2e-11 of their size (the spline's third derivative), and at its
# 300 rpm they are ~1000 sizes/s² where the check below allows 10·TOL sizes/s²
TOL = {"six_bar_press.toml": 1e-6, "cam_follower.toml": 1e-8}


def _scaled(mech, k):
    """The model with every length multiplied by k (joints, points, link lengths, the higher pairs' places,
    radii and curves)."""
    def xy(at):
        return None if at is None else (at[0] * k, at[1] * k)

    def times(v):
        return None if v is None else v * k

    def pair(h):
        c = h.curve
        if c is not None:
            c = dataclasses.replace(c, centre=xy(c.centre), radius=times(c.radius), points=tuple(map(xy, c.points)))
        return dataclasses.replace(h, at=xy(h.at), radii=None if h.radii is None else tuple(map(times, h.radii)),
                                   module=times(h.module), radius=h.radius * k, curve=c)
    return dataclasses.replace(
        mech,
        joints={n: dataclasses.replace(j, at=xy(j.at)) for n, j in mech.joints.items()},
        points={n: dataclasses.replace(p, at=xy(p.at), distance=None if p.distance is None else p.distance * k,
                                       offset=p.offset * k) for n, p in mech.points.items()},
        links={n: dataclasses.replace(lk, lengths=tuple((a, b, v * k) for a, b, v in lk.lengths))
               for n, lk in mech.links.items()},
        higher={n: pair(h) for n, h in mech.higher.items()})


def _linkage_with_revolute_inputs(path) -> bool:
    """A linkage model (not a cam) whose inputs are all revolute."""
    try:
        mech = mbplanar.read_model(path)
    except ModelError:
        return False
    return all(mech.joints[i.joint].kind == "R" for i in mech.inputs)


@pytest.mark.parametrize("path", [p for p in MODELS if _linkage_with_revolute_inputs(p)],
                         ids=lambda p: p.name)
@pytest.mark.parametrize("k", [1e-12, 1e12, 1e-90, 1e90])
def test_scaled_model_gives_the_same_dimensionless_answers(path, k):
    mech = mbplanar.read_model(path)
    ref_engine = mbplanar.Engine(mech)
    engine = mbplanar.Engine(_scaled(mech, k))
    n_in = len(mech.inputs)
    phi = ref_engine.phi_drawn[None, :] + np.linspace(0.0, 0.5, 4)[:, None] if n_in > 1 else \
        ref_engine.phi_drawn[0] + np.linspace(0.0, 0.5, 4)
    ref, got = mbplanar.analyse(ref_engine, phi), mbplanar.analyse(engine, phi)
    assert got.success and ref.success
    tol = TOL.get(path.name, 1e-12)
    size = ref_engine.size
    assert engine.size == pytest.approx(size * k, rel=tol)
    assert np.abs(got.xy / k - ref.xy).max() <= tol * size
    assert np.abs(got.angle - ref.angle).max() <= tol
    assert np.abs(got.w - ref.w).max() <= tol * (1 + np.abs(ref.w).max())
    assert np.abs(got.v / k - ref.v).max() <= tol * size * (1 + np.abs(ref.w).max())
    assert np.abs(got.a / k - ref.a).max() <= 10 * tol * size * (1 + np.abs(ref.e).max())


@pytest.mark.parametrize("k", [1e-300, 1e300])
def test_scale_out_of_range_is_refused(k):
    mech = mbplanar.read_model(next(p for p in MODELS if _linkage_with_revolute_inputs(p)))
    with pytest.raises(ModelError, match="scale out of range"):
        mbplanar.Engine(_scaled(mech, k))
