/*  The guard of a gateway call: halt/0,1 called in a guarded goal, however often, and the
    progress watch of a world's batch of episodes.
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/guard').

:- begin_tests(guarded_halt).

%   SWI-Prolog honours a cancelled halt only nine times in a process: the wrapper of
%   halt/1 must stop every one of them, not cancel them.
test(halt_twenty_times_in_guarded_goals, Results == [true]) :-
    findall(R, ( between(1, 20, _),
                 guarded(halt, error(halt_called(goal), _)),
                 guarded(system:halt(3), error(halt_called(goal), _)),
                 guarded(call(halt), R0),
                 R0 = error(halt_called(_), _),
                 R = true ), Rs),
    sort(Rs, Results),
    length(Rs, 20).

test(a_halt_caught_by_the_goal_is_still_reported, R = error(halt_called(goal), _)) :-
    guarded(( catch(halt, _, true), X = 1, X == 1 ), R).

:- end_tests(guarded_halt).

:- begin_tests(progress_watch).

%   The tick handler, as the prof signal runs it inside a guarded call.
tick_in_call(Goal) :-
    guarded(( Goal, relrl_guard:tick(prof) ), Result),
    Result == true.

test(a_tick_outside_a_watch_does_nothing) :-
    tick_in_call(true).

test(a_tick_with_progress_within_the_limit_goes_on) :-
    tick_in_call(progress_watch(0.2, true)).

test(a_tick_after_the_limit_without_progress_stops_the_goal,
     R = error(time_limit_exceeded, _)) :-
    guarded(progress_watch(0.05, ( sleep(0.1), relrl_guard:tick(prof) )), R).

test(a_progress_mark_counts_the_limit_from_then) :-
    guarded(progress_watch(0.05, ( sleep(0.1), progress_mark,
                                   relrl_guard:tick(prof), relrl_guard:tick(prof) )), R),
    R == true.

test(the_watch_ends_with_the_goal) :-
    guarded(progress_watch(0.05, true), true),
    call_context(watch, none).

test(limit_must_be_positive, error(domain_error(positive_number, 0))) :-
    progress_watch(0, true).

test(limit_must_be_a_number, error(type_error(number, soon))) :-
    progress_watch(soon, true).

:- end_tests(progress_watch).
