:- module(relrl_memory,
          [ wm_insert/2,          % +KB, +Elements
            wm_insert/3,          % +KB, +Record, +Elements
            wm_element/3,         % ?KB, ?Element, ?Age
            wm_has/2,             % +KB, ?Element
            wm_has_chk/2,         % +KB, ?Element
            wm_now/2,             % +KB, ?Element
            wm_has_stimulus/2,    % +KB, +Stimulus
            wm_stamped/3,         % +Record, -Clock, -Pairs
            wm_elements/2,        % +KB, -Pairs
            wm_clear/1,           % +KB
            wm_span/2,            % +KB, -Span
            wm_set_span/2,        % +KB, +Span
            wm_clock/2,           % +KB, -Clock
            wm_size/2,            % +KB, -Size
            wm_state/2,           % +KB, -State
            wm_set_state/2        % +KB, +State
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(kbstate).

/** <module> Working memory with age counters

The working memory of section 3 of da Silva & Romero (2012). It holds what the robot perceives
(percepts such as see(face), pose(face, frontal), hear(attention)), the last emitted response
and anything else the architecture wants to remember for a few steps.

Every element has an age. An element enters with age 0; every later *insertion* ages it by
one. An insertion is one call of wm_insert/2, normally the percepts of one control step, so
ages count control steps. Elements older than the memory's span expire at the next insertion.
Inserting an element that is already present renews it (its age becomes 0 again): the memory
never holds two copies of one element.

Each knowledge base (a Prolog module, see relrl.pl) has a memory of its own; the first
argument of every predicate names it. This module is the only one that stores percepts.
*/

:- use_module(library(pairs)).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

%   The memory of knowledge base KB is one term, wm(Clock, Span, Pairs, Elements, Now), the
%   `memory` part of KB's record (kbstate.pl): Clock counts insertions, Span is the expiry
%   age (or `default` until the domain's memory_span/1 is read), Pairs are Element-Stamp
%   pairs, newest first; Elements are the same elements alone and Now those of the latest
%   insertion (age 0), both in the same order: the perception predicates look elements up
%   many times a step, and memberchk/2 over plain terms takes half the time of a look-up
%   over pairs. A term in the record instead of asserted clauses keeps the robot's control
%   step free of assert/retract churn. Readers take the term and then unify it with the
%   wm/5 they want (State = wm(...)): a wm/5 pattern given to record_get/3 would first be built
%   on the global stack, every read.

%!  wm_span(+KB, -Span) is det.
%
%   Span is the largest age an element of KB's memory can reach before it expires. The
%   default is 0: only the elements of the latest insertion are remembered. A domain sets
%   its own with a memory_span/1 declaration; wm_set_span/2 overrides it.

wm_span(KB, Span) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, Span0, _, _, _),
    (   Span0 == default
    ->  domain_span(KB, Span)
    ;   Span = Span0
    ).

domain_span(KB, Span) :-
    (   current_predicate(KB:memory_span/1),
        KB:memory_span(Span0)
    ->  must_be(nonneg, Span0),
        Span = Span0
    ;   Span = 0
    ).

%!  wm_set_span(+KB, +Span) is det.
%
%   Elements of KB older than Span insertions expire.
%
%   @error type_error(nonneg, Span) if Span is not a non-negative integer.

wm_set_span(KB, Span) :-
    must_be(atom, KB),
    must_be(nonneg, Span),
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(Clock, _, Pairs, Elements, Now),
    record_set(Record, memory, wm(Clock, Span, Pairs, Elements, Now)).

%!  wm_clock(+KB, -Clock) is det.
%
%   Clock is the number of insertions into KB's memory so far.

wm_clock(KB, Clock) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(Clock, _, _, _, _).

%!  wm_insert(+KB, +Elements:list) is det.
%!  wm_insert(+KB, +Record, +Elements:list) is det.
%
%   One insertion: every element of Elements enters KB's memory with age 0, every other
%   element ages by one, and elements older than the span expire. Record is KB's record
%   (relrl_kbstate:kb_record/2), for a caller that has it (the control step).
%
%   @error instantiation_error if an element is not ground.

wm_insert(KB, New) :-
    kb_record(KB, Record),
    wm_insert(KB, Record, New).

wm_insert(KB, Record, New) :-
    (   atom(KB), is_list(New), ground(New)
    ->  true
    ;   must_be(atom, KB),
        must_be(list, New),
        member(E, New), \+ ground(E)
    ->  instantiation_error(E)
    ;   true
    ),
    record_get(Record, memory, State),
    State = wm(Clock0, Span0, Old, _, _),
    (   Span0 == default
    ->  domain_span(KB, Span)
    ;   Span = Span0
    ),
    Clock is Clock0 + 1,
    Oldest is Clock - Span,
    stamp(New, Clock, Pairs, KeptPairs, Now, Elements, KeptElements),
    keep_old(Old, New, Oldest, KeptPairs, KeptElements),
    record_set(Record, memory, wm(Clock, Span, Pairs, Elements, Now)).

%   The new memory is copied into the record (record_set/3), never linked (nb_linkval/2 or
%   nb_linkarg/3): a linked term is only as safe as every binding that built it, and a
%   signal handler that stores a term on the global stack in the middle of an insertion
%   (an alarm re-arming itself did) freezes the stack, so that the list cells bound after
%   it are trailed; the gateway's discarded frame, or any backtracking past the call, then
%   undid them and left the stored memory with an unbound tail
%   (tests/prolog/test_memory.plt, tests/relrl/test_memory_signals.py).

%   The new elements stamped, in front of PairsTail, and alone (Now), in front of Tail.
stamp([], _, PairsTail, PairsTail, [], Tail, Tail).
stamp([E|Es], Clock, Pairs, PairsTail, Now, Elements, Tail) :-
    (   memberchk(E, Es)                   % the same element twice in one insertion
    ->  stamp(Es, Clock, Pairs, PairsTail, Now, Elements, Tail)
    ;   Pairs = [E-Clock|Pairs1],
        Now = [E|Now1],
        Elements = [E|Elements1],
        stamp(Es, Clock, Pairs1, PairsTail, Now1, Elements1, Tail)
    ).

keep_old([], _, _, [], []).
keep_old([P|Ps], New, Oldest, Pairs, Elements) :-
    P = E-S,
    (   ( S < Oldest ; memberchk(E, New) )
    ->  keep_old(Ps, New, Oldest, Pairs, Elements)
    ;   Pairs = [P|Pairs1],
        Elements = [E|Elements1],
        keep_old(Ps, New, Oldest, Pairs1, Elements1)
    ).

%!  wm_element(?KB, ?Element, ?Age) is nondet.
%
%   Element is in KB's memory with age Age (0 for the latest insertion).

wm_element(KB, Element, Age) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(Clock, _, Pairs, _, _),
    member(Element-Stamp, Pairs),
    Age is Clock - Stamp.

%!  wm_has(+KB, ?Element) is nondet.
%
%   Element is in KB's memory (any age): wm_element/3 without computing ages, for the
%   perception predicates the engine runs many times a step.

wm_has(KB, Element) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, _, _, Elements, _),
    element_in(Element, Elements).

%!  wm_has_chk(+KB, ?Element) is semidet.
%
%   once(wm_has(KB, Element)).

wm_has_chk(KB, Element) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, _, _, Elements, _),
    memberchk(Element, Elements).

