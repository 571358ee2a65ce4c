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

import hashlib

from numba import njit, types

from relrl.bridge.lib import FOREIGN
from relrl.errors import RelrlError

__all__ = ["load", "step", "DONE", "RAISED", "READ_REST", "ARITY", "STEP_ARGUMENTS", "RESULT",
           "FIELDS", "PRED", "FLAGS", "TRUE", "MODULE", "PERCEPTS", "EMITTED", "MODE", "WANT",
           "FRAME", "ARGS", "CODE", "NECESSITY", "REINFORCED", "MASK", "ACTION", "OUTPUTS",
           "IO_SIZE", "REWARD", "FIRST_OUTPUT", "signatures_digest"]

#: gw_step/14's arguments in order, the one statement of its layout (prolog/gateway.pl's
#: head is held to it by a test): the inputs, the result, then the step's fields in
#: :class:`relrl.engine.StepResult`'s order.
STEP_ARGUMENTS = ("kb", "percepts", "emitted", "mode", "want", "result",
                  "code", "necessity", "outputs", "reward", "reinforced", "mask", "action",
                  "extras")
ARITY = len(STEP_ARGUMENTS)
(_KB, _PERCEPTS, _EMITTED, _MODE, _WANT, RESULT, _CODE, _NECESSITY, _OUTPUTS, _REWARD,
 _REINFORCED, _MASK, _ACTION, _EXTRAS) = range(ARITY)
#: the fields' positions: ``range(*FIELDS)``
FIELDS = (_CODE, ARITY)

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

# The kernel's foreign functions, typed from relrl.bridge.lib.FOREIGN, the one table of
# their signatures: every handle and pointer is an unsigned machine word here.
_KINDS = {None: types.void, "term": types.uintp, "handle": types.uintp, "int": types.intc,
          "uint": types.uintc, "int64": types.int64, "double": types.float64,
          "size": types.size_t}
_USES = ("PL_open_foreign_frame", "PL_discard_foreign_frame", "PL_new_term_refs",
         "PL_new_term_ref", "PL_put_atom", "PL_put_int64", "PL_put_nil", "PL_put_term",
         "PL_recorded", "PL_call_predicate", "PL_get_atom", "PL_get_int64", "PL_get_float",
         "PL_get_list", "PL_get_nil")
#: numba caches the compiled step on disk keyed on this file alone: the digest of the
#: signatures above as FOREIGN gives them is written here, so that a change of FOREIGN
#: this file does not follow is refused (:func:`load`) instead of run by a stale kernel.
SIGNATURES_DIGEST = "9db46a46ca5a4c00"


def signatures_digest() -> str:
    """A digest of the kernel's foreign signatures as :data:`FOREIGN` gives them now."""
    text = repr([(name, FOREIGN[name]) for name in _USES])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _numba(kind: str | None) -> types.Type:
    return types.uintp if kind is not None and kind.endswith("*") else _KINDS[kind]


def _external(name: str) -> types.ExternalFunction:
    result, *arguments = FOREIGN[name]
    return types.ExternalFunction(name, _numba(result)(*map(_numba, arguments)))


(_open_frame, _discard_frame, _new_term_refs, _new_term_ref, _put_atom, _put_int64, _put_nil,
 _put_term, _recorded, _call_predicate, _get_atom, _get_int64, _get_float, _get_list,
 _get_nil) = (_external(name) for name in _USES)


def load(library: str) -> None:
    """Make ``library``'s (libswipl's) symbols visible to the compiled code, and compile
    :func:`step` (or load it from numba's cache) now rather than in the first step."""
    import llvmlite.binding

    if signatures_digest() != SIGNATURES_DIGEST:
        raise RelrlError("relrl.bridge.lib.FOREIGN changed the compiled step's signatures: "
                         f"set stepkernel.SIGNATURES_DIGEST to {signatures_digest()!r} (so "
                         "that numba compiles the step anew)")
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
    _put_atom(a + _KB, io[MODULE])
    _recorded(io[PERCEPTS], a + _PERCEPTS)
    _put_int64(a + _EMITTED, io[EMITTED])
    _put_atom(a + _MODE, io[MODE])
    if io[WANT] != 0:
        _recorded(io[WANT], a + _WANT)
    else:
        _put_nil(a + _WANT)
    if _call_predicate(0, io[FLAGS], io[PRED], a) == 0:
        return RAISED
    iop = io.ctypes.data
    fop = fo.ctypes.data
    if _get_atom(a + RESULT, iop + 8 * CODE) == 0 or io[CODE] != io[TRUE]:
        return READ_REST
    if (_get_int64(a + _CODE, iop + 8 * CODE) == 0
            or _get_atom(a + _NECESSITY, iop + 8 * NECESSITY) == 0
            or _get_float(a + _REWARD, fop + 8 * REWARD) == 0
            or _get_atom(a + _REINFORCED, iop + 8 * REINFORCED) == 0
            or _get_int64(a + _MASK, iop + 8 * MASK) == 0
            or _get_int64(a + _ACTION, iop + 8 * ACTION) == 0
            or _get_nil(a + _EXTRAS) == 0):
        return READ_REST
    head = _new_term_ref()
    rest = _new_term_ref()
    _put_term(rest, a + _OUTPUTS)
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
