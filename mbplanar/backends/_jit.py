"""The compiled kernels' decorator: `njit` makes a `Kernel`, a numba kernel that imports numba only when it
is first compiled, and that runs the ahead-of-time build (`_aot`) instead where one matches.

A module of kernels (`_numba_kinematics`, ...) imports without numba. A call (`Kernel.entry` for the
compiled function itself, or calling the kernel) looks the arguments' types up: when the ahead-of-time
module of this copy of mbplanar is built and has the kernel for exactly these types, its function is
used, and numba is never imported (a process saves numba's own start, ~0.8 s); else numba compiles the
kernel for them (or loads it from its on-disk cache), as `numba.njit` would, with the one-line notice
of `_numba_notice` while it compiles. Both are compiled from the same Python function with the same
options, and tests hold their results equal bit for bit.

Kernels calling each other: numba types a `Kernel` found in a kernel's globals as its dispatcher
(``_numba_type_``), so a kernel calls another as it would call a ``numba.njit`` function.

`LeanPipeline` (the option ``lean=True``): numba's nopython pipeline less the passes that these kernels
have nothing for: closures and functions made inside them, numba's own inlining, literal unrolling and
dispatch on literals, branch pruning on constants, array-expression rewrites, and the SSA form with its
phi nodes (there to type a variable that changes type, which no kernel variable does: a variable that
did would fail to compile, not change meaning). They cost about a fifth of the kinematics kernel's first
compile (7.9 → 6.2 s CPU), the compiled code is the same speed, and the tests hold the results bit for
bit where they were.
"""

from __future__ import annotations

import threading

import numpy as np

__all__ = ["Kernel", "njit", "lean_pipeline", "signature", "capture", "forget", "interpret", "plain"]


def njit(**options):
    """A decorator making a `Kernel` compiled with ``numba.njit(**options)`` (``lean=True``: with
    `lean_pipeline`)."""
    return lambda func: Kernel(func, options)


