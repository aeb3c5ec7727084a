"""Copying a large array past the CPU caches, for bytes that another process will read.

An ordinary copy (``memcpy``, ``numpy.copyto``) of a frame into shared memory first reads
every destination cache line it is about to overwrite ("read for ownership"), then leaves the
written lines in the writer's cache, where they push out the writer's own data. A copy with
*non-temporal* stores writes whole lines straight to memory: one stream fewer, and on the
machine measured a camera frame is copied in about three quarters of the time
(``docs/benchmarks.md``).

The copy loop is a few lines of LLVM IR compiled for the host CPU at first use, through
llvmlite (which numba, a dependency of cyborg, already brings); it runs without the GIL. Where
llvmlite cannot compile it, :func:`stream_copy` is a plain ``numpy.copyto``.

    stream_copy(destination_view, frame)   # destination: a writable buffer of frame.nbytes
"""

from __future__ import annotations

import ctypes
import functools
import logging
import platform
from collections.abc import Callable

import numpy as np

log = logging.getLogger(__name__)

STREAM_MINIMUM = 256 * 1024
"""Below this many bytes the copy stays in the cache: the reader soon finds it there."""

_BLOCK = 64  # bytes per non-temporal store: one cache line

_IR = """
define void @stream_copy(ptr noalias %dst, ptr noalias readonly %src, i64 %n) {
entry:
  %blocks = lshr i64 %n, 6
  %empty = icmp eq i64 %blocks, 0
  br i1 %empty, label %done, label %loop
loop:
  %i = phi i64 [0, %entry], [%next, %loop]
  %offset = shl i64 %i, 6
  %from = getelementptr i8, ptr %src, i64 %offset
  %to = getelementptr i8, ptr %dst, i64 %offset
  %ahead = getelementptr i8, ptr %from, i64 1024
  call void @llvm.prefetch.p0(ptr %ahead, i32 0, i32 LOCALITY, i32 1)
  %line = load <16 x i32>, ptr %from, align 1
  store <16 x i32> %line, ptr %to, align 64, !nontemporal !0
  %next = add i64 %i, 1
  %more = icmp ult i64 %next, %blocks
  br i1 %more, label %loop, label %done
done:
  FENCE
  ret void
}
FENCE_DECLARATION
declare void @llvm.prefetch.p0(ptr, i32, i32, i32)
!0 = !{i32 1}
"""
# The source is read ahead with a prefetch (which never faults, even past the end): a
# non-temporal one (locality 0), so it too passes by the caches, or one that keeps it in them
# (locality 3) for a caller that reads the source again right after. Non-temporal stores are
# weakly ordered: on x86 only SFENCE (or MFENCE) makes them visible before the stores that
# announce them; elsewhere LLVM's fence covers them.
_X86_FENCE = ("call void @llvm.x86.sse.sfence()", "declare void @llvm.x86.sse.sfence()")
_OTHER_FENCE = ("fence seq_cst", "")

_Kernel = Callable[[int, int, int], None]
_keep: list[object] = []  # the JIT engine owns the machine code: keep it alive


@functools.cache
def kernel(keep_source: bool = False) -> _Kernel | None:
    """The compiled copy loop, built on first call; None where it cannot be built.

    ``keep_source``: read the source into the caches (for a caller that reads it again next)
    instead of past them.
    """
    try:
        import llvmlite.binding as llvm

        llvm.initialize_native_target()
        llvm.initialize_native_asmprinter()
        x86 = platform.machine().lower() in ("x86_64", "amd64")
        fence, declaration = _X86_FENCE if x86 else _OTHER_FENCE
        source = _IR.replace("FENCE_DECLARATION", declaration).replace("FENCE", fence) \
            .replace("LOCALITY", "3" if keep_source else "0")
        machine = llvm.Target.from_default_triple().create_target_machine(
            cpu=llvm.get_host_cpu_name(), features=llvm.get_host_cpu_features().flatten(),
            opt=3)
        module = llvm.parse_assembly(source)
        module.verify()
        engine = llvm.create_mcjit_compiler(module, machine)
        engine.finalize_object()
        address = engine.get_function_address("stream_copy")
    except Exception as exc:  # no llvmlite, or it cannot target this CPU: copy the plain way
        log.info("streaming copy unavailable (%s: %s); using numpy.copyto",
                 type(exc).__name__, exc)
        return None
    _keep.append(engine)
    function = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)(address)
    _keep.append(function)
    return function


def stream_copy(destination: memoryview | np.ndarray, source: np.ndarray, *,
                keep_source: bool = False) -> None:
    """Copy ``source``'s bytes into ``destination`` (writable, exactly as many bytes).

    ``keep_source``: leave the source in the CPU's caches (see :func:`kernel`).

    Large contiguous sources go through the non-temporal loop; the unaligned head and the tail
    of the destination, small sources and strided ones take ``numpy.copyto``.
    """
    target = np.frombuffer(destination, np.uint8) if isinstance(destination, memoryview) \
        else destination.reshape(-1).view(np.uint8)
    if target.nbytes != source.nbytes:
        raise ValueError(f"stream_copy: destination holds {target.nbytes} bytes, "
                         f"source {source.nbytes}")
    run = kernel(keep_source) if source.nbytes >= STREAM_MINIMUM else None
    if run is None or not source.flags.c_contiguous or not target.flags.writeable:
        np.copyto(target, source.reshape(-1).view(np.uint8))
        return
    flat = source.reshape(-1).view(np.uint8)
    head = -target.ctypes.data % _BLOCK
    body = (target.nbytes - head) // _BLOCK * _BLOCK
    if head:
        np.copyto(target[:head], flat[:head])
    run(target.ctypes.data + head, flat.ctypes.data + head, body)
    if head + body < target.nbytes:
        np.copyto(target[head + body:], flat[head + body:])
