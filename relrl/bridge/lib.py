"""libswipl, loaded and started once, and the foreign functions relrl calls.

relrl starts SWI-Prolog itself, with explicit arguments, the first time a knowledge base is
made (:func:`start`):

* the library and SWI-Prolog's home come from ``LIBSWIPL_PATH`` and ``SWI_HOME_DIR`` when both
  are set, else from ``swipl --dump-runtime-variables``;
* ``--stack-limit``: all Prolog stacks together (:data:`STACK_LIMIT`);
* signals, decided here once: SWI-Prolog keeps two (:data:`PROLOG_SIGNALS`), Python every
  other. SIGSEGV is its C-stack guard: a recursion in C too deep for the C stack (reading a
  term nested some 15,000 deep, writing one) raises a resource error, as in plain swipl,
  where with ``--no-signals`` it crashed the process. SIGUSR2 is its alert signal, with
  which the time limit or Ctrl-C of a call (raised in Prolog's thread by
  :mod:`relrl.bridge.deadline` with ``PL_thread_raise``, not by the OS) also stops a
  blocking system call such as ``sleep/1``. Every other handler SWI-Prolog installs while it
  starts is put back as it was (Ctrl-C stays Python's ``KeyboardInterrupt``).

The functions that only build or read terms keep the GIL (a ``PyDLL`` view of the library:
they take microseconds, and handing the GIL over would let a busy thread take it each
time); those that run Prolog goals release it, so other Python threads — the watchdog, the
monitor's server — run meanwhile.
"""

from __future__ import annotations

import ctypes
import os
import re
import shutil
import signal
import subprocess
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from ctypes import POINTER, c_char_p, c_double, c_int, c_int64, c_size_t, c_uint, c_void_p

from relrl.errors import PrologMissing

__all__ = ["Lib", "start", "STACK_LIMIT"]

#: Bytes of Prolog stack (all stacks together) before a rule raises a resource error:
#: a runaway recursion ends in about 1.5 s (SWI-Prolog's default, 1 GB, takes 3).
STACK_LIMIT = 512 * 1024 * 1024

# SWI-Prolog 9 foreign-interface constants.
VARIABLE, ATOM, INTEGER, RATIONAL, FLOAT, STRING, TERM, NIL, BLOB, LIST_PAIR = range(1, 11)
REP_UTF8 = 0x00100000
CVT_ATOM, CVT_STRING, CVT_INTEGER, CVT_VARIABLE, CVT_WRITEQ = 0x1, 0x2, 0x8, 0x40, 0xC0
Q_FLAGS = 0x04 | 0x08          # PL_Q_NODEBUG | PL_Q_CATCH_EXCEPTION

_T = c_size_t                   # term_t, atom_t, functor_t, fid_t, qid_t: uintptr_t
_QUICK = {  # name: (result, arguments) of the calls that keep the GIL
    "PL_new_term_refs": (_T, c_size_t), "PL_new_term_ref": (_T,),
    "PL_put_int64": (c_int, _T, c_int64), "PL_put_float": (c_int, _T, c_double),
    "PL_put_nil": (c_int, _T), "PL_put_variable": (c_int, _T), "PL_put_term": (c_int, _T, _T),
    "PL_put_atom": (c_int, _T, _T), "PL_cons_list": (c_int, _T, _T, _T),
    "PL_cons_functor_v": (c_int, _T, _T, _T),
    "PL_new_atom_mbchars": (_T, c_int, c_size_t, c_char_p), "PL_unregister_atom": (None, _T),
    "PL_new_functor_sz": (_T, _T, c_size_t), "PL_chars_to_term": (c_int, c_char_p, _T),
    "PL_term_type": (c_int, _T),
    "PL_get_nchars": (c_int, _T, POINTER(c_size_t), POINTER(c_char_p), c_uint),
    "PL_get_int64": (c_int, _T, POINTER(c_int64)), "PL_get_float": (c_int, _T, POINTER(c_double)),
    "PL_get_name_arity_sz": (c_int, _T, POINTER(_T), POINTER(c_size_t)),
    "PL_atom_mbchars": (c_int, _T, POINTER(c_size_t), POINTER(c_char_p), c_uint),
    "PL_get_arg_sz": (c_int, c_size_t, _T, _T), "PL_get_list": (c_int, _T, _T, _T),
    "PL_predicate": (c_void_p, c_char_p, c_int, c_char_p),
    "PL_open_foreign_frame": (_T,), "PL_discard_foreign_frame": (None, _T),
    "PL_exception": (_T, _T), "PL_clear_exception": (None,),
    "PL_record": (c_void_p, _T), "PL_recorded": (c_int, c_void_p, _T), "PL_erase": (None, c_void_p),
    "PL_mark_string_buffers": (None, POINTER(c_size_t)),
    "PL_release_string_buffers_from_mark": (None, c_size_t),
    "PL_thread_raise": (c_int, c_int, c_int), "PL_thread_self": (c_int,),
}
_RUNS_PROLOG = {  # the calls that release the GIL: they run goals
    "PL_call_predicate": (c_int, c_void_p, c_int, c_void_p, _T),
    "PL_open_query": (c_void_p, c_void_p, c_int, c_void_p, _T),
    "PL_next_solution": (c_int, c_void_p), "PL_close_query": (c_int, c_void_p),
    "PL_handle_signals": (c_int,),
}


