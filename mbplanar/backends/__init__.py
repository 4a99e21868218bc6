"""Backends: the compiled (numba) kernels for kinematics and kinetostatics, and the thread pool that
splits long batches. numpy (in `mbplanar.kinematics` and `mbplanar.forces`) is the reference; numba is
optional (extra ``mbplanar[fast]``) and imported only when a compiled engine is asked for.

``mbplanar._numba_kinematics``, ``mbplanar._numba_kinetostatics`` and ``mbplanar._threads`` are deprecated
aliases of the modules here.
"""

__all__: list[str] = []