class Kernel:
    """A numba kernel made on first use (`dispatcher`), or the ahead-of-time build's function for the
    argument types it was built for (`entry`)."""

    def __init__(self, func, options: dict):
        self.py_func, self.options = func, dict(options)
        self.name = f"{func.__module__}.{func.__qualname__}"
        self.__doc__, self.__name__, self.__module__ = func.__doc__, func.__name__, func.__module__
        self._dispatcher = None
        self._entries: dict = {}  # signature → the compiled function taking it
        _kernels.append(self)

    @property
    def dispatcher(self):
        """numba's dispatcher of the kernel, made (numba imported) on first use."""
        if self._dispatcher is None:
            self._dispatcher = _dispatcher_of(self.py_func, self.options)
        return self._dispatcher

    @property
    def _numba_type_(self):
        """How numba types the kernel where another kernel calls it: as its dispatcher."""
        from numba.core import types
        return types.Dispatcher(self.dispatcher)

    def entry(self, args: tuple):
        """The compiled function for arguments of the types of `args` (not called): the ahead-of-time
        build's where it has them, else numba's (compiled, or loaded from its cache, now)."""
        if _capturing:
            return self._captured
        key = signature(args)
        found = self._entries.get(key) if key is not None else None
        if found is None:
            from . import _aot
            found = _aot.function(self.name, key) if key is not None else None
            if found is None:
                dispatcher = self.dispatcher
                types = tuple(dispatcher.typeof_pyval(a) for a in args)
                found = dispatcher.compile(types)
            if key is not None:
                self._entries[key] = found
        return found

    def __call__(self, *args):
        if _plain.on:
            return self.py_func(*args)
        return self.entry(args)(*args)

    def _captured(self, *args):
        """While `capture` records: note the arguments of an outermost call, run the Python function."""
        if _capturing[-1]["depth"] == 0:
            _capturing[-1]["calls"].setdefault(self.name, (self, args))
        _capturing[-1]["depth"] += 1
        try:
            result = self.py_func(*args)
        finally:
            _capturing[-1]["depth"] -= 1
        _capturing[-1]["results"].setdefault(self.name, result)
        return result

    def __getattr__(self, name):
        """numba's dispatcher's attributes (``signatures``, ``overloads``, ...)."""
        if name.startswith("__") or name in ("_dispatcher", "py_func", "options"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __repr__(self):
        return f"<compiled kernel {self.name}>"


_kernels: list = []  # every kernel made
_capturing: list = []
_plain = threading.local()  # `interpret`: this thread runs the kernels as plain Python
_plain.on = False


def interpret(kernel: Kernel, args: tuple, viewed: tuple = ()):
    """`kernel(*args)` run as plain Python, with the kernels it calls: every array of `args` (and of the
    named tuples among them) read through a memoryview (`plain`), whose elements are Python floats, ints
    and bools (a numpy scalar's arithmetic costs several times a float's); `viewed`: arguments already
    made `plain`, passed first. The kernels use only element access, len(), .shape and `math` on their
    arrays, so the same function runs either way, with the same floating-point operations in the same
    order. A division by zero or an overflow Python raises, where the compiled code gives inf or NaN,
    propagates (as ArithmeticError)."""
    plain_args = viewed + tuple(_viewed(a) for a in args)
    before, _plain.on = getattr(_plain, "on", False), True
    try:
        return kernel.py_func(*plain_args)
    finally:
        _plain.on = before


def plain(value):
    """`value` as `interpret` hands it to a kernel: its arrays (and those of its named tuples) as
    memoryviews."""
    return _viewed(value)


def _viewed(value):
    """`value` with its arrays as memoryviews (named tuples and tuples member by member)."""
    if value.__class__ is np.ndarray:
        return memoryview(value)
    if isinstance(value, tuple):
        return value.__class__(*map(_viewed, value)) if hasattr(value, "_fields") else tuple(map(_viewed, value))
    return value


def forget() -> None:
    """Forget the compiled functions found so far, and the ahead-of-time module looked up: the next call
    of each kernel looks again (after `_aot.build`, or a test switching it on or off). Plans that hold a
    function (`_numba_kinematics._KernelPlan.entry`) keep it."""
    from . import _aot
    _aot.reset()
    for kernel in _kernels:
        kernel._entries.clear()


class capture:
    """``with capture() as seen``: every kernel runs as plain Python; ``seen["calls"]`` collects, per
    kernel name, the first outermost call's (kernel, arguments), ``seen["results"]`` its result: the
    ahead-of-time build learns the argument types from a sample run without compiling anything."""

    def __enter__(self) -> dict:
        _capturing.append({"depth": 0, "calls": {}, "results": {}})
        return _capturing[-1]

    def __exit__(self, *exc):
        _capturing.pop()


def signature(args) -> str | None:
    """The numba types of `args` (what `numba.typeof` tells apart: dtype, dimensions, layout, read-only and
    alignment of an array, the scalars' kinds, tuples and named tuples member by member) as a string
    made without numba; None for a value it does not describe (the kernel then goes through numba)."""
    try:
        return ",".join(_type_of(a) for a in args)
    except TypeError:
        return None


def _type_of(value) -> str:
    cls = value.__class__
    if cls is np.ndarray:
        flags = value.flags
        layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
        return (f"{value.dtype.str}{value.ndim}{layout}{'' if flags.writeable else 'r'}"
                f"{'' if flags.aligned else 'u'}")
    if cls is bool or cls is np.bool_:
        return "?"
    if cls is float or cls is np.float64:
        return "d"
    if (cls is int and -2 ** 63 <= value < 2 ** 63) or cls is np.int64:
        return "q"
    if isinstance(value, tuple) and cls is tuple or hasattr(cls, "_fields"):
        prefix = cls.__name__ if hasattr(cls, "_fields") else ""
        return f"{prefix}({','.join(_type_of(v) for v in value)})"
    raise TypeError(cls)


def _dispatcher_of(func, options: dict):
    """``numba.njit(**options)(func)``, with the compile notice installed (numba imported here)."""
    import numba
    from . import _numba_notice
    _numba_notice.install()
    options = dict(options)
    if options.pop("lean", False):
        options["pipeline_class"] = lean_pipeline()
    dispatcher = numba.njit(**options)(func)
    _stamp_cache_with_kernel_sources(dispatcher)
    return dispatcher


def _stamp_cache_with_kernel_sources(dispatcher) -> None:
    """Tie numba's on-disk cache of a kernel to every kernel module, not only its own file.

    numba checks a cached kernel against its own source file's size and time, but a kernel inlines the
    building blocks and kernels of the other modules of this folder: after an edit there (a ``git pull``
    into an editable install), numba would load a kernel holding the old code. The index is stamped with
    the size and time of every module here instead, so any edit compiles the kernels again."""
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    if cache_file is not None and hasattr(cache_file, "_source_stamp"):
        cache_file._source_stamp = _kernel_sources_stamp()


def _kernel_sources_stamp() -> str:
    """The name, size and modification time of every module of this folder (read once per process)."""
    if not _sources:
        import os
        from ..engine._cache import _stamp_of_files
        _sources.append(_stamp_of_files(os.path.dirname(os.path.abspath(__file__))))
    return _sources[0]


_sources: list = []


_lean: list = []


def lean_pipeline():
    """`LeanPipeline`'s class (numba's nopython pipeline less `_SKIPPED`), made on first use."""
    if not _lean:
        from numba.core import typed_passes, untyped_passes
        from numba.core.compiler import CompilerBase, DefaultPassBuilder
        from numba.core.compiler_machinery import PassManager

        skipped = [getattr(module, name, None) for module, name in (
            (untyped_passes, "InlineClosureLikes"), (untyped_passes, "MakeFunctionToJitFunction"),
            (untyped_passes, "InlineInlinables"), (untyped_passes, "DeadBranchPrune"),
            (untyped_passes, "FindLiterallyCalls"), (untyped_passes, "LiteralUnroll"),
            (untyped_passes, "ReconstructSSA"), (untyped_passes, "LiteralPropagationSubPipelinePass"),
            (typed_passes, "PreLowerStripPhis"), (typed_passes, "NopythonRewrites"))]

        class LeanPipeline(CompilerBase):
            """numba's nopython pipeline less the skipped passes (per function, as
            ``numba.njit(pipeline_class=LeanPipeline)``: numba's settings for other code are untouched)."""

            def define_pipelines(self):
                full = DefaultPassBuilder.define_nopython_pipeline(self.state)
                lean = PassManager("mbplanar lean nopython")
                for kind, description in full.passes:
                    if kind not in skipped:
                        lean.add_pass(kind, description)
                lean.finalize()
                return [lean]

        _lean.append(LeanPipeline)
    return _lean[0]