%!  wm_now(+KB, ?Element) is nondet.
%
%   Element entered (or was renewed in) KB's memory at the latest insertion: age 0.

wm_now(KB, Element) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, _, _, _, Now),
    element_in(Element, Now).

%   Element is in Elements (a memory holds one copy of an element at most).
element_in(Element, Elements) :-
    (   ground(Element)
    ->  memberchk(Element, Elements)
    ;   member(Element, Elements)
    ).

%!  wm_has_stimulus(+KB, +Stimulus) is semidet.
%
%   Stimulus is perceived through a sense (see(S), hear(S), smell(S), at(S)) or located
%   (at(S, Place)) in KB's memory.

wm_has_stimulus(KB, S) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, _, _, Elements, _),
    member(E, Elements),
    compound(E),
    (   compound_name_arguments(E, Sense, [S1])
    ->  S1 == S,
        sense_name(Sense)
    ;   E = at(S1, _)
    ->  S1 == S
    ),
    !.

sense_name(see).
sense_name(hear).
sense_name(smell).
sense_name(at).

%!  wm_stamped(+Record, -Clock, -Pairs:list) is det.
%
%   Clock is the number of insertions so far and Pairs the memory as Element-Stamp pairs,
%   newest first (an element's age is Clock - Stamp), of the knowledge base whose record
%   (relrl_kbstate:kb_record/2) is Record: the whole memory in one read, for the control
%   step's pass over it (the state code's).

wm_stamped(Record, Clock, Pairs) :-
    record_get(Record, memory, State),
    State = wm(Clock, _, Pairs, _, _).

%!  wm_elements(+KB, -Pairs:list) is det.
%
%   Pairs is the memory of KB as Age-Element pairs, youngest first, in insertion order.

wm_elements(KB, Pairs) :-
    findall(Age-E, wm_element(KB, E, Age), Pairs0),
    map_list_to_pairs(pair_age, Pairs0, Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Pairs).

pair_age(Age-_, Age).

%!  wm_clear(+KB) is det.
%
%   Forget every element of KB's memory and reset its clock. The span is kept.

wm_clear(KB) :-
    must_be(atom, KB),
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, Span, _, _, _),
    record_set(Record, memory, wm(0, Span, [], [], [])).

%!  wm_size(+KB, -Size:nonneg) is det.
%
%   Size is the number of elements in KB's memory.

wm_size(KB, Size) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(_, _, Pairs, _, _),
    length(Pairs, Size).

%!  wm_state(+KB, -State) is det.
%!  wm_set_state(+KB, +State) is det.
%
%   Save KB's whole memory as one term, wm(Clock, Span, Pairs) (Pairs: Element-Stamp,
%   newest first), and put it back: an evaluation can use the memory and leave it as it
%   found it.
%
%   @error domain_error(working_memory_state, State) if State is not such a term.

wm_state(KB, wm(Clock, Span, Pairs)) :-
    kb_record(KB, Record),
    record_get(Record, memory, State),
    State = wm(Clock, Span, Pairs, _, _).

wm_set_state(KB, State) :-
    must_be(atom, KB),
    (   State = wm(Clock, Span, Pairs), integer(Clock), is_list(Pairs),
        maplist(stamped, Pairs, Elements)
    ->  findall(E, ( member(E-S, Pairs), S =:= Clock ), Now),
        kb_set(KB, memory, wm(Clock, Span, Pairs, Elements, Now))
    ;   domain_error(working_memory_state, State)
    ).

stamped(E-S, E) :-
    integer(S).
