:- module(relrl_guard,
          [ guarded/2,            % :Goal, -Result
            error_result/2,       % +Exception, -Result
            halt_message/2,       % +Where, -Message
            gw_take_abort/1,      % -Where
            text_failed/1,        % +Error
            progress_watch/2,     % +Limit, :Goal
            progress_mark/0,
            message_text/2,       % +Message, -Text
            call_context/2,       % ?Key, ?Value
            set_call_context/2    % +Key, +Value
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

What a call needs to know beyond its arguments lives in one record, the call context,
owned here and read and written only through call_context/2 and set_call_context/2: its
keys are declared once, by context_key/3.
*/

:- meta_predicate guarded(0, -), once_result(0, -), progress_watch(+, 0).

%!  call_context(?Key, ?Value) is semidet.
%
%   Value is the call context's Key (one of context_key/3's; its default until set):
%
%     - active: `true` while a guarded call runs (the signal and halt handlers act);
%     - halt: where a cancelled halt/0,1 came from (File:Line or `goal`), or `none`;
%     - abort: where abort/0 was called in the last call, or `none`;
%     - timeout_where: where a file was being loaded when the time limit passed;
%     - answer_mode, answer_again: how a user's open query writes its answers
%       (toplevel.pl);
%     - random_owner: the knowledge base whose random stream the generator holds
%       (engine.pl), or `none`;
%     - state_touch: how many times the rules may have changed (state.pl);
%     - watch: watch(Limit, Seen, Since) while progress_watch/2 runs its goal (the
%       progress count last seen and when it changed), `none` otherwise;
%     - progress: how many units of work (a world's steps) progress_mark/0 has counted.
%
%   The context is per thread and survives backtracking, as nb_setval/2 does.

call_context(Key, Value) :-
    context_key(Key, I, _),
    context_record(Record),
    arg(I, Record, Value).

%!  set_call_context(+Key, +Value) is det.
%
%   The call context's Key is Value from now on (a copy of it; not undone on
%   backtracking).

set_call_context(Key, Value) :-
    (   context_key(Key, I, _)
    ->  context_record(Record),
        nb_setarg(I, Record, Value)
    ;   must_be(atom, Key),
        domain_error(call_context_key, Key)
    ).

%   context_key(?Key, ?Position, ?Default): the record's fields, the one list of them.
context_key(active,        1, false).
context_key(halt,          2, none).
context_key(abort,         3, none).
context_key(timeout_where, 4, none).
context_key(answer_mode,   5, print).
context_key(answer_again,  6, none).
context_key(random_owner,  7, none).
context_key(state_touch,   8, 0).
context_key(watch,         9, none).
context_key(progress,     10, 0).

%   This thread's record (a global variable's term: nb_setarg/3 changes it in place),
%   made with the defaults on first use.
context_record(Record) :-
    (   nb_current(relrl_call_context, Record)
    ->  true
    ;   findall(Default, context_key(_, _, Default), Defaults),
        Fresh =.. [context|Defaults],
        nb_setval(relrl_call_context, Fresh),
        nb_getval(relrl_call_context, Record)
    ).

%!  guarded(:Goal, -Result) is det.
%
%   Run Goal once. Result is `true` (Goal's bindings are kept), `false`, or
%   error(Kind, Message) (see error_result/2), also for a halt/0,1 called while Goal ran.
%
%   The flag that says a guarded call runs is set in the setup and restored in the cleanup
%   of one setup_call_cleanup/3, which SWI-Prolog runs with signals blocked and, when Goal
%   raises, before the catch/3 handler: an exception at any point — the goal's, the time
%   limit's, Ctrl-C's — leaves it as it was, and a time limit or Ctrl-C raised again while
%   the handler runs (the watchdog raises every tenth of a second until the call returns;
%   a second Ctrl-C raises at once) finds the flag down and does nothing, so no exception
%   gets past the guard. abort/0 runs the handler before it unwinds on.

guarded(Goal, Result) :-
    call_context(active, Was),
    catch(guarded_call(Goal, Was, Result0), E, error_result(E, Result0)),
    halt_result(Result0, Result).

guarded_call(Goal, Was, Result) :-
    setup_call_cleanup(set_call_context(active, true),
                       once_result(Goal, Result),
                       set_call_context(active, Was)).

once_result(Goal, Result) :-
    (   call(Goal)
    ->  Result = true
    ;   Result = false
    ).

%   Result0, or the error for a halt/0,1 called while the call ran (Result0 itself when it
%   is already that error, naming the rule).
halt_result(Result0, Result) :-
    (   call_context(halt, Where),
        Where \== none
    ->  set_call_context(halt, none),
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
    (   call_context(active, true)
    ->  load_location(Where),
        set_call_context(halt, Where),
        Where == goal,
        throw(relrl_halt_called)
    ;   call(Halt)
    ).

:- initialization(at_halt(relrl_guard:halt_hook)).

%   at_halt/1 hook: inside a guarded call, cancel the halt and remember where it came from.
halt_hook :-
    (   call_context(active, true)
    ->  load_location(Where),
        set_call_context(halt, Where),
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
    (   call_context(active, true)
    ->  load_location(Where),
        set_call_context(timeout_where, Where),
        throw(time_limit_exceeded)
    ;   true
    ).

%   A watched call's tick (every tenth of a second): throw as time_up/1 does once the
%   watched goal has run its limit since its last progress mark; nothing outside the goal
%   (the moments before progress_watch/2 sets the watch and after it ends).
tick(_Signal) :-
    (   call_context(active, true),
        call_context(watch, watch(Limit, Seen, Since)),
        call_context(progress, N),
        get_time(Now),
        (   N =\= Seen
        ->  set_call_context(watch, watch(Limit, N, Now)),
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
%   call runs: relrl/bridge/deadline.py, SIG_TICK). The watch is the call context's
%   `watch`, set while Goal runs and `none` again when it ends, whatever way it ends.

progress_watch(Limit, Goal) :-
    must_be(number, Limit),
    (   Limit > 0
    ->  true
    ;   domain_error(positive_number, Limit)
    ),
    call_context(progress, N),
    get_time(Now),
    setup_call_cleanup(set_call_context(watch, watch(Limit, N, Now)),
                       once(Goal),
                       set_call_context(watch, none)).

%!  progress_mark is det.
%
%   A unit of work (a world's step) has ended: progress_watch/2 counts its limit from now
%   (the call context's `progress` count goes up by one).

progress_mark :-
    call_context(progress, N0),
    N is N0 + 1,
    set_call_context(progress, N).

interrupt(_Signal) :-
    (   call_context(active, true)
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
    ;   E = error(domain_error(world_vocabulary, Text), _)    % world_step.pl
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
    (   call_context(abort, W), W \== none
    ->  true
    ;   set_call_context(abort, goal)
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
    call_context(abort, Where),
    set_call_context(abort, none).

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
    (   catch(message_text(E, Message0), Error, text_failed(Error))
    ->  true
    ;   format(string(Message0), "~q", [E])
    ),
    one_line(Message0, Message).

%!  message_text(+Message, -Text:string) is det.
%
%   Text is Message (an error term, query(more(...)), any message term) as print_message/2
%   writes it, without a prefix: its lines from SWI-Prolog's public translation,
%   prolog:translate_message//1, written by print_message_lines/3.

message_text(Message, Text) :-
    phrase(prolog:translate_message(Message), Lines),
    with_output_to(string(Text), print_message_lines(current_output, '', Lines)).
