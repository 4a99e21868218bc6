"""Synthesis of planar linkages; every design comes back as an mbplanar model checked by mbplanar.

* `synthesise_seed001`: seed 001's guiding crank-slider for a walking foot (forms (a), (b), (c) of its
  interpolation method, the seed's objective Δ = Δ1 + Δ2);
* `synthesise_function` / `synthesise_angle_pairs`: four-bar function generation (Freudenstein);
* `synthesise_motion`: four-bar motion generation through 2–5 poses (Burmester), with
  `centre_point_curve` and `burmester_points`;
* `check_defects`: circuit, branch and order defects of any design, by mbplanar's engine;
* `synthesise_path`: a four-bar coupler curve through untimed or timed target points, by default within
  the designer's bounds (`path.DESIGNER`: a full turn, transmission angle ≥ 30°, link ratio ≤ 10; any
  `PathConstraints`): a screen of crank-rocker shapes placed on the targets in closed form and a
  least-squares polish, seeded, serial or on Dask, within a time budget if asked; targets met a hair out
  of order, or bounds no design meets, come back as warnings with the best design;
* `synthesise_model_path`: the same on any model's named parameters, by the study's design batch;
* `fourbar_coupler_paths`, `path_errors`: batches of four-bar designs (D, 10) scored at once.

Each result carries the model's TOML text (`toml`), the `Mechanism` read back from it, and errors that
mbplanar's analysis of that model gives; `table_toml` writes any model's table as TOML text (the
importers of `mbplanar.formats` use it). Each name is imported on first use. Nothing below
`mbplanar.formats` imports this package.
"""

from .._lazy import lazy_attributes

_HOME = {"fourbar_coupler_paths": "batch", "path_errors": "batch", "Dyad": "burmester", "MotionResult": "burmester",
         "SliderDyad": "burmester", "burmester_points": "burmester", "centre_point_curve": "burmester",
         "slider_points": "burmester", "synthesise_motion": "burmester", "Defects": "defects",
         "check_defects": "defects", "FunctionResult": "freudenstein", "FunctionTask": "freudenstein",
         "freudenstein_coefficients": "freudenstein", "synthesise_angle_pairs": "freudenstein",
         "synthesise_function": "freudenstein", "SEED001_CHAIN": "guiding", "Candidates": "guiding",
         "Chain": "guiding", "WalkingTarget": "guiding", "chebyshev_nodes": "guiding", "foot_paths": "guiding",
         "PathConstraints": "constraints", "PathResult": "path", "synthesise_path": "path",
         "ModelPathResult": "path_model", "synthesise_model_path": "path_model", "GuidingResult": "seed001",
         "synthesise_seed001": "seed001", "table_toml": "_models"}

__all__ = ["synthesise_seed001", "GuidingResult", "Chain", "SEED001_CHAIN", "WalkingTarget", "Candidates",
           "chebyshev_nodes", "foot_paths", "synthesise_function", "synthesise_angle_pairs", "FunctionTask",
           "FunctionResult", "freudenstein_coefficients", "synthesise_motion", "MotionResult", "Dyad",
           "centre_point_curve", "burmester_points", "SliderDyad", "slider_points", "check_defects", "Defects",
           "fourbar_coupler_paths", "path_errors", "synthesise_path", "PathResult", "PathConstraints",
           "synthesise_model_path", "ModelPathResult", "table_toml"]


__getattr__, __dir__ = lazy_attributes(__name__, _HOME)
