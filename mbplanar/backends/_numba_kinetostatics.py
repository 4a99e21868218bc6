"""The compiled kinetostatics (optional, needs numba): a `forces._program.Program` run over the positions
of a compiled one-input `Motion`, reading its records (`Motion.records`).

The program (written by the forces layer once per engine, record layout and `inertia`) is a list of
elementary ops on the rows of a work matrix, one row per value and one column per position of a chunk
of 128 to 384 positions (`chunk_of`); `_kernel` runs the ops one after the other, each over the whole
chunk in an inner loop (SIMD lanes), so the tables are read once per chunk, not once per position. The
kernel is one small function of 27 kinds of op whatever the model, so numba compiles it once, in about
2 s. This module gets the program, the records and the inputs (`forces._kinetostatics.KinetostaticsJob`),
nothing of the engine.
"""

from __future__ import annotations

import sys
import threading

import numpy as np

from . import _threads
from ._jit import njit

__all__ = ["run"]


#: positions the kernel takes at once (each op of the program runs over them in an inner loop): the
#: longest whose work matrix fits `WORK_BYTES`, else the last; all multiples of 8 (rows on cache lines)
CHUNKS = (384, 320, 256, 128)


def _l2_bytes(path="/sys/devices/system/cpu/cpu0/cache/index2/size") -> int:
    """The size of a core's L2 cache (Linux's sysfs; 512 KiB where it does not say)."""
    try:
        with open(path, encoding="ascii") as f:
            text = f.read().strip()
        return int(text[:-1]) * {"K": 1024, "M": 1024 ** 2}[text[-1]]
    except (OSError, ValueError, KeyError, IndexError):
        return 512 * 1024


#: bytes of the work matrix: four fifths of the core's L2 cache (at 512 KiB: the class IV group's
#: kernel 7 % faster at 320 positions (400 KiB) than at 128, the six-bar press's 2 % at 384 than at 256)
WORK_BYTES = _l2_bytes() * 4 // 5


def chunk_of(rows: int) -> int:
    """Positions per chunk for a work matrix of `rows` rows (`CHUNKS`): a longer chunk runs each op's
    loop over more positions for one dispatch, until the matrix crowds the L2 cache."""
    return next((c for c in CHUNKS if rows * c * 8 <= WORK_BYTES), CHUNKS[-1])


def _scratch(rows: int) -> tuple:
    """Work arrays of `_kernel`: the work matrix (rows + 2, `chunk_of(rows)`), on a cache line
    (`aligned_zeros`); its last two rows are PIVOT's (the largest entry so far, and its row)."""
    return (aligned_zeros((rows + 2, chunk_of(rows))),)


#: bytes of a cache line, where the work matrix starts
LINE = 64


