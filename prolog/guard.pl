:- module(relrl_guard,
          [ guarded/2,            % :Goal, -Result
            error_result/2,       % +Exception, -Result
            halt_message/2,       % +Where, -Message
            gw_take_abort/1,      % -Where
            text_failed/1,        % +Error
            progress_watch/2,     % +Limit, :Goal
            progress_mark/0
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(prolog_wrap)).

/** <module> The guard of a gateway call: results instead of exceptions, halt, signals

Every call from Python runs its goal through guarded/2: once, its exceptions turned into a
result term, so that no Prolog exception escapes into the host. Nothing a loaded file or a
rule does can end the program: halt/0,1 called during a guarded call never reaches the
system's halt/1 (wrapped by library(prolog_wrap), which covers halt/0, `system:halt/1` and
call/N alike) and is reported: in a directive it fails, and the load names the file and
line; in a goal it throws `relrl_halt_called`, so the goal stops there and the rule that
called it is named (rules.pl wraps the exception as it wraps any other). SWI-Prolog honours
a cancel_halt/1 only nine times in a process, so cancelling is the fallback of the at_halt
hook for a halt that comes from C, not the way. abort/0, which unwinds past every catch/3,
is noted for gw_take_abort/1 on its way out.

The time limit and Ctrl-C come from the host (relrl/bridge/deadline.py): a watchdog thread
raises a Prolog signal in this thread while a call runs too long (vtalrm) or the user
presses Ctrl-C (usr1), and ticks a watched call (prof). The handlers below throw `time_limit_exceeded`, as
call_with_time_limit/2's alarm does, or `relrl_interrupted`, inside the running goal; a
signal that arrives when no guarded call runs (it was raised as the call returned) does
nothing. Under progress_watch/2 (a batch of a world's episodes, which may rightly run for
an hour) the limit is the time since the last progress_mark/0 (a world's step): a rule
that loops is stopped once it has run Limit seconds, however long the batch. The host deregisters the OS handlers of both signals: only Prolog's signal table
knows them.
*/

:- meta_predicate guarded(0, -), once_result(0, -), progress_watch(+, 0).

%!  guarded(:Goal, -Result) is det.
%
%   Run Goal once. Result is `true` (Goal's bindings are kept), `false`, or
%   error(Kind, Message) (see error_result/2), also for a halt/0,1 called while Goal ran.
%
%   The flag that says a guarded call runs is set and restored inside one catch/3, and its
%   handler restores it too: an exception at any point — the goal's, the time limit's,
%   Ctrl-C's, even while the flag is restored — leaves it as it was, and abort/0 runs the
%   handler before it unwinds on.

guarded(Goal, Result) :-
    (   nb_current(relrl_active, Was)
    ->  true
    ;   Was = false
    ),
    catch(guarded_call(Goal, Was, Result0), E, guarded_error(E, Was, Result0)),
    halt_result(Result0, Result).

guarded_call(Goal, Was, Result) :-
    nb_setval(relrl_active, true),
    once_result(Goal, Result),
    nb_setval(relrl_active, Was).

guarded_error(E, Was, Result) :-
    call_cleanup(error_result(E, Result), nb_setval(relrl_active, Was)).

once_result(Goal, Result) :-
    (   call(Goal)
    ->  Result = true
    ;   Result = false
    ).

%   Result0, or the error for a halt/0,1 called while the call ran (Result0 itself when it
%   is already that error, naming the rule).
halt_result(Result0, Result) :-
    (   nb_current(relrl_halt, Where),
        Where \== none
    ->  nb_setval(relrl_halt, none),
        (   halt_error(Result0)
        ->  Result = Result0
        ;   halt_message(Where, Message),
            Result = error(halt_called(Where), Message)
        )
    ;   Result = Result0
    ).

halt_error(error(halt_called(_), _)).
halt_error(error(rule_error(_, _, halt_called), _)).

%!  halt_message(+Where, -Message) is det.
%
%   Message says that halt/0,1 was called at Where (File:Line of a directive, or `goal`).

halt_message(Where, Message) :-
    (   Where = File:Line
    ->  format(string(Message), "~w:~w: halt/0,1 called while loading (a loaded file \c
                                 cannot end relrl)", [File, Line])
    ;   format(string(Message), "halt/0,1 called by a goal (a rule cannot end relrl)", [])
    ).

:- initialization(wrap_predicate(system:halt(Status), relrl_guard, Halt,
                                  relrl_guard:guarded_halt(Status, Halt))).

%   The wrapper of halt/1 (halt/0 calls it): outside a guarded call, the system's halt;
%   inside one, remember where it came from, then fail (a directive: the load goes on and
%   reports it at its line) or throw relrl_halt_called (a goal: it stops).
:- meta_predicate guarded_halt(+, 0).
guarded_halt(_Status, Halt) :-
    (   nb_current(relrl_active, true)
    ->  load_location(Where),
        nb_setval(relrl_halt, Where),
        Where == goal,
        throw(relrl_halt_called)
    ;   call(Halt)
    ).

:- initialization(at_halt(relrl_guard:halt_hook)).

%   at_halt/1 hook: inside a guarded call, cancel the halt and remember where it came from.
halt_hook :-
    (   nb_current(relrl_active, true)
    ->  load_location(Where),
        nb_setval(relrl_halt, Where),
        cancel_halt(relrl_guard)
    ;   true
    ).

load_location(Where) :-
    (   prolog_load_context(file, File),
        prolog_load_context(term_position, Pos),
        stream_position_data(line_count, Pos, Line)
    ->  Where = File:Line
    ;   Where = goal
    ).

:- initialization(on_signal(vtalrm, _, relrl_guard:time_up)).
:- initialization(on_signal(usr1, _, relrl_guard:interrupt)).
:- initialization(on_signal(prof, _, relrl_guard:tick)).

%   The running call's time limit passed: remember where a file being loaded was (a
%   directive that never ends), then throw as call_with_time_limit/2 does.
time_up(_Signal) :-
    (   nb_current(relrl_active, true)
    ->  load_location(Where),
        nb_setval(relrl_timeout_where, Where),
        throw(time_limit_exceeded)
    ;   true
    ).

%   A watched call's tick (every tenth of a second): throw as time_up/1 does once the
%   watched goal has run its limit since its last progress mark; nothing outside the goal
%   (the moments before progress_watch/2 sets the watch and after it ends).
tick(_Signal) :-
    (   nb_current(relrl_active, true),
        nb_current(relrl_watch, watch(Limit, Seen, Since)),
        flag(relrl_progress, N, N),
        get_time(Now),
        (   N =\= Seen
        ->  nb_setval(relrl_watch, watch(Limit, N, Now)),
            fail
        ;   Now - Since >= Limit
        )
    ->  throw(time_limit_exceeded)
    ;   true
    ).

%!  progress_watch(+Limit:number, :Goal) is semidet.
%
%   Run Goal once, stopped with `time_limit_exceeded` once Limit seconds pass with no
%   progress_mark/0 (the host raises the prof signal every tenth of a second while the
%   call runs: relrl/bridge/deadline.py, SIG_TICK).

progress_watch(Limit, Goal) :-
    must_be(number, Limit),
    (   Limit > 0
    ->  true
    ;   domain_error(positive_number, Limit)
    ),
    flag(relrl_progress, N, N),
    get_time(Now),
    setup_call_cleanup(nb_setval(relrl_watch, watch(Limit, N, Now)),
                       once(Goal),
                       nb_setval(relrl_watch, none)).

%!  progress_mark is det.
%
%   A unit of work (a world's step) has ended: progress_watch/2 counts its limit from now.

progress_mark :-
    flag(relrl_progress, N, N + 1).

interrupt(_Signal) :-
    (   nb_current(relrl_active, true)
    ->  throw(relrl_interrupted)
    ;   true
    ).

%!  error_result(+Exception, -Result) is det.
%
%   Result is error(Kind, Message) for Exception: Kind keeps the error's structure for
%   Python (time_limit_exceeded, time_limit_exceeded(rule(Goal, Where)),
%   rule_error(Goal, Where, Formal) (Formal `halt_called` for a rule that called halt/0,1),
%   halt_called(goal), policy_error(File, Line, Text), interrupted, aborted, or the error
%   term itself) and Message is one line for a person.

error_result(relrl_interrupted, error(interrupted, "interrupted")) :- !.
error_result(relrl_rule_error(_, _, relrl_interrupted), Result) :- !,
    error_result(relrl_interrupted, Result).
error_result(relrl_rule_error(Goal, Where0, E), error(Kind, Message)) :- !,
    where_text(Where0, Where),
    format(string(GoalText), "~q", [Goal]),
    (   E == time_limit_exceeded
    ->  Kind = time_limit_exceeded(rule(GoalText, Where)),
        format(string(Message), "~w: rule ~w ran longer than the time limit (a rule that \c
                                 never ends?)", [Where, GoalText])
    ;   E == relrl_halt_called
    ->  Kind = rule_error(GoalText, Where, halt_called),
        format(string(Message), "~w: rule ~w called halt/0,1 (a rule cannot end relrl)",
               [Where, GoalText])
    ;   E = error(resource_error(Resource), _)
    ->  Kind = rule_error(GoalText, Where, resource_error(Resource)),
        format(string(Message), "~w: rule ~w ran out of ~w (a recursion without end?)",
               [Where, GoalText, Resource])
    ;   E = error(domain_error(world_vocabulary, Text), _)    % world.pl's contract/4
    ->  Kind = rule_error(GoalText, Where, domain_error(world_vocabulary, Text)),
        format(string(Message), "~w: ~w", [Where, Text])
    ;   strip_context(E, E1),
        message_string(E1, Inner),
        (   E1 = error(Formal, _)
        ->  true
        ;   Formal = E1
        ),
        Kind = rule_error(GoalText, Where, Formal),
        format(string(Message), "~w: rule ~w: ~w", [Where, GoalText, Inner])
    ).
error_result(error(relrl_policy_error(File, Line, Text), _),
             error(policy_error(File, Line, Text1), Message)) :- !,
    one_line(Text, Text1),
    (   Line > 0
    ->  format(string(Message), "~w:~w: ~w", [File, Line, Text1])
    ;   format(string(Message), "~w: ~w", [File, Text1])
    ).
error_result(relrl_halt_called, error(halt_called(goal), Message)) :- !,
    halt_message(goal, Message).
error_result('$aborted', error(aborted, "abort/0 called")) :- !,
    (   nb_current(relrl_abort, W), W \== none
    ->  true
    ;   nb_setval(relrl_abort, goal)
    ).
error_result(E0, error(E, Message)) :-
    strip_context(E0, E),
    message_string(E, Message).

where_text(File:Line, Where) :- !,
    format(string(Where), "~w:~w", [File, Line]).
where_text(_, "(no source)").

one_line(Text, Line) :-
    split_string(Text, "\n", " \t", Parts0),
    exclude(==(""), Parts0, Parts),
    atomic_list_concat(Parts, ' ', A),
    atom_string(A, Line).

%!  gw_take_abort(-Where) is det.
%
%   Where a goal called abort/0 in the last gateway call (File:Line when a file was being
%   loaded, goal otherwise, none when no abort happened); forgets it.

gw_take_abort(Where) :-
    (   nb_current(relrl_abort, Where0)
    ->  Where = Where0
    ;   Where = none
    ),
    nb_setval(relrl_abort, none).

%   The alarm's context is noise for a user; keep the error itself.
strip_context(error(Formal, context(time:_, _)), error(Formal, _)) :- !.
strip_context(E, E).

%!  text_failed(+Error) is semidet.
%
%   Rendering a message or an answer as text failed with Error: fail, so that the plain
%   rendering is used instead, unless Error must reach the caller — a time limit, Ctrl-C,
%   abort or a resource error is never swallowed.

text_failed(Error) :-
    (   must_pass(Error)
    ->  throw(Error)
    ;   fail
    ).

must_pass(time_limit_exceeded).
must_pass(relrl_interrupted).
must_pass(relrl_halt_called).
must_pass('$aborted').
must_pass(unwind(_)).
must_pass(error(resource_error(_), _)).

message_string(E, Message) :-
    (   catch(message_to_codes(E, Codes), Error, text_failed(Error))
    ->  string_codes(Message0, Codes)
    ;   format(string(Message0), "~q", [E])
    ),
    one_line(Message0, Message).

message_to_codes(E, Codes) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(codes(Codes), print_message_lines(current_output, '', Lines)).
