"""Reading a Prolog term for Python in one compiled call (numba).

:meth:`relrl.kb._Engine.get` reads a term node by node through ctypes, three or four
foreign calls of about 0.3 µs per node: a learner's tree for the monitor (some 3,300 nodes
after a few thousand steps) took 9 ms to read, beside 3.5 ms to build. :func:`flatten`
walks the term in compiled code and writes it as a flat stream that Python turns into
values in one pass (:meth:`relrl.kb._Engine.read`):

=================  =====================================================================
``ATOM h``          an atom, by handle (Python looks its name up)
``INT v``           an integer that fits 64 bits
``FLOAT i``         a float, ``nums[i]``
``STRING o n``      a string, UTF-8 bytes ``text[o:o+n]``
``NIL``             ``[]``
``LIST n``          a list of ``n`` elements, then its tail (``NIL`` for a proper list)
``TERM h a``        a compound named by atom ``h`` with ``a`` arguments, which follow
``OTHER r``         anything else — a variable, a big integer, a rational, a blob, a
                    dict — at term reference ``r``, read by the node-by-node reader
=================  =====================================================================

Atoms are passed by handle: they are alive while the term is, and the caller keeps the
frame open until it has read them. The foreign functions are named, not addressed, as in
:mod:`relrl._step_kernel` (whose loader makes libswipl's symbols visible).
"""

from __future__ import annotations

from numba import njit, types

__all__ = ["flatten", "ATOM", "INT", "FLOAT", "STRING", "NIL", "LIST", "TERM", "OTHER",
           "FULL", "DEEP", "LONG"]

ATOM, INT, FLOAT, STRING, NIL, LIST, TERM, OTHER = range(8)
# What flatten() returns besides the stream's length.
FULL = -1        # an array is too small: grow them and call again
DEEP = -2        # nested deeper than the limit (or cyclic)
LONG = -3        # a list longer than the limit (or cyclic)

_PL_VARIABLE, _PL_ATOM, _PL_INTEGER, _PL_FLOAT, _PL_STRING = 1, 2, 3, 5, 6
_PL_TERM, _PL_NIL, _PL_LIST_PAIR, _PL_CYCLIC_TERM = 7, 8, 10, 42
_CVT_STRING, _REP_UTF8 = 0x2, 0x00100000

_T = types.uintp
_I = types.intc
_term_type = types.ExternalFunction("PL_term_type", _I(_T))
_get_atom = types.ExternalFunction("PL_get_atom", _I(_T, _T))
_get_int64 = types.ExternalFunction("PL_get_int64", _I(_T, _T))
_get_float = types.ExternalFunction("PL_get_float", _I(_T, _T))
_get_nchars = types.ExternalFunction("PL_get_nchars", _I(_T, _T, _T, types.uintc))
_get_name_arity = types.ExternalFunction("PL_get_name_arity_sz", _I(_T, _T, _T))
_get_arg = types.ExternalFunction("PL_get_arg_sz", _I(types.size_t, _T, _T))
_get_list = types.ExternalFunction("PL_get_list", _I(_T, _T, _T))
_skip_list = types.ExternalFunction("PL_skip_list", _I(_T, _T, _T))
_new_term_ref = types.ExternalFunction("PL_new_term_ref", _T())
_new_term_refs = types.ExternalFunction("PL_new_term_refs", _T(types.size_t))
_put_term = types.ExternalFunction("PL_put_term", _I(_T, _T))
_memcpy = types.ExternalFunction("memcpy", _T(_T, _T, types.size_t))

# The walk's stack: what each entry is.
_ITEM, _ELEMENTS = 0, 1