class Lib:
    """The started library's foreign functions as attributes without the ``PL_`` prefix
    (``lib.put_atom``, ``lib.call_predicate``), and where it lives.

    Attributes:
        path: the shared library; ``thread``: the Python thread that started Prolog (the
            only one that may call it); ``segv``: SWI-Prolog's SIGSEGV handler.
    """

    def __init__(self, cdll: ctypes.CDLL, path: str) -> None:
        self.path = path
        self.thread = threading.get_ident()
        self.segv: ctypes.Array[ctypes.c_char] | None = None
        quick = ctypes.PyDLL(path, handle=cdll._handle)
        for table, view in ((_QUICK, quick), (_RUNS_PROLOG, cdll)):
            for name, (restype, *argtypes) in table.items():
                f = getattr(view, name)
                f.restype, f.argtypes = restype, argtypes
                setattr(self, name[3:], f)

    def keep_c_stack_guard(self) -> None:
        """Put SWI-Prolog's C-stack guard back in SIGSEGV if a library installed another
        handler since (Ray does): before a call that may read text from outside."""
        if self.segv is not None and _sigaction(signal.SIGSEGV).raw[:8] != self.segv.raw[:8]:
            _LIBC.sigaction(signal.SIGSEGV, self.segv, None)


def _find() -> tuple[str, str]:
    """The path of libswipl and SWI-Prolog's home folder."""
    path, home = os.environ.get("LIBSWIPL_PATH"), os.environ.get("SWI_HOME_DIR")
    if path and home:
        return path, home
    swipl = shutil.which("swipl")
    if swipl is None:
        raise PrologMissing("SWI-Prolog is not installed: swipl is not on the PATH (make setup "
                         "installs it; or set LIBSWIPL_PATH and SWI_HOME_DIR)")
    out = subprocess.run([swipl, "--dump-runtime-variables"], capture_output=True,
                         text=True, timeout=60).stdout
    found = dict(re.findall(r'^(\w+)="(.*)";$', out, re.M))
    if "PLLIBSWIPL" not in found or "PLBASE" not in found:
        raise PrologMissing(f"{swipl} did not say where libswipl is (a SWI-Prolog without "
                         "its shared library? set LIBSWIPL_PATH and SWI_HOME_DIR)")
    return found["PLLIBSWIPL"], found["PLBASE"]


_lib: Lib | None = None
_start_lock = threading.Lock()


def start(boot: Callable[[Lib], None]) -> Lib:
    """The process's SWI-Prolog, started on first use (see the module documentation);
    ``boot`` loads the program into it, as part of the start (its signal handlers too).

    Raises:
        PrologMissing: SWI-Prolog is missing or does not start.
    """
    global _lib
    with _start_lock:
        if _lib is None:
            path, home = _find()
            cdll = ctypes.CDLL(path, mode=os.RTLD_GLOBAL)   # foreign packages link to it
            argv = [b"relrl", f"--home={home}".encode(), b"--quiet",
                    f"--stack-limit={STACK_LIMIT}".encode()]
            cdll.PL_initialise.argtypes = [c_int, POINTER(c_char_p)]
            lib = Lib(cdll, path)
            with _python_signals():
                if not cdll.PL_initialise(len(argv), (c_char_p * len(argv))(*argv)):
                    raise PrologMissing(f"SWI-Prolog ({path}) did not start")
                boot(lib)
            lib.segv = _sigaction(signal.SIGSEGV)
            _lib = lib
    return _lib


#: The signals whose handlers SWI-Prolog keeps: its C-stack guard (a deep recursion in C
#: raises instead of crashing) and its alert signal (a blocking system call is stopped).
PROLOG_SIGNALS = (signal.SIGSEGV, signal.SIGUSR2)


_LIBC = ctypes.CDLL(None)


def _sigaction(sig: int) -> ctypes.Array[ctypes.c_char]:
    """The handler of ``sig`` as the bytes of a ``struct sigaction`` (the handler first)."""
    action = ctypes.create_string_buffer(512)          # with room to spare
    _LIBC.sigaction(sig, None, action)
    return action


@contextmanager
def _python_signals() -> Iterator[None]:
    """Every signal but :data:`PROLOG_SIGNALS` keeps the handler it had before the block
    (Python's, faulthandler's, the default), whatever SWI-Prolog installs in it."""
    saved = {sig: _sigaction(sig) for sig in range(1, signal.NSIG)
             if sig not in (*PROLOG_SIGNALS, signal.SIGKILL, signal.SIGSTOP)}
    try:
        yield
    finally:
        for sig, action in saved.items():
            _LIBC.sigaction(sig, action, None)

