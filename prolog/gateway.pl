:- module(relrl_gateway,
          [ gw_run/3,             % :Goal, +TimeLimit, -Result
            gw_step/15,           % +KB, +Percepts, +Emitted, +Mode, +Want, +TimeLimit,
                                  % -Result, -Code, -Necessity, -Outputs, -Reward,
                                  % -Reinforced, -Mask, -Action, -Extras
            gw_load/3,            % +File, +Module, -Problems
            gw_load/4,            % +File, +Module, +TimeLimit, -Problems
            gw_take_abort/1,      % -Where
            python_api/1,         % ?PredicateIndicator
            gw_query/5,           % +Module, +Text, +TimeLimit, +MaxSolutions, -Result
            gw_new_kb/1,          % -Module
            gw_drop_kb/1,         % +Module
            gw_findall/3,         % +Module, +Template, -List
            gw_parse/3            % +Module, +Text, -Terms
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(time)).
:- use_module(relrl).
:- use_module(declarations).
:- use_module(policy).
:- use_module(engine, [engine_park/0]).
:- use_module(state, [state_touch/0]).

/** <module> The Prolog side of relrl's Python gateway

The Python gateway (relrl/kb.py) calls only the predicates of this module. Each runs one
deterministic goal, catches every exception and turns it into a result term, so that a
Prolog error never escapes as an uncaught exception into the host and every query is
bounded in time:

  - gw_run/3 runs a goal once under a time limit;
  - gw_step/15 is gw_run/3 of the control step (relrl_engine:engine_step/6), its result
    spread over output arguments that Python reads without decoding a term;
  - gw_load/4 consults a domain file into a knowledge-base module under a time limit and
    collects every error and warning with its file and line instead of printing them;
  - gw_query/5 parses a query typed by a user and collects its solutions as bindings.

gw_run/3 runs only goals of a knowledge-base module (the user's own domain) or of the
public API listed by python_api/1: the exact contract between relrl's Python and its
Prolog. Nothing else of relrl's Prolog is reachable from Python, tests included.

Nothing a loaded file or a rule does can end the program: halt/0,1 called during any
gateway call is cancelled and reported as an error naming the file and line when it came
from a directive; abort/0 is reported (gw_take_abort/1) instead of unwinding silently.

A knowledge base is a module of its own (gw_new_kb/1), so two knowledge bases in one
process never see each other's clauses or working memory. Every call but a step first puts
the random stream of the knowledge base that stepped last away (engine_park/0): a user's
query or a loaded file that draws random numbers draws from none of the agents' streams.
A call that may change the domain's rules (a goal of a knowledge base, a user's query,
loading a file) also makes the next step check which facts it may read straight off
working memory (relrl_state:state_touch/0).
*/

:- meta_predicate gw_run(0, +, -), guarded(0, +, -), guarded_call(0, +, +, +, -),
    api_call(0), once_result(0, -), limited(0, +, -).

%!  gw_run(:Goal, +TimeLimit, -Result) is det.
%
%   Run Goal once. Result is `true` (Goal's bindings are kept), `false`, or
%   error(Error, Message) where Message is Prolog's rendering of Error as a string and
%   Error is `time_limit_exceeded` when Goal ran longer than TimeLimit seconds.
%   A TimeLimit of 0 means no limit.

gw_run(Goal, Limit, Result) :-
    guarded(api_call(Goal), Limit, Result).

%!  gw_step(+KB, +Percepts, +Emitted, +Mode, +Want, +TimeLimit, -Result,
%!          -Code, -Necessity, -Outputs, -Reward, -Reinforced, -Mask, -Action,
%!          -Extras) is det.
%
%   One control step: gw_run(relrl_engine:engine_step(KB, Percepts, Emitted, Mode, Want,
%   Out), TimeLimit, Result) — the same time limit, errors, halt and abort handling — with
%   the fields of Out (step(Code, Necessity, Outputs, Reward, Reinforced, Mask, Action,
%   Extras), see engine_step/6) as arguments of their own. Python reads each output with
%   one foreign call instead of converting the whole result term: the step is the call
%   the robot makes thousands of times a second. The outputs stay unbound unless Result
%   is `true`.

gw_step(KB, Percepts, Emitted, Mode, Want, Limit, Result,
        Code, Necessity, Outputs, Reward, Reinforced, Mask, Action, Extras) :-
    guarded(relrl_engine:engine_step(KB, Percepts, Emitted, Mode, Want, Out), Limit, Result),
    (   Result == true
    ->  Out = step(Code, Necessity, Outputs, Reward, Reinforced, Mask, Action, Extras)
    ;   true
    ).

%   A goal of a knowledge-base module or of python_api/1; anything else is refused. The
%   last stepping agent's random stream is put away first (see relrl_engine:engine_park/0);
%   a goal of a knowledge base (the user's own: it may redefine or trace a rule) touches
%   the state plans (relrl_state:state_touch/0).
api_call(Goal) :-
    engine_park,
    strip_module(Goal, M, G),
    (   callable(G),
        functor(G, Name, Arity),
        (   kb_module_(M)
        ->  state_touch
        ;   python_api(M:Name/Arity)
        )
    ->  call(Goal)
    ;   functor(G, Name, Arity),
        permission_error(call, private_predicate, M:Name/Arity)
    ).

%   Run Goal once as a gateway call, under the time limit Limit (0: none): Result is true,
%   false or error(E, Message). While it runs, halt/0,1 is cancelled (see halt_hook/0;
%   Result then says so) and Ctrl-C may stop it (interrupt/1).
%
%   The flags and the deadline (see limited/3) are set and restored inside one catch/3
%   (guarded_call/5), and its handler restores them too (guarded_error/4): an exception
%   at any point of the call — the goal's, the alarm's, Ctrl-C's, even while they are
%   being restored — leaves them as they were before it, and abort/0, which unwinds past
%   every catch/3, runs the handler first. Outside the catch/3 nothing is left that an
%   alarm or Ctrl-C could interrupt (the flag and the deadline are the caller's again).
%   A third cheaper than setup_call_cleanup/3 around the call (0.5 us a step).
guarded(Goal, Limit, Result) :-
    (   nb_current(relrl_active, Was)
    ->  true
    ;   Was = false
    ),
    call_deadline(Limit, Outer, Deadline),
    catch(guarded_call(Goal, Deadline, Was, Outer, Result0), E,
          guarded_error(E, Was, Outer, Result0)),
    halt_result(Result0, Result).

guarded_call(Goal, Deadline, Was, Outer, Result) :-
    enter_call(Deadline),
    once_result(Goal, Result),
    leave_call(Was, Outer).

guarded_error(E, Was, Outer, Result) :-
    nb_setval(relrl_deadline, Outer),           % the error's report is not timed
    call_cleanup(error_result(E, Result), nb_setval(relrl_active, Was)).

enter_call(Deadline) :-
    nb_setval(relrl_active, true),
    nb_setval(relrl_halt, none),
    enter_deadline(Deadline).

leave_call(Was, Outer) :-
    nb_setval(relrl_active, Was),
    nb_setval(relrl_deadline, Outer).

%   Run Goal (which catches its own errors) with halt/0,1 cancelled: Result is Result0,
%   or error(halt_called(Where), Message) when Goal called halt (gw_load/4).
active(Goal, Result0, Result) :-
    (   nb_current(relrl_active, Was)
    ->  true
    ;   Was = false
    ),
    setup_call_cleanup(
        ( nb_setval(relrl_active, true), nb_setval(relrl_halt, none) ),
        Goal,
        nb_setval(relrl_active, Was)),
    halt_result(Result0, Result).

%   Result0, or the error for a halt/0,1 that was cancelled while the call ran.
halt_result(Result0, Result) :-
    nb_getval(relrl_halt, Halt),
    (   Halt == none
    ->  Result = Result0
    ;   nb_setval(relrl_halt, none),
        halt_message(Halt, Message),
        Result = error(halt_called(Halt), Message)
    ).

once_result(Goal, Result) :-
    (   call(Goal)
    ->  Result = true
    ;   Result = false
    ).

halt_message(Where, Message) :-
    (   Where = File:Line
    ->  format(string(Message), "~w:~w: halt/0,1 called while loading (a loaded file \c
                                 cannot end relrl)", [File, Line])
    ;   format(string(Message), "halt/0,1 called by a goal (a rule cannot end relrl)", [])
    ).

:- initialization(at_halt(relrl_gateway:halt_hook)).

%   Ctrl-C at the shell: kb.py's watcher thread raises SIGUSR1 in Prolog's thread
%   (PL_thread_raise/2) while a user's query runs; the query stops with relrl_interrupted,
%   reported as error(interrupted, _), at once instead of when its time limit strikes.
:- initialization(on_signal(usr1, _, relrl_gateway:interrupt)).

interrupt(_Signal) :-
    (   nb_current(relrl_active, true)
    ->  throw(relrl_interrupted)
    ;   true                            % between gateway calls: nothing to stop
    ).

%   at_halt/1 hook: inside a gateway call, cancel the halt and remember where it came from.
%   Otherwise the process ends: the watchdog, which stays armed between calls (limited/3),
%   is disarmed first, so that no alarm is pending while the alarm library shuts down.
halt_hook :-
    (   nb_current(relrl_active, true)
    ->  load_location(Where),
        nb_setval(relrl_halt, Where),
        cancel_halt(relrl_gateway)
    ;   nb_current(relrl_watchdog, Alarm)
    ->  nb_setval(relrl_armed, none),
        uninstall_alarm(Alarm)
    ;   true
    ).

load_location(Where) :-
    (   prolog_load_context(file, File),
        prolog_load_context(term_position, Pos),
        stream_position_data(line_count, Pos, Line)
    ->  Where = File:Line
    ;   Where = goal
    ).

%!  python_api(?PI) is nondet.
%
%   The predicates of relrl's Prolog that Python may call through gw_run/3, as
%   Module:Name/Arity. Everything else is private.

python_api(relrl_engine:engine_configure/4).
python_api(relrl_engine:engine_step/6).
python_api(relrl_engine:engine_end_episode/1).
python_api(relrl_engine:engine_explain/3).
python_api(relrl_engine:engine_text/2).
python_api(relrl_engine:engine_graph/2).
python_api(relrl_engine:engine_knowledge/2).
python_api(relrl_engine:engine_size/2).
python_api(relrl_engine:engine_policy/3).
python_api(relrl_engine:engine_keep/2).
python_api(relrl_engine:engine_resume/2).
python_api(relrl_engine:engine_reseed/2).
python_api(relrl_engine:engine_responses/2).
python_api(relrl_engine:engine_necessities/2).
python_api(relrl_engine:engine_learner/2).
python_api(relrl_engine:engine_relational_state/2).
python_api(relrl_policy:policy_learner/2).
python_api(relrl_policy:policy_load/2).
python_api(relrl_policy:policy_max_number/1).
python_api(relrl_memory:wm_insert/2).
python_api(relrl_memory:wm_elements/2).
python_api(relrl_memory:wm_clear/1).
python_api(relrl_memory:wm_clock/2).
python_api(relrl_memory:wm_set_span/2).
python_api(relrl_state:state_code/2).
python_api(relrl_state:state_terms/2).
python_api(relrl_state:state_decode/3).
python_api(relrl_state:state_encode/3).
python_api(relrl_state:state_features/2).
python_api(relrl_responses:allowed_responses/2).
python_api(relrl_declarations:necessity_inputs/3).
python_api(relrl_check:check_domain/2).
python_api(relrl_check:rule_listing/2).
python_api(relrl_check:bias_listing/2).
python_api(relrl_percepts:world_problems/3).
python_api(relrl_percepts:unread_percepts/3).
python_api(relrl_gateway:gw_new_kb/1).
python_api(relrl_gateway:gw_drop_kb/1).
python_api(relrl_gateway:gw_load/4).
python_api(relrl_gateway:gw_query/5).
python_api(relrl_gateway:gw_findall/3).
python_api(relrl_gateway:gw_parse/3).
python_api(relrl_gateway:gw_take_abort/1).

%   Run Goal once under a time limit of Limit seconds (0: none of its own; a limit of an
%   enclosing call still holds).
%
%   The limit is a deadline in a global variable, and one alarm (the watchdog) is armed
%   only when no earlier alarm is pending: when it fires, time_up/0 throws if the running
%   call's deadline has passed, and otherwise sets itself for that deadline. A robot
%   stepping thousands of times a second under a 10 s limit so arms the alarm about once
%   in 10 s instead of twice per call: arming and disarming an alarm wakes the alarm
%   library's scheduler thread, which cost a control step 10-60 µs here, more than the
%   rest of the gateway (call_with_time_limit/2, which also creates an alarm per call,
%   costs more still). The limit holds to within the alarm's precision, as before.

limited(Goal, Limit, Result) :-
    call_deadline(Limit, Outer, Deadline),
    setup_call_cleanup(
        enter_deadline(Deadline),
        once_result(Goal, Result),
        nb_setval(relrl_deadline, Outer)).

%   call_deadline(+Limit, -Outer, -Deadline): Outer is the deadline of the enclosing call
%   (or none); Deadline the one a call limited to Limit seconds (0: none of its own) runs
%   under — the earlier of the two.
call_deadline(Limit, Outer, Deadline) :-
    nb_getval(relrl_deadline, Outer),
    (   Limit > 0
    ->  get_time(Now),
        Deadline0 is Now + Limit,
        (   Outer \== none,
            Outer < Deadline0
        ->  Deadline = Outer
        ;   Deadline = Deadline0
        )
    ;   Deadline = Outer
    ).

enter_deadline(Deadline) :-
    (   Deadline == none
    ->  true
    ;   set_deadline(Deadline)
    ).

:- initialization(( nb_setval(relrl_deadline, none), nb_setval(relrl_armed, none) )).

%   The running call must end by Deadline: arm the watchdog unless it fires sooner.
set_deadline(Deadline) :-
    nb_setval(relrl_deadline, Deadline),
    nb_getval(relrl_armed, At),
    (   At \== none,
        At =< Deadline
    ->  true
    ;   arm(Deadline)
    ).

%   Set the watchdog to fire at Deadline (signals held off: time_up/0 arms it too).
arm(Deadline) :-
    sig_atomic(arm_(Deadline)).

arm_(Deadline) :-
    watchdog(Alarm),
    uninstall_alarm(Alarm),
    get_time(Now),
    In is max(Deadline - Now, 0.0001),
    install_alarm(Alarm, In),
    nb_setval(relrl_armed, Deadline).

%   The one alarm, made once.
watchdog(Alarm) :-
    (   nb_current(relrl_watchdog, Alarm0)
    ->  Alarm = Alarm0
    ;   alarm(3600, relrl_gateway:time_up, Alarm,
              [remove(false), install(false)]),
        nb_setval(relrl_watchdog, Alarm)
    ).

%   The alarm fired. If the running call's deadline has passed: remember where a file
%   being loaded was (a directive that never ends), then throw as call_with_time_limit/2
%   does. If a call runs with a later deadline, wait for that; if none runs, stay unarmed.
time_up :-
    nb_setval(relrl_armed, none),
    nb_getval(relrl_deadline, Deadline),
    (   Deadline == none
    ->  true
    ;   get_time(Now),
        Now >= Deadline - 0.0005
    ->  load_location(Where),
        nb_setval(relrl_timeout_where, Where),
        throw(time_limit_exceeded)
    ;   arm(Deadline)
    ).

%!  error_result(+Exception, -Result) is det.
%
%   Result is error(Kind, Message) for Exception: Kind keeps the error's structure for
%   Python (time_limit_exceeded, time_limit_exceeded(rule(Goal, Where)),
%   rule_error(Goal, Where, Formal), policy_error(File, Line, Text), or the error term
%   itself) and Message is one line for a person.

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
    ;   E = error(resource_error(Resource), _)
    ->  Kind = rule_error(GoalText, Where, resource_error(Resource)),
        format(string(Message), "~w: rule ~w ran out of ~w (a recursion without end?)",
               [Where, GoalText, Resource])
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

%   Rendering a message or an answer as text failed with Error: the plain rendering is used
%   instead (fail), unless Error must reach the caller — a time limit, Ctrl-C, abort or a
%   resource error is never swallowed.
text_failed(Error) :-
    (   must_pass(Error)
    ->  throw(Error)
    ;   fail
    ).

must_pass(time_limit_exceeded).
must_pass(relrl_interrupted).
must_pass('$aborted').
must_pass(unwind(_)).
must_pass(error(resource_error(_), _)).

message_string(E, Message) :-
    (   catch(message_to_codes(E, Codes), Error, text_failed(Error))
    ->  string_codes(Message0, Codes)
    ;   format(string(Message0), "~q", [E])
    ),
    split_string(Message0, "\n", " \t", Parts0),
    exclude(==(""), Parts0, Parts),
    atomic_list_concat(Parts, ' ', Atom),
    atom_string(Atom, Message).

message_to_codes(E, Codes) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(codes(Codes), print_message_lines(current_output, '', Lines)).

%!  gw_new_kb(-Module) is det.
%
%   Module is a fresh, empty knowledge-base module that sees relrl's predicates.

:- dynamic kb_counter/1, kb_module_/1.
kb_counter(0).

gw_new_kb(Module) :-
    retract(kb_counter(N0)),
    N is N0 + 1,
    assertz(kb_counter(N)),
    format(atom(Module), "relrl_kb_~d", [N]),
    assertz(kb_module_(Module)),
    set_module(Module:class(user)),
    add_import_module(Module, relrl, start),
    set_prolog_flag(Module:unknown, error).

%!  gw_drop_kb(+Module) is det.
%
%   Forget the clauses and working memory of a knowledge-base module.

gw_drop_kb(Module) :-
    must_be(atom, Module),
    relrl_memory:wm_clear(Module),
    relrl_engine:engine_forget(Module),
    retractall(kb_module_(Module)),
    forall(( current_predicate(Module:Name/Arity),
             functor(Head, Name, Arity),
             \+ predicate_property(Module:Head, imported_from(_)) ),
           abolish(Module:Name/Arity)).

%!  gw_load(+File, +Module, -Problems:list) is det.
%!  gw_load(+File, +Module, +TimeLimit, -Problems:list) is det.
%
%   Consult File into Module, its directives running under TimeLimit seconds (0: none).
%   Problems lists every error and warning printed while loading, as
%   problem(Kind, File, Line, Message), in order. Nothing is printed. A file that does not
%   exist gives one problem with line 0; a directive that runs past the time limit or calls
%   halt/0,1 gives an error at its line.

:- dynamic collecting/1, collected/2.

gw_load(File, Module, Problems) :-
    gw_load(File, Module, 0, Problems).

gw_load(File, Module, Limit, Problems) :-
    must_be(atom, Module),
    must_be(number, Limit),
    engine_park,                        % a directive may draw random numbers
    state_touch,                        % or redefine a rule
    (   exists_file(File)
    ->  absolute_file_name(File, Abs),
        atomic_list_concat([Abs, '#', Module], Id),
        gensym(load_, Key),
        nb_setval(relrl_timeout_where, none),
        active(setup_call_cleanup(
                   asserta(collecting(Key)),
                   catch(limited(load_stream(Abs, Id, Module), Limit, _), E,
                         note_exception(Key, Abs, Limit, E)),
                   retract(collecting(Key))),
               true, Result),
        (   Result = error(halt_called(F:L), _)
        ->  assertz(collected(Key, problem(error, F, L, "halt/0,1 called while loading \c
                                       (a loaded file cannot end relrl)")))
        ;   true
        ),
        findall(P, retract(collected(Key, P)), Problems0),
        exclude(cancelled_halt_warning(Result), Problems0, Problems)
    ;   exists_directory(File)
    ->  Problems = [problem(error, File, 0, "a directory, not a Prolog file")]
    ;   Problems = [problem(error, File, 0, "no such file")]
    ).

%   The directive whose halt was cancelled also "failed": one problem for it is enough.
cancelled_halt_warning(error(halt_called(F:L), _), problem(warning, F, L, _)).

load_stream(Abs, Id, Module) :-
    setup_call_cleanup(
        open(Abs, read, Stream),
        load_files(Module:Id, [stream(Stream), if(true)]),
        close(Stream)).

note_exception(Key, File, Limit, E) :-
    (   E == time_limit_exceeded
    ->  nb_getval(relrl_timeout_where, Where),
        (   Where = F:L
        ->  true
        ;   F = File, L = 0
        ),
        format(string(Msg), "loading ran longer than the time limit (~w s): a directive \c
                             that never ends?", [Limit])
    ;   E == '$aborted'
    ->  nb_setval(relrl_abort, File:0),
        F = File, L = 0, Msg = "abort/0 called while loading"
    ;   E = relrl_rule_error(_, _, _)
    ->  error_result(E, error(_, Msg)),
        F = File, L = 0
    ;   message_string(E, Msg),
        (   E = error(_, Context), nonvar(Context), Context = file(F, L, _, _)
        ->  true
        ;   F = File, L = 0
        )
    ),
    assertz(collected(Key, problem(error, F, L, Msg))).

:- multifile user:message_hook/3.
:- dynamic user:message_hook/3.

user:message_hook(Term, Kind, Lines) :-
    collecting(Key),
    memberchk(Kind, [error, warning]),
    message_location(Term, File, Line),
    lines_string(Lines, Msg0),
    strip_location(Msg0, Msg),
    assertz(collected(Key, problem(Kind, File, Line, Msg))).

message_location(error(_, Context), File, Line) :-
    nonvar(Context),
    Context = file(File, Line, _, _),
    !.
message_location(_, File, Line) :-
    source_location(File, Line), !.
message_location(_, '', 0).

lines_string(Lines, String) :-
    with_output_to(string(S0), print_message_lines(current_output, '', Lines)),
    split_string(S0, "\n", " \t", Parts0),
    exclude(==(""), Parts0, Parts),
    atomic_list_concat(Parts, ' ', A),
    atom_string(A, String).

%   Syntax errors repeat the location in their text: keep the text after it.
strip_location(Msg0, Msg) :-
    (   sub_string(Msg0, B, _, A, ": Syntax error: "),
        B > 0
    ->  sub_string(Msg0, _, A, 0, Rest),
        string_concat("Syntax error: ", Rest, Msg)
    ;   Msg = Msg0
    ).

%!  gw_query(+Module, +Text, +TimeLimit, +Max, -Result) is det.
%
%   Parse Text as a query in Module and collect up to Max solutions. Result is
%   solutions(List, More) where each element of List is a list of Name-Value-Printed
%   triples (Printed is the value written as Prolog would, with the query's variable
%   names) and More is true when there were more than Max solutions; or
%   error(Error, Message) for a syntax error, an exception or a time-out.

gw_query(Module, Text, Limit, Max, Result) :-
    state_touch,                        % a query may redefine or trace a rule
    catch(query_(Module, Text, Limit, Max, Result), E, error_result(E, Result)).

query_(Module, Text, Limit, Max, solutions(Solutions, More)) :-
    term_string(Goal, Text, [variable_names(Bindings), module(Module)]),
    Max1 is Max + 1,
    exclude(anonymous, Bindings, Named),
    (   Limit > 0
    ->  call_with_time_limit(Limit,
            findnsols(Max1, Named-Printed,
                      ( Module:Goal, print_bindings(Named, Bindings, Printed) ),
                      All)),
        !
    ;   findnsols(Max1, Named-Printed,
                  ( Module:Goal, print_bindings(Named, Bindings, Printed) ), All),
        !
    ),
    (   length(All, N), N > Max
    ->  More = true, length(Kept, Max), append(Kept, _, All)
    ;   More = false, Kept = All
    ),
    maplist(solution_triples, Kept, Solutions).

anonymous(Name=_) :-
    sub_atom(Name, 0, _, _, '_').

print_bindings(Named, All, Printed) :-
    maplist(print_binding(All), Named, Printed).

print_binding(All, _=Value, String) :-
    format(string(String), "~W",
           [Value, [quoted(true), portray(true), variable_names(All), max_depth(50),
                    cycles(true),
                    spacing(next_argument)]]).

solution_triples(Named-Printed, Triples) :-
    maplist(solution_triple, Named, Printed, Triples).

%   A value too deep (or cyclic) for Python's side of the gateway goes as its printed text.
solution_triple(Name=Value, Printed, Name-Value1-Printed) :-
    (   acyclic_term(Value),
        depth_within(Value, 300)
    ->  Value1 = Value
    ;   Value1 = Printed
    ).

%   Term nests at most Max compound levels (list elements count a level; the list's own
%   spine does not, as Python reads lists as sequences).
depth_within(Term, Max) :-
    (   var(Term)
    ->  true
    ;   atomic(Term)
    ->  true
    ;   Max > 0,
        Max1 is Max - 1,
        (   is_list(Term)
        ->  forall(member(X, Term), depth_within(X, Max1))
        ;   forall(arg(_, Term, X), depth_within(X, Max1))
        )
    ).

%!  gw_findall(+Module, +Template, -List) is det.
%
%   List holds every declaration Template (e.g. stimulus(X)) of the knowledge base Module.

gw_findall(Module, Template, List) :-
    findall(Template, declared(Module, Template), List).

%!  gw_parse(+Module, +Text, -Terms:list) is det.
%
%   Terms are the comma-separated terms of Text, read with Module's operators. Reading
%   only: nothing in Text is run. A syntax error raises.

gw_parse(Module, Text, Terms) :-
    term_string(Term, Text, [module(Module)]),
    comma_list(Term, Terms).

                /*******************************
                *  ONE ANSWER AT A TIME (shell) *
                *******************************/

%   relrl shell keeps a query open between its answers, as swipl's toplevel does: kb.py
%   opens gw_answer/5 with PL_open_query/4 and asks for the next answer with
%   PL_next_solution/1 only when the user types ; (both are transport, called by kb.py
%   directly, not through gw_run/3). Each answer runs under the time limit (the clock
%   stops between answers), output of the goal goes out as it is written, and the
%   answer is written by Prolog's own writer after the toplevel's translation of the
%   bindings (cycles factorized, depth limited), so no term crosses the bridge.

%!  gw_answer(+Module, +Text, +TimeLimit, +Mode, -Answer) is nondet.
%
%   Answer is one answer of the query Text, read in Module: answer(Printed, Det) with
%   Printed the bindings as swipl's toplevel writes them (a string, "" when there are
%   none, without the final `.` or `;`) and Det `true` when no further answer can follow,
%   `false` when there may be one; or error(Kind, Message) (see error_result/2) for a
%   syntax error, an exception or a time-out, after which there are no more answers.
%   TimeLimit (seconds, > 0) bounds the work for each answer. Mode is `print` (terms
%   written to depth 10, the toplevel's default) or `write` (whole terms).

gw_answer(Module, Text, Limit, Mode, Answer) :-
    must_be(atom, Module),
    (   number(Limit), Limit > 0, Limit =\= inf
    ->  true
    ;   domain_error(positive_time_limit, Limit)
    ),
    must_be(oneof([write, print]), Mode),
    nb_setval(relrl_answer_mode, Mode),
    nb_setval(relrl_answer_again, none),
    catch(term_string(Goal, Text, [variable_names(Bindings), module(Module)]), E, true),
    (   var(E)
    ->  answers(Module:Goal, Bindings, Limit, Answer)
    ;   error_result(E, Answer)
    ).

answers(Goal, Bindings, Limit, Answer) :-
    (   catch(answer(Goal, Bindings, Limit, Answer0), E0,
              ( pause(_), toplevel_error(E0, E), error_result(E, Answer0) ))
    *-> Answer = Answer0
    ;   pause(Halt),
        Halt \== none,
        halt_message(Halt, Message),
        Answer = error(halt_called(Halt), Message)
    ).

answer(Goal, Bindings, Limit, Answer) :-
    resume(Limit),
    call_cleanup(Goal, Det = true),
    (   var(Det)
    ->  Det = false
    ;   true
    ),
    deliver(Bindings, Det, Limit, Answer).

%   Write the answer (again, after gw_answer_again/1); on backtracking for the next
%   answer, restart the clock and fail into the goal (the cuts stay in this clause).
deliver(Bindings, Det, Limit, Answer) :-
    repeat,
    answer_text(Bindings, Text),
    pause(Halt),
    (   Halt \== none
    ->  !,
        halt_message(Halt, Message),
        Answer = error(halt_called(Halt), Message)
    ;   Answer = answer(Text, Det)
    ;   nb_getval(relrl_answer_again, Again),
        Again \== none
    ->  resume(Limit),
        fail
    ;   !,
        resume(Limit),
        fail
    ).

%   The goal runs inside call_cleanup/2: an error's context names the query itself, as
%   at the toplevel, not the wrapper.
toplevel_error(error(Formal, context(Wrapper, Message)), error(Formal, context(_, Message))) :-
    nonvar(Wrapper),
    strip_module(Wrapper, _, setup_call_catcher_cleanup/4),
    !.
toplevel_error(E, E).

%   The clock runs and halt/0,1 is cancelled (see halt_hook/0) while an answer is sought;
%   between answers the clock stops and what the goal wrote is flushed.
resume(Limit) :-
    engine_park,                        % a step may have run between two answers
    state_touch,                        % a query may redefine or trace a rule
    nb_setval(relrl_active, true),
    nb_setval(relrl_halt, none),
    get_time(Now),
    Deadline is Now + Limit,
    set_deadline(Deadline).

pause(Halt) :-
    nb_setval(relrl_deadline, none),
    flush_output(user_output),          % the goal's output comes before the answer
    nb_setval(relrl_active, false),
    nb_getval(relrl_halt, Halt),
    nb_setval(relrl_halt, none).

%!  gw_answer_again(+Mode) is det.
%
%   Called by kb.py while a gw_answer/5 query is open, before asking for its next
%   solution: write the current answer again, in Mode `write` (whole terms, as the
%   toplevel's w) or `print` (depth-limited, as p and the default); later answers too.

gw_answer_again(Mode) :-
    must_be(oneof([write, print]), Mode),
    nb_setval(relrl_answer_mode, Mode),
    nb_setval(relrl_answer_again, Mode).

answer_text(Bindings0, Text) :-
    nb_setval(relrl_answer_again, none),
    exclude(anonymous, Bindings0, Bindings1),
    prolog:translate_bindings(Bindings1, Bindings, [], [], _:Residuals),
    name_variables(Bindings-Residuals),
    answer_mode(Options),
    (   catch(toplevel_text(Bindings, Residuals, Options, Text0), Error,
              text_failed(Error))
    ->  true
    ;   format(string(Text0), "~W", [Bindings-Residuals, Options])
    ),
    split_string(Text0, "", " \n", [Text]).

answer_mode(Options) :-
    (   nb_current(relrl_answer_mode, write)
    ->  Options = [quoted(true), numbervars(true), spacing(next_argument),
                   max_depth(MaxDepth)],
        safe_write_depth(MaxDepth)
    ;   Options = [quoted(true), portray(true), numbervars(true), max_depth(10),
                   spacing(next_argument)]
    ).

%   Writing a term recurses in C: beyond some thousands of levels the host's C stack
%   overflows, so even `w` writes at most this deep.
safe_write_depth(5000).

%   The toplevel's own rendering (boot/messages.pl), with Options as answer_write_options.
toplevel_text(Bindings, Residuals, Options, Text) :-
    (   current_prolog_flag(answer_write_options, Old)
    ->  Restore = set_prolog_flag(answer_write_options, Old)
    ;   Restore = true
    ),
    setup_call_cleanup(
        create_prolog_flag(answer_write_options, Options, [type(term)]),
        '$messages':translate_message(query(more(Bindings, true, Residuals)), Lines, []),
        Restore),
    with_output_to(string(Text), print_message_lines(current_output, '', Lines)).

%   As the toplevel does: a variable that occurs once is written _, the others _A, _B, ...
name_variables(Term) :-
    term_singletons(Term, Singletons),
    maplist(=('$VAR'('_')), Singletons),
    term_variables(Term, Vars),
    foldl(name_variable, Vars, 0, _).

name_variable('$VAR'(Name), N0, N) :-
    Letter is 0'A + N0 mod 26,
    (   N0 < 26
    ->  format(atom(Name), "_~c", [Letter])
    ;   Index is N0 // 26,
        format(atom(Name), "_~c~d", [Letter, Index])
    ),
    N is N0 + 1.

%   relrl shell's trace. sets trace points (library(prolog_trace)) on the domain's
%   predicates; their ports are written as swipl writes them, without the knowledge base's
%   internal module name.
user:message_hook(frame(Module:Goal, trace(Port, _Frame-Level)), debug, _) :-
    atom(Module),
    kb_module_(Module),
    upcase_atom(Port, Upper),
    sub_atom(Upper, 0, 1, _, First),
    sub_atom(Port, 1, _, 0, Rest),
    format(user_error, " T [~w] ~w~w: ~W~n",
           [Level, First, Rest, Goal, [quoted(true), portray(true), max_depth(10),
                                      spacing(next_argument)]]).
