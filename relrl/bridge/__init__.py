"""relrl's transport to SWI-Prolog, in layers that import only the ones below them.

=====================  ====================================================================
:mod:`~.lib`           libswipl found, loaded and started once; the foreign functions, typed
:mod:`~.marshal`       Python values to Prolog terms and back (see :mod:`relrl.terms`)
:mod:`~.deadline`      the time limit and Ctrl-C of a running call (a watchdog thread)
:mod:`~.calls`         a goal run once, the control step, an open query; Prolog's errors
                       as relrl exceptions
=====================  ====================================================================

:class:`relrl.kb.KnowledgeBase` is the facade over them; nothing else in relrl calls Prolog.
"""

from __future__ import annotations

__all__: list[str] = []