def aligned_zeros(shape) -> np.ndarray:
    """Zeros of `shape` whose first element starts a cache line (`LINE`). The kernel's loops load and
    store the rows of its work matrix 32 bytes at a time, and numpy's allocator aligns an array to 16
    bytes only: a matrix 16 bytes off a line makes every other access straddle two lines, and the kernel
    ran 14-15 % slower (six-bar press, class IV group; which of the two a process got was chance).
    The rows stay on lines as `chunk_of` gives multiples of 8 positions."""
    size = int(np.prod(shape))
    block = np.zeros(size + LINE // 8)
    start = (-block.ctypes.data % LINE) // 8
    return block[start:start + size].reshape(shape)


#: output blocks a program keeps for reuse
KEEP_OUTPUTS = 2
_outputs_lock = threading.Lock()


def _output_block(kept: list, shape) -> np.ndarray:
    """An array `shape` for the kernel's outputs: a block of an earlier call that no result holds any
    more (every array of a result is a view of its block), else a new one, kept for reuse (up to
    `KEEP_OUTPUTS` per program). Reusing it spares the pages a new one faults in: glibc gives a freed
    block of megabytes back to the system, and a sweep repeated over the same batch (a study, a
    benchmark) would fault its few MB in again every call (~0.1 µs per position at N = 3600).
    `kept`: the blocks kept (a program's)."""
    with _outputs_lock:
        free = [i for i in range(len(kept)) if _references(kept, i) == _UNHELD]
        for i in free:
            if kept[i].shape == shape:
                return kept[i]
        block = np.empty(shape)
        if free:
            kept[free[0]] = block
        elif len(kept) < KEEP_OUTPUTS:
            kept.append(block)
        return block


def _references(blocks, i) -> int:
    """The reference count of blocks[i] as this function sees it."""
    return sys.getrefcount(blocks[i])


_UNHELD = _references([np.empty(0)], 0)  # that of a block only its list holds


def run(job) -> np.ndarray:
    """The outputs (O, B) of the program of `job` (a `KinetostaticsJob`) over its B positions: the
    unknowns, the loads' values, the virtual-power residual and the singular flag (`Program`)."""
    program, records, inputs = job.program, job.records, job.inputs
    batch = len(records)
    store = program.store
    out = _output_block(store.setdefault("outputs", []), (program.outputs_rows, batch))
    row = records.view(np.float64).reshape(batch, -1)
    parts = _threads.chunks(batch, job.threads)
    work = _threads.work_arrays(store.setdefault("scratch", []), lambda: _scratch(program.rows), len(parts))
    args = (program.ops, program.consts, program.aux, row, inputs, out)
    _threads.run([lambda p=p, w=w: _run(store, (p.start, p.stop, *args, *w)) for p, w in zip(parts, work)])
    return out


def _run(store: dict, args) -> None:
    """`_kernel(*args)`. The first call of a program looks the compiled function up for the arguments'
    types (`_jit.Kernel.entry`, about 7 µs a call); later calls pass the same types (the program, and
    C-contiguous float64 arrays made here, of fixed dimensions) but for the records, which may be
    read-only, so the function is kept per that flag and called directly."""
    writeable = args[5].flags.writeable
    entries = store.setdefault("entries", {})
    entry = entries.get(writeable)
    if entry is None:
        entry = entries[writeable] = _kernel.entry(args)
    entry(*args)


# -- kernel -------------------------------------------------------------------------------------------
# Its inner loops run over the positions of a chunk, so LLVM's vectorizers stay on (the other kernels,
# scalar loops over a few links, are compiled without them: `_jit._scalar_codegen`); it calls no other
# kernel, so no building block is compiled under its settings. Measured in four processes each: class IV
# group with reactions 1.64-1.70 µs per position with them, 1.84-1.98 without.
_jit = njit(cache=True, error_model="numpy", nogil=True, _nrt=False, vectorize=True)


@_jit
def _kernel(start, stop, ops, K, aux, row, inputs, out, W):
    """Positions start … stop − 1, a chunk at a time: every op of the program (`_program`; codes above)
    over the chunk, from the records `row` (B, fields) and `inputs` into `out`."""
    chunk = W.shape[1]
    for b0 in range(start, stop, chunk):
        nc = min(chunk, stop - b0)
        for t in range(len(ops)):
            code, d, a, b, e, f, k = ops[t, 0], ops[t, 1], ops[t, 2], ops[t, 3], ops[t, 4], ops[t, 5], ops[t, 6]
            Wd, Wa, Wb, We, Wf = W[d], W[a], W[b], W[e], W[f]
            k0, k1 = K[k], K[k + 1]  # (read once: the stores to W might alias K)
            if code == 0:  # GATHER, two fields a pass (`finish` pads them to an even number)
                for i in range(a, a + 2 * b, 4):
                    s0, W0, s1, W1 = aux[i], W[aux[i + 1]], aux[i + 2], W[aux[i + 3]]
                    for c in range(nc):
                        rec = row[b0 + c]
                        W0[c] = rec[s0]
                        W1[c] = rec[s1]
            elif code == 1:  # INPUT
                for c in range(nc):
                    Wd[c] = inputs[a, b0 + c]
            elif code == 2:  # SET
                for c in range(nc):
                    Wd[c] = k0
            elif code == 3:  # MUL
                for c in range(nc):
                    Wd[c] = Wa[c] * Wb[c]
            elif code == 4:  # DIV
                for c in range(nc):
                    Wd[c] = Wa[c] / Wb[c]
            elif code == 5:  # MAX
                for c in range(nc):
                    Wd[c] = max(Wa[c], Wb[c])
            elif code == 6:  # SQRT
                for c in range(nc):
                    Wd[c] = np.sqrt(Wa[c])
            elif code == 7:  # ABS
                for c in range(nc):
                    Wd[c] = abs(Wa[c])
            elif code == 8:  # MSUB
                for c in range(nc):
                    Wd[c] = Wa[c] - Wb[c] * We[c]
            elif code == 9:  # MADD
                for c in range(nc):
                    Wd[c] = Wa[c] + Wb[c] * We[c]
            elif code == 10:  # DOT
                for c in range(nc):
                    Wd[c] = Wa[c] * Wb[c] + We[c] * Wf[c]
            elif code == 11:  # LEVER
                for c in range(nc):
                    Wd[c] = ((Wa[c] + Wb[c]) + k0) * k1
            elif code == 12:  # OUT
                for c in range(nc):
                    out[d, b0 + c] = Wa[c]
            elif code == 13:  # FLAG (a select, not a branch: the loop vectorises)
                for c in range(nc):
                    Wd[c] = Wd[c] if k0 < Wa[c] <= k1 else 1.0
            elif code == 15:  # ADD
                for c in range(nc):
                    Wd[c] = Wa[c] + Wb[c]
            elif code == 16:  # SUB
                for c in range(nc):
                    Wd[c] = Wa[c] - Wb[c]
            elif code == 17:  # ADDK
                for c in range(nc):
                    Wd[c] = Wa[c] + k0
            elif code == 18:  # KSUB
                for c in range(nc):
                    Wd[c] = k0 - Wa[c]
            elif code == 19:  # MULK
                for c in range(nc):
                    Wd[c] = Wa[c] * k0
            elif code == 20:  # MADDK
                for c in range(nc):
                    Wd[c] = Wa[c] + k0 * Wb[c]
            elif code == 21:  # MSUBK
                for c in range(nc):
                    Wd[c] = Wa[c] - k0 * Wb[c]
            elif code == 22:  # DOTK
                for c in range(nc):
                    Wd[c] = Wa[c] * k0 + Wb[c] * k1
            elif code == 23:  # CROSS
                for c in range(nc):
                    Wd[c] = Wa[c] * Wb[c] - We[c] * Wf[c]
            elif code == 24:  # GUIDE
                for c in range(nc):
                    rate = -Wa[c] if Wb[c] < 0 else Wa[c]
                    if k1 == 0.0:  # forward
                        along = -1.0 if rate >= 0 else 0.0
                    elif k1 == 1.0:  # backward
                        along = 1.0 if rate <= 0 else 0.0
                    else:  # always: −sign(rate)
                        along = -1.0 if rate > 0 else (1.0 if rate < 0 else -(rate * 0.0))
                    Wd[c] = along * k0
            elif code == 25:  # RESIDUAL
                for c in range(nc):
                    Wd[c] = abs(Wa[c]) / (Wb[c] if Wb[c] > 0 else 1.0)
            elif code == 26:  # OUTK
                for c in range(nc):
                    out[d, b0 + c] = k0
            else:  # PIVOT: the search row by row over the chunk (selects: the loops vectorise), then the swaps
                w = b + 1
                big, at = W[W.shape[0] - 2], W[W.shape[0] - 1]  # (the two rows past the program's)
                first = W[aux[a]]
                for c in range(nc):
                    big[c], at[c] = abs(first[c]), 0.0
                for i in range(1, b):
                    Wi, fi = W[aux[a + i * w]], float(i)
                    for c in range(nc):
                        v = abs(Wi[c])
                        larger = v > big[c]
                        big[c] = v if larger else big[c]
                        at[c] = fi if larger else at[c]
                for c in range(nc):
                    p = int(at[c])
                    if p:
                        for j in range(w):
                            s, t = aux[a + j], aux[a + p * w + j]
                            W[s, c], W[t, c] = W[t, c], W[s, c]
                        Wd[c] = -Wd[c]
