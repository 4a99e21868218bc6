"""Results as pandas DataFrames, with the columns of the CSV tables (`mbplanar sweep`, `mbplanar dynamics -o`).

pandas is an optional extra (``pip install mbplanar[pandas]``), imported only here, when a frame is asked for.
The result types reach these functions through `to_frame()` (see `mbplanar.model._views`).
"""

from __future__ import annotations

import numpy as np

from ..errors import MbplanarError
from ._tables import dynamics_table, forces_columns, sweep_table

__all__ = ["frame", "motion_frame", "kinetostatics_frame", "dynamics_frame", "VIEWS"]


def frame(header, columns):
    """A pandas DataFrame of a table (`header` names, `columns` (B, k)); a clear error without pandas."""
    try:
        import pandas as pd
    except ImportError:
        raise MbplanarError("DataFrames need pandas: pip install mbplanar[pandas]") from None
    columns = np.asarray(columns, float).reshape(-1, len(header))
    return pd.DataFrame(columns, columns=list(header))


def motion_frame(motion, engine=None):
    """The sweep table of a `Motion` (the columns of `mbplanar sweep` without forces), one row per position."""
    from ._export import engine_for
    engine = engine_for(motion, engine)
    unit = "rad" if engine.inputs[0].unit == "rad" else "deg"
    return frame(*sweep_table(engine, motion, unit))


def kinetostatics_frame(result, engine=None):
    """The force columns of `mbplanar sweep` for a `Kinetostatics`, with the input column first."""
    from ._export import engine_for
    engine = engine_for(result, engine)
    inp = engine.inputs[0]
    header, cols = forces_columns(engine, result)
    header = [f"{inp.name}[{inp.unit}]"] + header
    return frame(header, np.column_stack([inp.from_si(result.motion.phi[:, 0]), cols]))


def dynamics_frame(dyn):
    """The cycle table of `mbplanar dynamics -o` for a `Dynamics`."""
    return frame(*dynamics_table(dyn))


#: result type's name → its frame
VIEWS = {"Motion": motion_frame, "Kinetostatics": kinetostatics_frame, "Dynamics": dynamics_frame}
