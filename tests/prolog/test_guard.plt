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

:- begin_tests(stop_signals).

%   A message that takes a Ctrl-C as it is formatted: the guard's handler formats the
%   error of a goal (error_result/2), and the watchdog raises Ctrl-C again every tenth of a
%   second (at once for a second Ctrl-C) until the call returns. The handler runs as that
%   raise finds it: the interrupt handler called from within the message.
:- multifile prolog:message//1.
prolog:message(relrl_test_signal_in_handler) -->
    { relrl_guard:interrupt(usr1) },
    [ 'an error whose message takes a Ctrl-C' ].

test(a_ctrl_c_while_the_guard_handles_an_error_stays_inside_it,
     R = error(relrl_test_signal_in_handler, _)) :-
    guarded(throw(relrl_test_signal_in_handler), R).

test(a_ctrl_c_in_the_goal_is_the_result, R == error(interrupted, "interrupted")) :-
    guarded(relrl_guard:interrupt(usr1), R).

test(the_flag_is_down_after_an_interrupted_call) :-
    guarded(relrl_guard:interrupt(usr1), _),
    call_context(active, false).

:- end_tests(stop_signals).
