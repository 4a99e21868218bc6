"""Results of every bundled model on both backends, saved once and compared later: a refactoring that
must not change an answer (the records, the dispatch seam, the kernels' named bundles) is held to the
numbers the code gave before it, bit for bit where it claims to be.

    python tests/same_results.py save DIR      # with the code before the change
    python tests/same_results.py compare DIR   # with the code after it: every difference, largest first

Saved per model and backend (`Engine(threads=1)`): `analyse` of the model's default sweep (every field,
the link frames, limits and change points), the same with ``rates=False`` and for two points only,
`position` at three input values, `kinetostatics` where the model has loads or masses, `check`,
`machine_dynamics` where the model has a ``[dynamics]`` section, and a design batch of the variants of
``models/crank_slider_rocker_variants.csv``. Values are read through public attributes only, so the
same script reads the code before and after. `compare` exits 1 when a value differs by more than
``--tol`` (default 0: bit for bit; NaN equals NaN) and prints the differences found either way.
"""

from __future__ import annotations

import argparse
import math
import sys
import tomllib
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
MODELS = ROOT / "models"

MOTION = ("phi", "omega", "epsilon", "angle", "w", "e", "xy", "v", "a", "value", "rate", "accel", "ic",
          "wq", "eq", "vq", "aq", "rate_q", "accel_q")
FRAMES = ("th", "r", "w", "v", "e", "a", "contact")
POSITION = MOTION
DYNAMICS = ("phi", "A_c", "driving_moment", "inertia_first_group", "dT_I_max", "dT_I_min", "phi_dT_max",
            "phi_dT_min", "J_II", "dJ_II", "M_red", "omega_mean", "resistance_work", "input_link_inertia",
            "A_total", "T_II", "dT_I", "omega", "epsilon", "omega_min", "omega_max", "epsilon_min", "epsilon_max")


def flat(prefix: str, value, out: dict) -> None:
    """`value` (array, number, string, dict, list, record) into `out` under keys starting with `prefix`."""
    if value is None:
        out[prefix] = np.array("None")
    elif isinstance(value, (str, bool, np.bool_)):
        out[prefix] = np.array(str(value))
    elif isinstance(value, (int, float, np.number)):
        out[prefix] = np.asarray(float(value))
    elif isinstance(value, np.ndarray):
        if value.dtype.names:
            for name in value.dtype.names:
                flat(f"{prefix}.{name}", value[name], out)
        else:
            out[prefix] = np.array(value, float if value.dtype.kind in "biuf" else object)
    elif isinstance(value, dict):
        for k, v in value.items():
            flat(f"{prefix}.{k}", v, out)
    elif isinstance(value, (list, tuple)):
        if all(isinstance(v, (int, float, np.number)) for v in value):
            out[prefix] = np.array(value, float)
        else:
            for k, v in enumerate(value):
                flat(f"{prefix}[{k}]", v, out)
    elif hasattr(value, "__dataclass_fields__"):
        for name in value.__dataclass_fields__:
            if name in ("engine", "motion", "solver", "rows", "records", "refill", "layout", "limit"):
                continue
            flat(f"{prefix}.{name}", getattr(value, name), out)
    else:
        out[prefix] = np.array(repr(value))


def frames_of(motion) -> dict:
    f = motion.frames
    if f is None:
        return {}
    get = (lambda n: f.get(n)) if isinstance(f, dict) else (lambda n: getattr(f, n, None))
    return {n: get(n) for n in FRAMES if get(n) is not None}


def motion_values(prefix: str, m, out: dict) -> None:
    for name in MOTION:
        try:
            value = getattr(m, name)
        except AttributeError:  # (rates not computed, before the records: RatesNotComputed)
            value = None
        flat(f"{prefix}.{name}", value, out)
    flat(f"{prefix}.frames", frames_of(m), out)
    flat(f"{prefix}.limits", [(float(lim.phi[0]), lim.direction, lim.kind) for lim in m.limits], out)
    flat(f"{prefix}.crossings", [(float(c.phi[0]), c.kind) for c in m.crossings], out)
    flat(f"{prefix}.success", m.success, out)
    flat(f"{prefix}.message", m.message, out)
    flat(f"{prefix}.names", [list(m.link_names), list(m.point_names), list(m.joint_names)], out)


def sweep_of(engine) -> np.ndarray:
    """The model's default sweep of its first input, 721 positions (SI)."""
    inp = engine.inputs[0]
    lo, hi = inp.default_sweep()[:2]
    lo, hi = float(lo), float(hi)
    return inp.to_si(np.linspace(lo, hi, 721))


