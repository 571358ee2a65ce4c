:- module(relrl_gateway,
          [ gw_run/3,             % :Goal, +TimeLimit, -Result
            gw_load/3,            % +File, +Module, -Problems
            gw_query/5,           % +Module, +Text, +TimeLimit, +MaxSolutions, -Result
            gw_new_kb/1,          % -Module
            gw_drop_kb/1,         % +Module
            gw_findall/3,         % +Module, +Template, -List
            gw_parse/3,           % +Module, +Text, -Terms
            gw_policy_learner/2   % +File, -Learner
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(time)).
:- use_module(relrl).
:- use_module(declarations).

/** <module> The Prolog side of relrl's Python gateway

The Python gateway (relrl/kb.py) calls only the predicates of this module. Each runs one
deterministic goal, catches every exception and turns it into a result term, so that a
Prolog error never escapes as an uncaught exception into the host and every query is
bounded in time:

  - gw_run/3 runs a goal once under a time limit;
  - gw_load/3 consults a domain file into a knowledge-base module and collects every
    error and warning with its file and line instead of printing them;
  - gw_query/5 parses a query typed by a user and collects its solutions as bindings.

A knowledge base is a module of its own (gw_new_kb/1), so two knowledge bases in one
process never see each other's clauses or working memory.
*/

:- meta_predicate gw_run(0, +, -).

%!  gw_run(:Goal, +TimeLimit, -Result) is det.
%
%   Run Goal once. Result is `true` (Goal's bindings are kept), `false`, or
%   error(Error, Message) where Message is Prolog's rendering of Error as a string and
%   Error is `time_limit_exceeded` when Goal ran longer than TimeLimit seconds.
%   A TimeLimit of 0 means no limit.

gw_run(Goal, Limit, Result) :-
    catch(limited(Goal, Limit, Result), E, error_result(E, Result)).

limited(Goal, Limit, Result) :-
    (   Limit > 0
    ->  watchdog(Alarm),
        setup_call_cleanup(
            install_alarm(Alarm, Limit),
            (   call(Goal)
            ->  Result = true
            ;   Result = false
            ),
            uninstall_alarm(Alarm))
    ;   (   call(Goal)
        ->  Result = true
        ;   Result = false
        )
    ).

%   One alarm, made once and re-armed for every call: much cheaper than creating and
%   removing an alarm per call (call_with_time_limit/2) when the robot steps thousands of
%   times a second.
watchdog(Alarm) :-
    (   nb_current(relrl_watchdog, Alarm0)
    ->  Alarm = Alarm0
    ;   alarm(3600, throw(time_limit_exceeded), Alarm,
              [remove(false), install(false)]),
        nb_setval(relrl_watchdog, Alarm)
    ).

error_result(E0, error(E, Message)) :-
    strip_context(E0, E),
    message_string(E, Message).

%   The alarm's context is noise for a user; keep the error itself.
strip_context(error(Formal, context(time:_, _)), error(Formal, _)) :- !.
strip_context(E, E).

message_string(E, Message) :-
    (   catch(message_to_codes(E, Codes), _, fail)
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

:- dynamic kb_counter/1.
kb_counter(0).

gw_new_kb(Module) :-
    retract(kb_counter(N0)),
    N is N0 + 1,
    assertz(kb_counter(N)),
    format(atom(Module), "relrl_kb_~d", [N]),
    set_module(Module:class(user)),
    add_import_module(Module, relrl, start),
    set_prolog_flag(Module:unknown, error).

%!  gw_drop_kb(+Module) is det.
%
%   Forget the clauses and working memory of a knowledge-base module.

gw_drop_kb(Module) :-
    must_be(atom, Module),
    relrl_memory:wm_clear(Module),
    forall(( current_predicate(Module:Name/Arity),
             functor(Head, Name, Arity),
             \+ predicate_property(Module:Head, imported_from(_)) ),
           abolish(Module:Name/Arity)).

%!  gw_load(+File, +Module, -Problems:list) is det.
%
%   Consult File into Module. Problems lists every error and warning printed while
%   loading, as problem(Kind, File, Line, Message), in order. Nothing is printed.
%   A file that does not exist gives one problem with line 0.

:- dynamic collecting/1, collected/2.

gw_load(File, Module, Problems) :-
    must_be(atom, Module),
    (   exists_file(File)
    ->  absolute_file_name(File, Abs),
        atomic_list_concat([Abs, '#', Module], Id),
        gensym(load_, Key),
        setup_call_cleanup(
            asserta(collecting(Key)),
            catch(load_stream(Abs, Id, Module), E, note_exception(Key, Abs, E)),
            retract(collecting(Key))),
        findall(P, retract(collected(Key, P)), Problems)
    ;   format(string(Msg), "no such file", []),
        Problems = [problem(error, File, 0, Msg)]
    ).

load_stream(Abs, Id, Module) :-
    setup_call_cleanup(
        open(Abs, read, Stream),
        load_files(Module:Id, [stream(Stream), if(true)]),
        close(Stream)).

note_exception(Key, File, E) :-
    message_string(E, Msg),
    (   E = error(_, file(F, L, _, _))
    ->  true
    ;   F = File, L = 0
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

message_location(error(_, file(File, Line, _, _)), File, Line) :- !.
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
           [Value, [quoted(true), portray(true), variable_names(All), max_depth(0),
                    spacing(next_argument)]]).

solution_triples(Named-Printed, Triples) :-
    maplist([Name=Value, P, Name-Value-P]>>true, Named, Printed, Triples).

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

%!  gw_policy_learner(+File, -Learner) is det.
%
%   Learner is the learner named by the relrl_policy/2 fact of a saved policy file (read
%   only, nothing is run). Fails if the file has none.

gw_policy_learner(File, Learner) :-
    setup_call_cleanup(
        open(File, read, S),
        policy_header(S, Learner),
        close(S)).

policy_header(S, Learner) :-
    read_term(S, T, []),
    (   T == end_of_file
    ->  fail
    ;   T = relrl_policy(Learner, _)
    ->  true
    ;   policy_header(S, Learner)
    ).
