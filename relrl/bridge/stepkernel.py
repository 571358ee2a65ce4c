"""The control step's crossing into Prolog, as one compiled call (numba).

A control step is one call of ``relrl_gateway:gw_step/14``. Made from Python, it is some
twenty-five foreign calls — a frame opened, the knowledge base, the percepts' record, the
response emitted, the mode and what else is wanted put, the predicate called, the state
code, necessity, unit outputs, reward, reinforcement, mask and action read — at about 0.3
µs each through ctypes: 7.5 µs of a 45 µs step (measured: ``docs/engine.md``). :func:`step`
makes the same calls from compiled code, one call from Python. It is the step's only
crossing: whatever it does not read (a result that is not ``true``, a field that is not a
64-bit integer, an atom or a float, the extras) the caller reads from the frame it leaves
open, with the one term reader of :mod:`relrl.bridge.marshal`.

The foreign functions are named, not addressed (:class:`numba.types.ExternalFunction`): the
compiled code is cached on disk and the names are resolved in each process, once
:func:`load` made libswipl's symbols visible to the JIT. The kernel holds no Python object
and releases the GIL (the watchdog must be able to run while Prolog steps).

Layout of the arrays :func:`step` reads and writes (indices are the constants below):

``io`` (int64): in — the predicate, the query flags, the atom ``true``, the knowledge base's
module (atom), the percepts' record, the response emitted (index or -1), the mode (atom),
the record of what else is wanted (0: nothing); out — the frame, the first argument
reference, the state code, the necessity (atom), ``reinforced`` (atom), the response mask,
the engine's action (index or -1), the number of unit outputs.

``fo`` (float64): out — the reward, then the units' outputs.

:func:`step` returns :data:`DONE` when it read every field and the extras are ``[]`` (the
frame is then discarded and ``io``'s frame is 0); otherwise the frame stays open for the
caller, who discards it.
"""

from __future__ import annotations

from numba import njit, types

__all__ = ["load", "step", "DONE", "RAISED", "READ_REST", "ARITY",
           "PRED", "FLAGS", "TRUE", "MODULE", "PERCEPTS", "EMITTED", "MODE", "WANT",
           "FRAME", "ARGS", "CODE", "NECESSITY", "REINFORCED", "MASK", "ACTION", "OUTPUTS",
           "IO_SIZE", "REWARD", "FIRST_OUTPUT"]

#: gw_step/14: KB, Percepts, Emitted, Mode, Want (in); Result, then the fields (out).
ARITY = 14
RESULT = 5

# io: inputs
PRED, FLAGS, TRUE, MODULE, PERCEPTS, EMITTED, MODE, WANT = range(8)
# io: outputs
FRAME, ARGS, CODE, NECESSITY, REINFORCED, MASK, ACTION, OUTPUTS = range(8, 16)
IO_SIZE = 16
# fo: the reward and the outputs
REWARD, FIRST_OUTPUT = 0, 1

# What step() returns.
DONE = 0         # every field read, the extras []: the frame is discarded
RAISED = -1      # the call raised past the gateway's catch (PL_exception holds it)
READ_REST = -2   # the caller reads the result (not `true`) or the fields from the frame

_T = types.uintp                       # term_t, atom_t, fid_t, record_t, predicate_t
_I = types.intc
_open_frame = types.ExternalFunction("PL_open_foreign_frame", _T())
_discard_frame = types.ExternalFunction("PL_discard_foreign_frame", types.void(_T))
_new_term_refs = types.ExternalFunction("PL_new_term_refs", _T(types.size_t))
_new_term_ref = types.ExternalFunction("PL_new_term_ref", _T())
_put_atom = types.ExternalFunction("PL_put_atom", _I(_T, _T))
_put_int64 = types.ExternalFunction("PL_put_int64", _I(_T, types.int64))
_put_nil = types.ExternalFunction("PL_put_nil", _I(_T))
_put_term = types.ExternalFunction("PL_put_term", _I(_T, _T))
_recorded = types.ExternalFunction("PL_recorded", _I(_T, _T))
_call_predicate = types.ExternalFunction("PL_call_predicate", _I(_T, _I, _T, _T))
_get_atom = types.ExternalFunction("PL_get_atom", _I(_T, _T))
_get_int64 = types.ExternalFunction("PL_get_int64", _I(_T, _T))
_get_float = types.ExternalFunction("PL_get_float", _I(_T, _T))
_get_list = types.ExternalFunction("PL_get_list", _I(_T, _T, _T))
_get_nil = types.ExternalFunction("PL_get_nil", _I(_T))


def load(library: str) -> None:
    """Make ``library``'s (libswipl's) symbols visible to the compiled code, and compile
    :func:`step` (or load it from numba's cache) now rather than in the first step."""
    import llvmlite.binding

    llvmlite.binding.load_library_permanently(library)
    step.compile("(int64[::1], float64[::1])")


@njit(nogil=True, cache=True)
def step(io, fo):  # pragma: no cover - compiled: numba runs it, coverage does not see it
    """One ``gw_step/14`` call with ``io``/``fo`` as laid out above: :data:`DONE`,
    :data:`RAISED` or :data:`READ_REST`."""
    fid = _open_frame()
    a = _new_term_refs(ARITY)
    io[FRAME] = fid
    io[ARGS] = a
    _put_atom(a, io[MODULE])
    _recorded(io[PERCEPTS], a + 1)
    _put_int64(a + 2, io[EMITTED])
    _put_atom(a + 3, io[MODE])
    if io[WANT] != 0:
        _recorded(io[WANT], a + 4)
    else:
        _put_nil(a + 4)
    if _call_predicate(0, io[FLAGS], io[PRED], a) == 0:
        return RAISED
    iop = io.ctypes.data
    fop = fo.ctypes.data
    if _get_atom(a + RESULT, iop + 8 * CODE) == 0 or io[CODE] != io[TRUE]:
        return READ_REST
    if (_get_int64(a + 6, iop + 8 * CODE) == 0 or _get_atom(a + 7, iop + 8 * NECESSITY) == 0
            or _get_float(a + 9, fop + 8 * REWARD) == 0
            or _get_atom(a + 10, iop + 8 * REINFORCED) == 0
            or _get_int64(a + 11, iop + 8 * MASK) == 0
            or _get_int64(a + 12, iop + 8 * ACTION) == 0
            or _get_nil(a + 13) == 0):
        return READ_REST
    head = _new_term_ref()
    rest = _new_term_ref()
    _put_term(rest, a + 8)
    n = 0
    room = fo.shape[0] - FIRST_OUTPUT
    while _get_list(rest, head, rest) != 0:
        if n == room or _get_float(head, fop + 8 * (FIRST_OUTPUT + n)) == 0:
            return READ_REST
        n += 1
    if _get_nil(rest) == 0:
        return READ_REST
    io[OUTPUTS] = n
    _discard_frame(fid)       # nothing left to read
    io[FRAME] = 0
    return DONE
