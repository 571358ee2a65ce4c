:- module(relrl_world_search,
          [ world_optimal/5,      % +KB, +Goal, +State, +Limit, -Steps
            world_bfs/5,          % +KB, +Goal, +State, +Limit, -Steps
            world_reachable/5,    % +KB, +Task, +Size, +Limit, -Verdict
            world_absent/4,       % +KB, +Task, +Size, -Absent
            world_verify/5        % +KB, +Task, +Size, +Count, -Pairs
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(assoc)).
:- use_module(rules).
:- use_module(engine, [engine_claim_random/1]).
:- use_module(world_step).

/** <module> Searching a world: optimal steps, reachability

The optimal number of steps of an episode (the world's optimal_steps/3, else a
breadth-first search over the world's own dynamics), whether a task can be reached at a
size at all, and a check of a world's declared optimal steps against the search. world.pl
re-exports these predicates.
*/


%!  world_optimal(+KB, +Goal, +State, +Limit, -Steps) is det.
%
%   Steps is the least number of actions that take State to one satisfying Goal: the
%   world's optimal_steps/3 when it defines it, else world_bfs/5 with at most Limit states;
%   `unreachable` when the search proves no state satisfying Goal reachable, `none` when
%   neither gives it (no search, or one stopped by its limit).

world_optimal(KB, Goal, State, Limit, Steps) :-
    (   world_defines(KB, optimal_steps/3)
    ->  (   rule_holds(KB, optimal_steps(Goal, State, N)), integer(N), N >= 0
        ->  Steps = N
        ;   world_contract(KB, optimal_steps(Goal, State, _), "optimal_steps/3 must give a \c
                     non-negative integer for ~q", [Goal])
        )
    ;   world_bfs(KB, Goal, State, Limit, Steps)
    ).

%!  world_bfs(+KB, +Goal, +State, +Limit:integer, -Steps) is det.
%
%   Breadth-first search over the world's own dynamics (world_legal/3, world_next/6): Steps
%   is the least number of actions from State to a state satisfying Goal; `unreachable`
%   when the search visited every state reachable from State (at most Limit) and none
%   satisfies Goal; `none` when it stopped at Limit states without finding one.

world_bfs(KB, Goal, State, Limit, Steps) :-
    must_be(nonneg, Limit),
    search(KB, Goal, State, Limit, Steps).

%   Steps: the least number of actions, `unreachable` when every reachable state was visited
%   without reaching Goal, `none` when Limit states were visited.
search(KB, Goal, State, Limit, Steps) :-
    (   world_holds_goal(KB, Goal, State)
    ->  Steps = 0
    ;   list_to_assoc([State-0], Seen),
        bfs([State], [], 0, KB, Goal, Seen, 1, Limit, Steps)
    ).

%   Frontier: the states at depth D; Next: those found at depth D + 1 so far.
bfs([], Next, D, KB, Goal, Seen, N, Limit, Steps) :-
    (   Next == []
    ->  Steps = unreachable
    ;   D1 is D + 1,
        bfs(Next, [], D1, KB, Goal, Seen, N, Limit, Steps)
    ).
bfs([S|Frontier], Next0, D, KB, Goal, Seen0, N0, Limit, Steps) :-
    world_legal(KB, S, As),
    expand(As, KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found),
    (   Found == true
    ->  Steps is D + 1
    ;   N > Limit
    ->  Steps = none
    ;   bfs(Frontier, Next, D, KB, Goal, Seen, N, Limit, Steps)
    ).

expand([], _, _, _, Seen, Seen, N, N, Next, Next, false).
expand([A|As], KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found) :-
    world_next(KB, Goal, S, A, S1, outcome(_, Reached)),
    (   Reached == true
    ->  Found = true, Seen = Seen0, N = N0, Next = Next0
    ;   get_assoc(S1, Seen0, _)
    ->  expand(As, KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found)
    ;   put_assoc(S1, Seen0, 0, Seen1),
        N1 is N0 + 1,
        expand(As, KB, Goal, S, Seen1, Seen, N1, N, [S1|Next0], Next, Found)
    ).

%!  world_reachable(+KB, +Task, +Size, +Limit, -Verdict) is det.
%
%   Verdict says whether the goal of Task (a task instance: on(b1, b2)) can be reached in
%   a world of Size objects, by a breadth-first search of at most Limit states from each of
%   three start states drawn with seed 0 (the generator of no knowledge base):
%   `reachable` from one of them, `unreachable` when each search visited every state it
%   could reach, else `unknown`. A task whose goal names an object the world does not
%   have at that size, or a relation no state can hold (on(b1, b1)), is `unreachable`.

world_reachable(KB, Task, Size, Limit, Verdict) :-
    must_be(positive_integer, Size),
    must_be(nonneg, Limit),
    set_random(seed(0)),
    findall(V, ( between(1, 3, _),
                 world_start(KB, Task, Size, S, Goal),
                 search(KB, Goal, S, Limit, Steps),
                 reach_verdict(Steps, V) ), Vs),
    (   memberchk(reachable, Vs)
    ->  Verdict = reachable
    ;   Vs = [_|_],
        forall(member(V, Vs), V == unreachable)
    ->  Verdict = unreachable
    ;   Verdict = unknown
    ).

reach_verdict(Steps, reachable) :-
    integer(Steps),
    !.
reach_verdict(unreachable, unreachable) :- !.
reach_verdict(_, unknown).

%!  world_absent(+KB, +Task, +Size, -Absent:list) is det.
%
%   Absent lists the arguments of the task instance Task (on(b1, b99): b1 and b99; numbers
%   pass) that stand in no fact of the three start states of Size objects world_reachable/5
%   draws: objects the world does not have at that size, found without a search (which a
%   large world cannot afford).

world_absent(KB, Task, Size, Absent) :-
    must_be(positive_integer, Size),
    set_random(seed(0)),
    findall(S, ( between(1, 3, _), world_start(KB, Task, Size, S, _) ), States),
    Task =.. [_|Args],
    exclude(named_in(States), Args, Absent0),
    exclude(number, Absent0, Absent).

named_in(States, Arg) :-
    member(State, States),
    member(Fact, State),
    sub_term(X, Fact),
    X == Arg,
    !.

%!  world_verify(+KB, +Task, +Size, +Count, -Pairs:list) is det.
%
%   Pairs are Declared-Searched for Count random start states of Task at Size: the
%   optimal number of steps world_optimal/5 gives (the world's optimal_steps/3) and the one
%   a breadth-first search finds (world_bfs/5, at most 200,000 states; `none` beyond).
%   Draws from the knowledge base's random stream.

world_verify(KB, Task, Size, Count, Pairs) :-
    must_be(nonneg, Count),
    engine_claim_random(KB),
    length(Pairs, Count),
    maplist(verify_one(KB, Task, Size), Pairs).

verify_one(KB, Task, Size, Declared-Searched) :-
    world_start(KB, Task, Size, S, Goal),
    world_optimal(KB, Goal, S, 0, Declared),
    world_bfs(KB, Goal, S, 200000, Searched).
