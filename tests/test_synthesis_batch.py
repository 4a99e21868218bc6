"""Batched four-bar coupler curves agree with mbplanar's analysis of each design's model."""

import numpy as np

import mbplanar
from mbplanar.synthesis.batch import design_toml, fourbar_coupler_paths, path_errors


def test_batch_curves_match_mbplanar_models():
    rng = np.random.default_rng(7)
    designs = np.column_stack([rng.uniform(-0.1, 0.1, (6, 2)), rng.uniform(0.9, 1.1, 6), rng.uniform(-0.1, 0.1, 6),
                               rng.uniform(0.15, 0.25, 6), rng.uniform(0.9, 1.2, 6), rng.uniform(0.9, 1.2, 6),
                               rng.uniform(-0.5, 0.5, (6, 2)), rng.choice([-1.0, 1.0], 6)])
    phi = np.radians(np.arange(0, 360, 30.0))
    _, _, p, ok = fourbar_coupler_paths(designs, phi)
    assert ok.all()                                       # Grashof crank-rockers: every sample closes
    for k, d in enumerate(designs):
        engine = mbplanar.Engine(mbplanar.parse_model(design_toml(d)))
        m = mbplanar.analyse(engine, phi)
        np.testing.assert_allclose(m.xy[:, m.point("P")], p[k], atol=1e-12)
    rms, mx = path_errors(p, ok, p[0, ::3])
    assert rms[0] == 0 and mx[0] == 0 and np.all(rms[1:] > 0)