@njit(nogil=True, cache=True)
def flatten(t, ops, nums, text, stack, max_depth, max_list):  # pragma: no cover - compiled
    """Write the term at reference ``t`` into ``ops`` (int64), ``nums`` (float64) and
    ``text`` (uint8) as laid out above, using ``stack`` (int64, 4 columns) for the walk.
    Returns the stream's length in ``ops``, or :data:`FULL`, :data:`DEEP`, :data:`LONG`."""
    scratch = stack.ctypes.data           # stack[0, 0:3] as out-parameters (row 0 unused)
    n_ops = n_nums = n_text = 0
    top = 1
    stack[1, 0] = _ITEM
    stack[1, 1] = t
    stack[1, 2] = 0
    while top > 0:
        kind = stack[top, 0]
        ref = stack[top, 1]
        depth = stack[top, 2]
        if kind == _ELEMENTS:             # the next element of a list (ref: the rest)
            left = stack[top, 3]
            head = _new_term_ref()
            _get_list(ref, head, ref)
            if left == 1:
                top -= 1
            else:
                stack[top, 3] = left - 1
            ref = head
        else:
            top -= 1
        if depth > max_depth:
            return DEEP
        if n_ops + 3 > ops.shape[0] or top + 3 > stack.shape[0]:
            return FULL
        tt = _term_type(ref)
        if tt == _PL_ATOM:
            _get_atom(ref, scratch)
            ops[n_ops] = ATOM
            ops[n_ops + 1] = stack[0, 0]
            n_ops += 2
        elif tt == _PL_INTEGER and _get_int64(ref, scratch) != 0:
            ops[n_ops] = INT
            ops[n_ops + 1] = stack[0, 0]
            n_ops += 2
        elif tt == _PL_FLOAT:
            if n_nums == nums.shape[0]:
                return FULL
            _get_float(ref, nums.ctypes.data + 8 * n_nums)
            ops[n_ops] = FLOAT
            ops[n_ops + 1] = n_nums
            n_nums += 1
            n_ops += 2
        elif tt == _PL_STRING:
            _get_nchars(ref, scratch, scratch + 8, _CVT_STRING | _REP_UTF8)
            size = stack[0, 0]
            if n_text + size > text.shape[0]:
                return FULL
            _memcpy(text.ctypes.data + n_text, stack[0, 1], size)
            ops[n_ops] = STRING
            ops[n_ops + 1] = n_text
            ops[n_ops + 2] = size
            n_text += size
            n_ops += 3
        elif tt == _PL_NIL:
            ops[n_ops] = NIL
            n_ops += 1
        elif tt == _PL_LIST_PAIR:
            tail = _new_term_ref()
            found = _skip_list(ref, tail, scratch)
            length = stack[0, 0]
            if found == _PL_CYCLIC_TERM or length > max_list:
                return LONG               # cyclic, or too long (a tail that is not a
                                          # list, [a|b], comes as the tail)
            ops[n_ops] = LIST
            ops[n_ops + 1] = length
            n_ops += 2
            top += 1                      # the tail comes after the elements
            stack[top, 0] = _ITEM
            stack[top, 1] = tail
            stack[top, 2] = depth + 1
            rest = _new_term_ref()
            _put_term(rest, ref)
            top += 1
            stack[top, 0] = _ELEMENTS
            stack[top, 1] = rest
            stack[top, 2] = depth + 1
            stack[top, 3] = length
        elif tt == _PL_TERM:
            _get_name_arity(ref, scratch, scratch + 8)
            arity = stack[0, 1]
            if top + arity + 1 > stack.shape[0]:
                return FULL
            ops[n_ops] = TERM
            ops[n_ops + 1] = stack[0, 0]
            ops[n_ops + 2] = arity
            n_ops += 3
            if arity > 0:
                args = _new_term_refs(arity)
                for i in range(arity):
                    _get_arg(i + 1, ref, args + i)
                for i in range(arity - 1, -1, -1):
                    top += 1
                    stack[top, 0] = _ITEM
                    stack[top, 1] = args + i
                    stack[top, 2] = depth + 1
        else:
            ops[n_ops] = OTHER
            ops[n_ops + 1] = ref
            n_ops += 2
    return n_ops
