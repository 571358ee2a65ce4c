:- module(relrl_toplevel,
          [ gw_answer/4,          % +Module, +Text, +Mode, -Answer
            gw_answer_again/1     % +Mode
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(guard).
:- use_module(kb_load, [kb_module/1]).
:- use_module(engine, [engine_pause/0]).

/** <module> A user's query, one answer at a time: the toplevel of relrl shell and of Python

relrl keeps a user's query open between its answers, as swipl's toplevel does: Python opens
gw_answer/4 with PL_open_query/4 and asks for the next answer with PL_next_solution/1 only
when the user types ; (relrl/query.py). Its time limit is armed by Python while an answer
is sought, never between answers. Output of the goal goes out as it is written; an answer
is written by Prolog's own writer after the toplevel's translation of the bindings (cycles
factorized, depth limited), so that for the shell no term crosses the bridge.
KnowledgeBase.query/2 takes its answers from here too, as values.
*/

%!  gw_answer(+Module, +Text, +Mode, -Answer) is nondet.
%
%   Answer is one answer of the query Text, read in Module, or error(Kind, Message) (see
%   error_result/2) for a syntax error, an exception or a halt, after which there are no
%   more answers. Det is `true` when no further answer can follow, `false` when there may
%   be one. With Mode `print` (terms written to depth 10, the toplevel's default) or
%   `write` (whole terms) Answer is answer(Text, Det, []), Text the bindings as swipl's
%   toplevel writes them (a string, "" when there are none); with Mode `values` it is
%   answer("", Det, Bindings), Bindings a list of Name-Value-Printed, Printed the value
%   written as Prolog would (to depth 50), which is also the value when that is too deep
%   or cyclic for Python.

gw_answer(Module, Text, Mode, Answer) :-
    must_be(atom, Module),
    must_be(oneof([write, print, values]), Mode),
    set_call_context(answer_mode, Mode),
    set_call_context(answer_again, none),
    catch(term_string(Goal, Text, [variable_names(Bindings), module(Module)]), E, true),
    (   var(E)
    ->  catch(answer(Module:Goal, Bindings, Answer), E0,
              ( pause(_), toplevel_error(E0, E1), error_result(E1, Answer) ))
    ;   error_result(E, Answer)
    ).

%   The answers of Goal, each delivered (again, after gw_answer_again/1) with the clock
%   stopped; when they are exhausted, a halt/0,1 the goal called is reported.
answer(Goal, Bindings, Answer) :-
    resume,
    (   call_cleanup(Goal, Det = true),
        (   var(Det)
        ->  Det = false
        ;   true
        ),
        deliver(Bindings, Det, Answer)
    ;   pause(Halt),
        Halt \== none,
        halt_message(Halt, Message),
        Answer = error(halt_called(Halt), Message)
    ).

%   Write the answer (again, after gw_answer_again/1); on backtracking for the next
%   answer, go on and fail into the goal (the cuts stay in this clause).
deliver(Bindings, Det, Answer) :-
    repeat,
    call_context(answer_mode, Mode),
    answer_term(Mode, Bindings, Det, Answer0),
    pause(Halt),
    (   Halt \== none
    ->  !,
        halt_message(Halt, Message),
        Answer = error(halt_called(Halt), Message)
    ;   Answer = Answer0
    ;   call_context(answer_again, Again),
        Again \== none
    ->  resume,
        fail
    ;   !,
        resume,
        fail
    ).

answer_term(values, Bindings0, Det, answer("", Det, Values)) :- !,
    exclude(anonymous, Bindings0, Bindings),
    maplist(binding_value(Bindings0), Bindings, Values).
answer_term(_, Bindings, Det, answer(Text, Det, [])) :-
    answer_text(Bindings, Text).

%   The goal runs inside call_cleanup/2: an error's context names the query itself, as
%   at the toplevel, not the wrapper.
toplevel_error(error(Formal, context(Wrapper, Message)), error(Formal, context(_, Message))) :-
    nonvar(Wrapper),
    strip_module(Wrapper, _, setup_call_catcher_cleanup/4),
    !.
toplevel_error(E, E).

%   While an answer is sought, a guarded call runs (halt/0,1 is cancelled, Ctrl-C and the
%   time limit stop it); between answers, none does and what the goal wrote is flushed.
resume :-
    engine_pause,                       % a step may have run between two answers
    set_call_context(active, true).

pause(Halt) :-
    flush_output(user_output),          % the goal's output comes before the answer
    set_call_context(active, false),
    call_context(halt, Halt),
    set_call_context(halt, none).

%!  gw_answer_again(+Mode) is det.
%
%   Called while a gw_answer/4 query is open, before asking for its next solution: write
%   the current answer again, in Mode `write` (whole terms, as the toplevel's w) or
%   `print` (depth-limited, as p and the default); later answers too.

gw_answer_again(Mode) :-
    must_be(oneof([write, print]), Mode),
    set_call_context(answer_mode, Mode),
    set_call_context(answer_again, Mode).

anonymous(Name=_) :-
    sub_atom(Name, 0, _, _, '_').

%   A value too deep (or cyclic) for Python's reader goes as its printed text.
binding_value(All, Name=Value, Name-Value1-Printed) :-
    format(string(Printed), "~W",
           [Value, [quoted(true), portray(true), variable_names(All), max_depth(50),
                    cycles(true), spacing(next_argument)]]),
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

answer_text(Bindings0, Text) :-
    set_call_context(answer_again, none),
    exclude(anonymous, Bindings0, Bindings1),
    prolog:translate_bindings(Bindings1, Bindings, [], [], _:Residuals),
    name_variables(Bindings-Residuals),
    answer_options(Options),
    (   catch(toplevel_text(Bindings, Residuals, Options, Text0), Error,
              text_failed(Error))
    ->  true
    ;   format(string(Text0), "~W", [Bindings-Residuals, Options])
    ),
    split_string(Text0, "", " \n", [Text]).

answer_options(Options) :-
    (   call_context(answer_mode, write)
    ->  Options = [quoted(true), numbervars(true), spacing(next_argument),
                   max_depth(MaxDepth)],
        safe_write_depth(MaxDepth)
    ;   Options = [quoted(true), portray(true), numbervars(true), max_depth(10),
                   spacing(next_argument)]
    ).

%   Writing a term recurses in C: even `w` writes at most this deep.
safe_write_depth(5000).

%   The toplevel's own rendering (boot/messages.pl), with Options as answer_write_options.
toplevel_text(Bindings, Residuals, Options, Text) :-
    (   current_prolog_flag(answer_write_options, Old)
    ->  Restore = set_prolog_flag(answer_write_options, Old)
    ;   Restore = true
    ),
    setup_call_cleanup(
        create_prolog_flag(answer_write_options, Options, [type(term)]),
        message_text(query(more(Bindings, true, Residuals)), Text),
        Restore).

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
:- multifile user:message_hook/3.
:- dynamic user:message_hook/3.

user:message_hook(frame(Module:Goal, trace(Port, _Frame-Level)), debug, _) :-
    atom(Module),
    kb_module(Module),
    upcase_atom(Port, Upper),
    sub_atom(Upper, 0, 1, _, First),
    sub_atom(Port, 1, _, 0, Rest),
    format(user_error, " T [~w] ~w~w: ~W~n",
           [Level, First, Rest, Goal, [quoted(true), portray(true), max_depth(10),
                                      spacing(next_argument)]]).
