"""The compiled kernels' decorator: `njit` makes a `Kernel`, a numba kernel that imports numba only when it
is first compiled or loaded.

A module of kernels (`_numba_kinematics`, ...) imports without numba. A call (`Kernel.entry` for the
compiled function itself, or calling the kernel) looks the arguments' types up: the first time, numba
loads the kernel for them from its on-disk cache (``cache=True``), or compiles it (and writes it there),
with the one-line notice of `_numba_notice` while it compiles. Before numba first loads or compiles a
kernel of this process, `_aot.prepare` checks mbplanar's index of numba's cache folder, so that a kernel
compiled from other sources is never loaded; ``mbplanar compile`` (`_aot.build`) fills the cache.

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

import contextlib
import threading

import numpy as np

__all__ = ["Kernel", "njit", "lean_pipeline", "signature", "forget", "kernels", "cache_path", "interpret", "plain"]


def njit(**options):
    """A decorator making a `Kernel` compiled with ``numba.njit(**options)`` (``lean=True``: with
    `lean_pipeline`; ``vectorize=True``: with numba's code generation as it is, LLVM's vectorizers
    included, which `_scalar_codegen` otherwise leaves out; ``opt=3``: LLVM's optimisation level for
    `_scalar_codegen`, default 2)."""
    return lambda func: Kernel(func, options)


class Kernel:
    """A numba kernel made on first use (`dispatcher`), with its compiled function per argument types
    (`entry`)."""

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
    def made(self) -> bool:
        """Whether numba's dispatcher of the kernel has been made in this process."""
        return self._dispatcher is not None

    @property
    def _numba_type_(self):
        """How numba types the kernel where another kernel calls it: as its dispatcher."""
        from numba.core import types
        return types.Dispatcher(self.dispatcher)

    def entry(self, args: tuple):
        """The compiled function for arguments of the types of `args` (not called): numba's, loaded from
        its cache or compiled now the first time."""
        key = signature(args)
        found = self._entries.get(key) if key is not None else None
        if found is None:
            dispatcher = self.dispatcher
            vectorize, opt = self.options.get("vectorize", False), self.options.get("opt", 2)
            with contextlib.nullcontext() if vectorize else _scalar_codegen(opt):
                found = dispatcher.compile(tuple(dispatcher.typeof_pyval(a) for a in args))
            if key is not None:
                self._entries[key] = found
        return found

    def __call__(self, *args):
        if _plain.on:
            return self.py_func(*args)
        return self.entry(args)(*args)

    def __getattr__(self, name):
        """numba's dispatcher's attributes (``signatures``, ``overloads``, ...)."""
        if name.startswith("__") or name in ("_dispatcher", "py_func", "options"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __repr__(self):
        return f"<compiled kernel {self.name}>"


_kernels: list = []  # every kernel made


@contextlib.contextmanager
def _scalar_codegen(opt: int = 2):
    """numba's code generation without LLVM's loop and SLP vectorizers and at LLVM's optimisation level
    `opt` (at most numba's own; numba's settings ``NUMBA_LOOP_VECTORIZE``, ``NUMBA_SLP_VECTORIZE`` and
    ``NUMBA_OPT``, which it reads when it optimises a library), for the kernels compiled or loaded
    inside, under numba's compiler lock so that no other compilation sees the change.

    The kernels are scalar loops over a few links and unknowns. Vectorised, their short loops became
    vector code behind run-time trip-count and alias checks whose speed depended on where the code was
    loaded (the four-bar sweep's kernel took 0.12 to 0.20 µs per position from one loaded copy to the
    next, 0.115 to 0.117 without the vectorizers); at level 3 the sweep with rates still did (slider-crank
    0.206 or 0.23 to 0.34 µs, one copy in three), at level 2 it keeps 0.204 to 0.216. Neither setting
    reorders a floating-point operation (no fastmath), so the results are the same to the bit."""
    from numba.core import config
    from numba.core.compiler_lock import global_compiler_lock
    with global_compiler_lock:
        saved = config.LOOP_VECTORIZE, config.SLP_VECTORIZE, config.OPT
        config.LOOP_VECTORIZE = config.SLP_VECTORIZE = False
        config.OPT = type(config.OPT)(min(int(config.OPT), opt))
        try:
            yield
        finally:
            config.LOOP_VECTORIZE, config.SLP_VECTORIZE, config.OPT = saved


class _Plain(threading.local):
    """Per thread: whether it runs the kernels as plain Python (`interpret`); off in every thread until
    it says otherwise (a design batch calls its kernel from worker threads too)."""

    on = False


_plain = _Plain()


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


def kernels() -> list:
    """Every kernel made so far (those of the kernel modules imported)."""
    return list(_kernels)


def forget() -> None:
    """Forget the compiled functions found so far: the next call of each kernel asks numba again (for
    tests). Plans that hold a function (`_numba_kinematics._KernelPlan.entry`) keep it."""
    for kernel in _kernels:
        kernel._entries.clear()


def cache_path() -> str:
    """numba's cache folder of the kernels (numba imported): where numba writes them and `_aot` its index."""
    from ._numba_blocks import _place
    return _place.dispatcher.stats.cache_path


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
    """``numba.njit(**options)(func)``, with the compile notice installed and numba's cache folder checked
    against the kernels' sources (`_aot.prepare`) before anything is loaded from it (numba imported here)."""
    import numba
    from . import _aot, _numba_notice
    _numba_notice.install()
    options = dict(options)
    options.pop("vectorize", None)
    options.pop("opt", None)
    if options.pop("lean", False):
        options["pipeline_class"] = lean_pipeline()
    dispatcher = numba.njit(**options)(func)
    if dispatcher.stats.cache_path is not None:
        _aot.prepare(dispatcher.stats.cache_path)
    return dispatcher


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
