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
from typing import Any

from relrl.errors import PrologMissing

__all__ = ["Lib", "start", "STACK_LIMIT", "BUILT_FOR", "FOREIGN", "RUNS_PROLOG", "CTYPES",
           "check_version"]

#: Bytes of Prolog stack (all stacks together) before a rule raises a resource error:
#: a runaway recursion ends in about 1.5 s (SWI-Prolog's default, 1 GB, takes 3).
STACK_LIMIT = 512 * 1024 * 1024

#: The SWI-Prolog major version whose foreign interface the constants and signatures below
#: are SWI-Prolog.h's (:func:`check_version` refuses another).
BUILT_FOR = 9

# SWI-Prolog 9 foreign-interface constants.
VARIABLE, ATOM, INTEGER, RATIONAL, FLOAT, STRING, TERM, NIL, BLOB, LIST_PAIR = range(1, 11)
REP_UTF8 = 0x00100000
CVT_ATOM, CVT_STRING, CVT_INTEGER, CVT_VARIABLE, CVT_WRITEQ = 0x1, 0x2, 0x8, 0x40, 0xC0
Q_FLAGS = 0x04 | 0x08          # PL_Q_NODEBUG | PL_Q_CATCH_EXCEPTION: an open query's
#: PL_call_predicate's: PL_Q_NODEBUG | PL_Q_PASS_EXCEPTION, so that an exception raised past
#: the gateway's catch is still there to read (PL_exception(0)) when the call returns.
CALL_FLAGS = 0x04 | 0x10
PL_VERSION_SYSTEM = 1

#: Every foreign function relrl calls, the one table of their signatures: name: (result,
#: arguments), in kinds of SWI-Prolog.h's C types. Both the ctypes calls (:class:`Lib`, by
#: :data:`CTYPES`) and the compiled step (:mod:`relrl.bridge.stepkernel`, by its own map
#: of the kinds) are built from it. Kinds: ``term`` (term_t, atom_t, functor_t, fid_t: an
#: uintptr_t handle), ``handle`` (module_t, predicate_t, qid_t, record_t: a pointer),
#: ``int``, ``uint``, ``int64``, ``double``, ``size``, ``text`` (char *); ``K*`` a pointer
#: to a K; None for void.
FOREIGN: dict[str, tuple[str | None, ...]] = {
    "PL_new_term_refs": ("term", "size"), "PL_new_term_ref": ("term",),
    "PL_put_int64": ("int", "term", "int64"), "PL_put_float": ("int", "term", "double"),
    "PL_put_nil": ("int", "term"), "PL_put_variable": ("int", "term"),
    "PL_put_term": ("int", "term", "term"), "PL_put_atom": ("int", "term", "term"),
    "PL_cons_list": ("int", "term", "term", "term"),
    "PL_cons_functor_v": ("int", "term", "term", "term"),
    "PL_new_atom_mbchars": ("term", "int", "size", "text"), "PL_unregister_atom": (None, "term"),
    "PL_new_functor_sz": ("term", "term", "size"), "PL_chars_to_term": ("int", "text", "term"),
    "PL_term_type": ("int", "term"),
    "PL_get_nchars": ("int", "term", "size*", "text*", "uint"),
    "PL_get_int64": ("int", "term", "int64*"), "PL_get_float": ("int", "term", "double*"),
    "PL_get_atom": ("int", "term", "term*"), "PL_get_nil": ("int", "term"),
    "PL_get_name_arity_sz": ("int", "term", "term*", "size*"),
    "PL_atom_mbchars": ("int", "term", "size*", "text*", "uint"),
    "PL_get_arg_sz": ("int", "size", "term", "term"),
    "PL_get_list": ("int", "term", "term", "term"),
    "PL_predicate": ("handle", "text", "int", "text"),
    "PL_open_foreign_frame": ("term",), "PL_discard_foreign_frame": (None, "term"),
    "PL_exception": ("term", "term"), "PL_clear_exception": (None,),
    "PL_record": ("handle", "term"), "PL_recorded": ("int", "handle", "term"),
    "PL_erase": (None, "handle"),
    "PL_mark_string_buffers": (None, "size*"),
    "PL_release_string_buffers_from_mark": (None, "size"),
    "PL_thread_raise": ("int", "int", "int"), "PL_thread_self": ("int",),
    "PL_version_info": ("uint", "int"),
    "PL_call_predicate": ("int", "handle", "int", "handle", "term"),
    "PL_open_query": ("handle", "handle", "int", "handle", "term"),
    "PL_next_solution": ("int", "handle"), "PL_close_query": ("int", "handle"),
    "PL_handle_signals": ("int",),
}
#: The functions of :data:`FOREIGN` that run Prolog goals: called with the GIL released (the
#: others keep it: they take microseconds, and handing the GIL over would let a busy thread
#: take it each time).
RUNS_PROLOG = frozenset({"PL_call_predicate", "PL_open_query", "PL_next_solution",
                         "PL_close_query", "PL_handle_signals"})

_T = c_size_t
#: :data:`FOREIGN`'s kinds as ctypes types.
CTYPES: dict[str | None, Any] = {
    None: None, "term": _T, "handle": c_void_p, "int": c_int, "uint": c_uint,
    "int64": c_int64, "double": c_double, "size": c_size_t, "text": c_char_p,
    "term*": POINTER(_T), "size*": POINTER(c_size_t), "int64*": POINTER(c_int64),
    "double*": POINTER(c_double), "text*": POINTER(c_char_p),
}


def check_version(version: int, path: str) -> None:
    """Refuse a libswipl (``version`` as ``PL_version_info`` gives it, 90004 for 9.0.4) of
    another major version than the one the bridge's constants were taken from.

    Raises:
        PrologMissing: ``version`` is not SWI-Prolog :data:`BUILT_FOR`'s.
    """
    if version // 10000 != BUILT_FOR:
        found = f"{version // 10000}.{version // 100 % 100}.{version % 100}"
        raise PrologMissing(f"SWI-Prolog {found} ({path}): relrl's bridge is built for "
                            f"SWI-Prolog {BUILT_FOR} (its foreign interface's constants); "
                            f"install SWI-Prolog {BUILT_FOR} or point LIBSWIPL_PATH and "
                            "SWI_HOME_DIR at one")


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
        for name, (result, *arguments) in FOREIGN.items():
            f = getattr(cdll if name in RUNS_PROLOG else quick, name)
            f.restype, f.argtypes = CTYPES[result], [CTYPES[a] for a in arguments]
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
            check_version(lib.version_info(PL_VERSION_SYSTEM), path)
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

