:- module(relrl_percept_check,
          [ world_problems/3,     % +KB, +Vocabulary, -Problems
            unread_percepts/3     % +KB, +Percepts, -Unread
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(check, [body_goal/2, data_goal/2, clause_location/3]).

/** <module> What a domain perceives, against what a world perceives

A domain reads working memory through percept/1, memory/2, the senses see/1, hear/1,
smell/1, at/1 and at/2 (relrl_senses). A world (the simulator, the episode world, a
camera) produces only some percepts: its *vocabulary*, a list of percept terms in which a
variable stands for any value, e.g. [see(face), pose(face, frontal), pose(face, left),
hear(_)] (the Python side declares them, see the `percepts` package).

  - world_problems/3 finds the facts of a domain that can never hold in a world, because
    every definition needs a percept the world never produces (`pose(face, left)` where
    the world perceives poses as `left_1`, `left_2`), and the stimuli the world never
    perceives. The analysis follows the definitions (conjunctions, disjunctions,
    if-then-else, calls of the domain's own predicates) and never claims more than it can
    show: negation, aggregation, dynamic predicates and goals it does not know count as
    possibly true.
  - unread_percepts/3 finds the percepts (inserted by hand with the shell's :add) that no
    stimulus, fact or rule of the domain perceives.
*/

%!  world_problems(+KB, +Vocabulary:list, -Problems:list) is det.
%
%   Problems lists problem(File, Line, Message), in file order, for every fact of KB that
%   can never hold and every stimulus that is never perceived when working memory holds only
%   percepts of Vocabulary.

world_problems(KB, Vocabulary, Problems) :-
    must_be(atom, KB),
    must_be(list, Vocabulary),
    findall(P, world_problem(KB, Vocabulary, P), Problems0),
    sort(Problems0, Problems1),
    predsort(by_location, Problems1, Problems).

by_location(Order, problem(F1, L1, M1), problem(F2, L2, M2)) :-
    compare(Order0, F1-L1, F2-L2),
    (   Order0 == (=)
    ->  compare(Order, M1, M2)
    ;   Order = Order0
    ).

world_problem(KB, Vocabulary, problem(File, Line, Message)) :-
    own_clause(KB, fact(Fact), true, Ref),
    callable(Fact),
    blocked(KB, Vocabulary, Fact, 0, [], Needs),
    clause_location(Ref, File, Line),
    Options = [quoted(true), spacing(next_argument)],
    format(string(Message), "fact ~W can never hold in this world: it needs ~W, which \c
                            the world never perceives", [Fact, Options, Needs, Options]).
world_problem(KB, Vocabulary, problem(File, Line, Message)) :-
    own_clause(KB, stimulus(Stimulus), true, Ref),
    \+ ( stimulus_percept(Stimulus, Percept),
         possible(Vocabulary, Percept) ),
    clause_location(Ref, File, Line),
    format(string(Message), "stimulus ~q is never perceived in this world", [Stimulus]).

stimulus_percept(Stimulus, Percept) :-
    relrl_senses:sense(Sense),
    Percept =.. [Sense, Stimulus].
stimulus_percept(Stimulus, at(Stimulus, _)).

%   A percept unifies with a term of the vocabulary.
possible(Vocabulary, Percept) :-
    \+ \+ memberchk(Percept, Vocabulary).

%!  blocked(+KB, +Vocabulary, +Goal, +Depth, +Stack, -Needs) is semidet.
%
%   Goal, run in KB, can never succeed while working memory holds only percepts of
%   Vocabulary: Needs is a percept it needs that the vocabulary lacks.

blocked(_, _, Goal, _, _, _) :-
    var(Goal), !, fail.
blocked(KB, V, (A, B), D, S, Needs) :- !,
    (   blocked(KB, V, A, D, S, Needs)
    ->  true
    ;   blocked(KB, V, B, D, S, Needs)
    ).
blocked(KB, V, (C -> T ; E), D, S, Needs) :- !,
    blocked(KB, V, (C, T), D, S, Needs),
    blocked(KB, V, E, D, S, _).
blocked(KB, V, (C *-> T ; E), D, S, Needs) :- !,
    blocked(KB, V, (C, T), D, S, Needs),
    blocked(KB, V, E, D, S, _).
blocked(KB, V, (A ; B), D, S, Needs) :- !,
    blocked(KB, V, A, D, S, Needs),
    blocked(KB, V, B, D, S, _).
blocked(KB, V, (C -> T), D, S, Needs) :- !,
    blocked(KB, V, (C, T), D, S, Needs).
blocked(KB, V, (C *-> T), D, S, Needs) :- !,
    blocked(KB, V, (C, T), D, S, Needs).
blocked(KB, V, call(G), D, S, Needs) :- !,
    blocked(KB, V, G, D, S, Needs).
blocked(KB, V, once(G), D, S, Needs) :- !,
    blocked(KB, V, G, D, S, Needs).
blocked(KB, V, M:G, D, S, Needs) :- !,
    M == KB,
    blocked(KB, V, G, D, S, Needs).
blocked(_, V, Goal, _, _, Needs) :-
    percept_read(Goal, Percept),
    !,
    \+ possible(V, Percept),
    Needs = Percept.
blocked(KB, V, Goal, D, S, Needs) :-
    sense_of_fact(Goal, Percept, Fact),
    !,
    (   \+ possible(V, Percept)
    ->  Needs = Percept
    ;   blocked(KB, V, Fact, D, S, Needs)
    ).
blocked(KB, V, Goal, D, S, Needs) :-
    D < 12,
    callable(Goal),
    \+ ( member(G0, S), G0 =@= Goal ),            % a recursive call: may hold
    domain_predicate(KB, Goal),
    \+ predicate_property(KB:Goal, dynamic),
    findall(Body, own_clause(KB, Goal, Body, _), Bodies),
    Bodies \== [],
    D1 is D + 1,
    blocked_all(Bodies, KB, V, D1, [Goal|S], Needs).

blocked_all([], _, _, _, _, _).
blocked_all([Body|Bodies], KB, V, D, S, Needs) :-
    blocked(KB, V, Body, D, S, Needs),
    blocked_all(Bodies, KB, V, D, S, _).

%   The working-memory element a perception predicate reads (relrl_senses:perceived/3
%   for the senses: see(face) reads see(face); see(frontal(face)) is sense_of_fact/3).
percept_read(percept(E), E).
percept_read(memory(E, _), E).
percept_read(at(S, P), at(S, P)).
percept_read(Goal, Goal) :-
    sense_goal(Goal, _, What),
    (   var(What)
    ;   atomic(What)
    ;   \+ ( What =.. [_, S], atomic(S) )
    ),
    !.

%   see(F(S)) reads see(S) and needs the fact F(S).
sense_of_fact(Goal, Percept, What) :-
    sense_goal(Goal, Sense, What),
    compound(What),
    What =.. [_, Stimulus],
    atomic(Stimulus),
    Percept =.. [Sense, Stimulus].

sense_goal(Goal, Sense, What) :-
    compound(Goal),
    compound_name_arity(Goal, Sense, 1),
    relrl_senses:sense(Sense),
    arg(1, Goal, What).

%   A predicate the domain defines itself (not relrl's, not a library's).
domain_predicate(KB, Goal) :-
    (   var(Goal)
    ->  current_predicate(KB:Name/Arity),
        functor(Goal, Name, Arity)
    ;   functor(Goal, Name, Arity),
        current_predicate(KB:Name/Arity)
    ),
    \+ predicate_property(KB:Goal, imported_from(_)),
    \+ predicate_property(KB:Goal, built_in).

own_clause(KB, Head, Body, Ref) :-
    domain_predicate(KB, Head),
    \+ predicate_property(KB:Head, foreign),
    clause(KB:Head, Body, Ref).

%!  unread_percepts(+KB, +Percepts:list, -Unread:list) is det.
%
%   Unread are the Percepts that no stimulus, fact or rule of KB perceives: not a sense of a
%   declared stimulus (see(face) for stimulus(face)), and matched by no perception goal in
%   the domain's rules, fact definitions, necessity inputs, behaviour antecedents or tests.

unread_percepts(KB, Percepts, Unread) :-
    must_be(atom, KB),
    must_be(list, Percepts),
    findall(Read, domain_read(KB, Read), Reads),
    exclude(perceived_by(KB, Reads), Percepts, Unread).

perceived_by(KB, _, Percept) :-
    nonvar(Percept),
    kb_stimulus(KB, Stimulus),
    stimulus_percept(Stimulus, Percept),
    !.
perceived_by(_, Reads, Percept) :-
    possible(Reads, Percept).

%   Every working-memory element (pattern) the domain's goals read.
domain_read(KB, Read) :-
    own_clause(KB, Head, Body, _),
    (   body_goal(Body, Goal)
    ;   (   data_goal(Head, Goal0)
        ;   Head = relation(Goal0)
        ),
        body_goal(Goal0, Goal)
    ),
    goal_read(Goal, Read).

goal_read(Goal, Read) :-
    percept_read(Goal, Read).
goal_read(Goal, Read) :-
    sense_of_fact(Goal, Read, _).
