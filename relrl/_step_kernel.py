"""The control step's crossing into Prolog as one compiled call (numba).

A control step calls ``relrl_gateway:gw_step/15`` once. Done from Python, that call is some
twenty-five foreign calls through ctypes — open a frame, make the argument references, put the
knowledge base, the percepts, the response emitted, the mode, what else is wanted and the
time limit, call the predicate, read the result's fields one by one — at about 0.3 µs each:
7–8 µs a step, a sixth of the whole step. :func:`step` makes the same calls, in the same
order, from compiled code: one call from Python.

The foreign functions are named, not addressed (:class:`numba.types.ExternalFunction`):
the compiled code is cached on disk and the names are resolved in each process, after
:func:`relrl.kb` made libswipl's symbols visible (``llvmlite.binding
.load_library_permanently``). The kernel holds no Python object and releases the GIL for
the step, as the ctypes call of ``PL_call_predicate`` does.

Layout of the two arrays :func:`step` reads and writes (indices are the constants below):

``io`` (int64): in — the predicate handle of ``gw_step/15``, the query flags, the atom
``true``, the knowledge base's module (atom), the percepts' record, the response emitted
(index or -1), the mode (atom), the record of what else is wanted (0: nothing); out — the
frame, the first argument reference, the state code, the necessity (atom), ``reinforced``
(atom), the response mask, the engine's action (index or -1), the number of outputs, and
whether the extras are not ``[]``.

``fo`` (float64): in — the time limit; out — the reward, then the necessity units' outputs.

When every field was read and the extras are ``[]``, the kernel discards the frame (``io``'s
frame is then 0). Otherwise the frame is left open: the caller reads what the kernel could
not (an error, a result other than ``true``, a field that is not a small integer, atom or
float, more outputs than ``fo`` holds, the extras) from the argument references, then
discards it.
"""

from __future__ import annotations

from numba import njit, types

__all__ = ["step", "RAISED", "NOT_TRUE", "SLOW",
           "PRED", "FLAGS", "TRUE", "MODULE", "PERCEPTS", "EMITTED", "MODE", "WANT",
           "FRAME", "ARGS", "CODE", "NECESSITY", "REINFORCED", "MASK", "ACTION", "OUTPUTS",
           "EXTRAS", "IO_SIZE", "LIMIT", "REWARD", "FIRST_OUTPUT"]

# io: inputs
PRED, FLAGS, TRUE, MODULE, PERCEPTS, EMITTED, MODE, WANT = range(8)
# io: outputs
FRAME, ARGS, CODE, NECESSITY, REINFORCED, MASK, ACTION, OUTPUTS, EXTRAS = range(8, 17)
IO_SIZE = 17
# fo: the time limit in, the reward and the outputs out
LIMIT, REWARD, FIRST_OUTPUT = 0, 0, 1

# What step() returns besides 0 (every field read).
RAISED = -1      # the call raised past the gateway's catch (PL_exception holds it)
NOT_TRUE = -2    # the gateway's Result is not `true` (false, or error(E, Message))
SLOW = -3        # a field must be converted by the caller

_T = types.uintp                       # term_t, atom_t, fid_t, record_t, predicate_t
_I = types.intc
_open_frame = types.ExternalFunction("PL_open_foreign_frame", _T())
_discard_frame = types.ExternalFunction("PL_discard_foreign_frame", types.void(_T))
_new_term_refs = types.ExternalFunction("PL_new_term_refs", _T(types.size_t))
_new_term_ref = types.ExternalFunction("PL_new_term_ref", _T())
_put_atom = types.ExternalFunction("PL_put_atom", _I(_T, _T))
_put_int64 = types.ExternalFunction("PL_put_int64", _I(_T, types.int64))
_put_float = types.ExternalFunction("PL_put_float", _I(_T, types.float64))
_put_nil = types.ExternalFunction("PL_put_nil", _I(_T))
_put_term = types.ExternalFunction("PL_put_term", _I(_T, _T))
_recorded = types.ExternalFunction("PL_recorded", _I(_T, _T))
_call_predicate = types.ExternalFunction("PL_call_predicate", _I(_T, _I, _T, _T))
_get_atom = types.ExternalFunction("PL_get_atom", _I(_T, _T))
_get_int64 = types.ExternalFunction("PL_get_int64", _I(_T, _T))
_get_float = types.ExternalFunction("PL_get_float", _I(_T, _T))
_get_list = types.ExternalFunction("PL_get_list", _I(_T, _T, _T))
_get_nil = types.ExternalFunction("PL_get_nil", _I(_T))


@njit(nogil=True, cache=True)
def step(io, fo):  # pragma: no cover - compiled (its Python twin is KnowledgeBase.step's)
    """One ``gw_step/15`` call with ``io``/``fo`` as laid out above: 0 when every field was
    read, else :data:`RAISED`, :data:`NOT_TRUE` or :data:`SLOW`."""
    fid = _open_frame()
    a = _new_term_refs(15)
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
    _put_float(a + 5, fo[LIMIT])
    if _call_predicate(0, io[FLAGS], io[PRED], a) == 0:
        return RAISED
    iop = io.ctypes.data
    fop = fo.ctypes.data
    if _get_atom(a + 6, iop + 8 * CODE) == 0 or io[CODE] != io[TRUE]:
        return NOT_TRUE
    if (_get_int64(a + 7, iop + 8 * CODE) == 0 or _get_atom(a + 8, iop + 8 * NECESSITY) == 0
            or _get_float(a + 10, fop + 8 * REWARD) == 0
            or _get_atom(a + 11, iop + 8 * REINFORCED) == 0
            or _get_int64(a + 12, iop + 8 * MASK) == 0
            or _get_int64(a + 13, iop + 8 * ACTION) == 0):
        return SLOW
    head = _new_term_ref()
    rest = _new_term_ref()
    _put_term(rest, a + 9)
    n = 0
    room = fo.shape[0] - FIRST_OUTPUT
    while _get_list(rest, head, rest) != 0:
        if n == room or _get_float(head, fop + 8 * (FIRST_OUTPUT + n)) == 0:
            return SLOW
        n += 1
    if _get_nil(rest) == 0:
        return SLOW
    io[OUTPUTS] = n
    io[EXTRAS] = 1 - _get_nil(a + 14)
    if io[EXTRAS] == 0:       # nothing left to read: the frame goes now
        _discard_frame(fid)
        io[FRAME] = 0
    return 0