def collect(backend: str) -> dict:
    import mbplanar
    out = {}
    for path in sorted(MODELS.glob("*.toml")):
        if "joints" not in tomllib.loads(path.read_text(encoding="utf-8")):
            continue
        name = path.stem
        mech = mbplanar.read_model(path)
        engine = mbplanar.Engine(mech, backend=backend, threads=1)
        key = f"{name}.{backend}"
        n_in = len(engine.inputs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if n_in == 1:
                phi = sweep_of(engine)
                m = mbplanar.analyse(engine, phi, None, -0.7)
                motion_values(f"{key}.sweep", m, out)
                motion_values(f"{key}.positions", mbplanar.analyse(engine, phi, rates=False), out)
                names = list(m.point_names)[-2:]
                motion_values(f"{key}.points", mbplanar.analyse(engine, phi, 2.5, points=names), out)
                for k, x in enumerate(phi[[100, 333, 600]]):
                    try:
                        p = mbplanar.position(engine, float(x))
                    except mbplanar.MotionError as exc:
                        flat(f"{key}.position{k}", str(exc), out)
                        continue
                    for field in POSITION:
                        flat(f"{key}.position{k}.{field}", getattr(p, field), out)
                if mech.loads or any(lk.mass or lk.inertia for lk in mech.links.values()):
                    ks = mbplanar.kinetostatics(engine, m)
                    for j, r in ks.reactions.items():
                        flat(f"{key}.forces.{j}", [r.fx, r.fy, r.moment], out)
                    flat(f"{key}.forces.balancing", ks.balancing, out)
                    flat(f"{key}.forces.residual", ks.virtual_power_residual, out)
                    flat(f"{key}.forces.singular", ks.singular, out)
                    flat(f"{key}.forces.success", ks.success, out)
                    flat(f"{key}.forces.contact", getattr(ks, "contact_forces", {}), out)
                try:
                    flat(f"{key}.check", mbplanar.check(engine).as_dict(), out)
                except mbplanar.MbplanarError as exc:
                    flat(f"{key}.check", str(exc), out)
                if mech.dynamics is not None:
                    dyn = mbplanar.machine_dynamics(engine, steps=720)
                    for field in DYNAMICS:
                        flat(f"{key}.dynamics.{field}", getattr(dyn, field), out)
                    flat(f"{key}.dynamics.flywheel", dyn.flywheel, out)
                    if dyn.simulation is not None:
                        flat(f"{key}.dynamics.simulation", dyn.simulation, out)
            else:
                x0 = engine.phi_drawn
                phi = x0[None, :] + np.linspace(0, 0.3, 50)[:, None] * np.arange(1, n_in + 1)[None, :]
                motion_values(f"{key}.sweep", mbplanar.analyse(engine, phi), out)
                p = mbplanar.position(engine, x0 + 0.1)
                for field in POSITION:
                    flat(f"{key}.position0.{field}", getattr(p, field), out)
    from mbplanar.study import design_batch
    batch = design_batch(MODELS / "crank_slider_rocker.toml", str(MODELS / "crank_slider_rocker_variants.csv"),
                         backend=backend)
    dm = batch.solve(np.radians(np.arange(0.0, 360.0, 2.0)))
    for field in ("phi", "valid", "ok", "reasons", "angle", "wq", "eq", "xy", "vq", "aq"):
        flat(f"design.{backend}.{field}", getattr(dm, field), out)
    flat(f"design.{backend}.limits", [(lim.design, lim.phi, lim.direction, lim.kind) for lim in dm.limits], out)
    return out


def differences(old: dict, new: dict):
    """(key, size of the difference) of every value that differs, largest first (inf: not comparable)."""
    found = []
    for key in sorted(set(old) | set(new)):
        if key not in old or key not in new:
            found.append((key, math.inf, "only before" if key in old else "only after"))
            continue
        a, b = old[key], new[key]
        if a.dtype.kind in "fc" and b.dtype.kind in "fc":
            if a.shape != b.shape:
                found.append((key, math.inf, f"shape {a.shape} → {b.shape}"))
                continue
            same_nan = np.isnan(a) & np.isnan(b)
            diff = np.where(same_nan, 0.0, np.abs(a - b))
            scale = np.maximum(1.0, np.abs(a))
            worst = float(np.nanmax(np.where(np.isnan(diff), np.inf, diff / scale), initial=0.0))
            if worst > 0:
                found.append((key, worst, ""))
        elif a.shape != b.shape or not np.array_equal(a.astype(str), b.astype(str)):
            found.append((key, math.inf, f"{a!r} → {b!r}"[:300]))
    return sorted(found, key=lambda f: -f[1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("action", choices=["save", "compare"])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--tol", type=float, default=0.0, help="largest relative difference allowed (default 0)")
    ap.add_argument("--backend", action="append", help="numpy, numba (default both)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    backends = args.backend or ["numpy", "numba"]
    new = {}
    for b in backends:
        new.update(collect(b))
    args.folder.mkdir(parents=True, exist_ok=True)
    if args.action == "save":
        for b in backends:
            np.savez_compressed(args.folder / f"{b}.npz", **{k: v for k, v in new.items() if f".{b}." in k})
        print(f"saved {len(new)} values to {args.folder}")
        return 0
    old = {}
    for b in backends:
        with np.load(args.folder / f"{b}.npz", allow_pickle=True) as f:
            old.update({k: f[k] for k in f.files})
    found = differences(old, new)
    bad = [f for f in found if f[1] > args.tol]
    new_only = [f for f in found if f[2] == "only after"]
    shown = [f for f in found if f[2] != "only after"][:60]
    for key, size, note in shown:
        print(f"{'FAIL' if size > args.tol else 'ok  '} {size:.3g} {key} {note}")
    if new_only:
        print(f"{len(new_only)} values only after (new results): {', '.join(k for k, _, _ in new_only[:8])}"
              f"{', ...' if len(new_only) > 8 else ''}")
    bad = [f for f in bad if f[2] != "only after"]
    print(f"{len(old)} values before, {len(new)} after; {len(found)} differ, {len(bad)} by more than {args.tol:g}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
