:- module(relrl_memory,
          [ wm_insert/2,          % +KB, +Elements
            wm_element/3,         % ?KB, ?Element, ?Age
            wm_elements/2,        % +KB, -Pairs
            wm_clear/1,           % +KB
            wm_span/2,            % +KB, -Span
            wm_set_span/2,        % +KB, +Span
            wm_clock/2            % +KB, -Clock
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).

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
argument of every predicate names it. This module is the only one that asserts percepts.
*/

:- dynamic
    element_/3,     % KB, Element, Stamp
    clock_/2,       % KB, Clock: number of insertions so far
    span_/2.        % KB, Span

%!  wm_span(+KB, -Span) is det.
%
%   Span is the largest age an element of KB's memory can reach before it expires. The
%   default is 0: only the elements of the latest insertion are remembered. A domain sets
%   its own with a memory_span/1 declaration; wm_set_span/2 overrides it.

wm_span(KB, Span) :-
    (   span_(KB, Span0)
    ->  Span = Span0
    ;   catch(KB:memory_span(Span0), error(existence_error(procedure, _), _), fail)
    ->  Span = Span0
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
    retractall(span_(KB, _)),
    assertz(span_(KB, Span)).

%!  wm_clock(+KB, -Clock) is det.
%
%   Clock is the number of insertions into KB's memory so far.

wm_clock(KB, Clock) :-
    (   clock_(KB, Clock0)
    ->  Clock = Clock0
    ;   Clock = 0
    ).

%!  wm_insert(+KB, +Elements:list) is det.
%
%   One insertion: every element of Elements enters KB's memory with age 0, every other
%   element ages by one, and elements older than the span expire.
%
%   @error instantiation_error if an element is not ground.

wm_insert(KB, Elements) :-
    must_be(atom, KB),
    must_be(list, Elements),
    maplist(must_be_ground, Elements),
    wm_clock(KB, Clock0),
    Clock is Clock0 + 1,
    retractall(clock_(KB, _)),
    assertz(clock_(KB, Clock)),
    forall(member(E, Elements),
           ( retractall(element_(KB, E, _)),
             assertz(element_(KB, E, Clock))
           )),
    wm_span(KB, Span),
    Oldest is Clock - Span,
    forall(( element_(KB, E, Stamp), Stamp < Oldest ),
           retract(element_(KB, E, Stamp))).

must_be_ground(E) :-
    (   ground(E)
    ->  true
    ;   instantiation_error(E)
    ).

%!  wm_element(?KB, ?Element, ?Age) is nondet.
%
%   Element is in KB's memory with age Age (0 for the latest insertion).

wm_element(KB, Element, Age) :-
    element_(KB, Element, Stamp),
    clock_(KB, Clock),
    Age is Clock - Stamp.

%!  wm_elements(+KB, -Pairs:list) is det.
%
%   Pairs is the memory of KB as Age-Element pairs, youngest first, in insertion order.

wm_elements(KB, Pairs) :-
    findall(Age-E, wm_element(KB, E, Age), Pairs0),
    msort_by_age(Pairs0, Pairs).

msort_by_age(Pairs0, Pairs) :-
    map_list_to_pairs(pair_age, Pairs0, Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Pairs).

pair_age(Age-_, Age).

%!  wm_clear(+KB) is det.
%
%   Forget every element of KB's memory and reset its clock. The span is kept.

wm_clear(KB) :-
    must_be(atom, KB),
    retractall(element_(KB, _, _)),
    retractall(clock_(KB, _)).
