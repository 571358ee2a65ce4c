:- module(relrl_kb,
          [ gw_new_kb/1,          % -Module
            gw_drop_kb/1,         % +Module
            gw_load/3,            % +File, +Module, -Problems
            kb_module/1           % ?Module
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(modules), []).   % its destroy_module/1: see destroy_module/1 below
:- use_module(guard).
:- use_module(engine, [engine_forget/1]).

/** <module> Knowledge bases: their life cycle and loading

A knowledge base is a module of its own (gw_new_kb/1) that sees relrl's predicates, so two
knowledge bases in one process never see each other's clauses or working memory.
gw_drop_kb/1 forgets all of it. gw_load/3 consults a domain file into one and collects
every error and warning with its file and line instead of printing them.
*/

:- dynamic kb_module_/2.             % Module, N: a knowledge base, relrl_kb_N

%!  kb_module(?Module) is nondet.
%
%   Module is a knowledge base made by gw_new_kb/1 and not dropped.

kb_module(Module) :-
    kb_module_(Module, _).

%!  gw_new_kb(-Module) is det.
%
%   Module is a fresh, empty knowledge-base module, relrl_kb_N with N the least number no
%   knowledge base has now, that sees relrl's predicates. (A dropped knowledge base's name
%   is given again: its module was destroyed, and the files loaded into the new one are
%   recorded under the same names, so that SWI-Prolog's records of loaded files do not
%   grow with every knowledge base a long-lived process makes.)

gw_new_kb(Module) :-
    free_number(1, N),
    format(atom(Module), "relrl_kb_~d", [N]),
    assertz(kb_module_(Module, N)),
    set_module(Module:class(temporary)),   % destroyed when dropped (gw_drop_kb/1)
    add_import_module(Module, relrl, start),
    set_prolog_flag(Module:unknown, error).

free_number(N0, N) :-
    (   kb_module_(_, N0)
    ->  N1 is N0 + 1,
        free_number(N1, N)
    ;   N = N0
    ).

%!  gw_drop_kb(+Module) is det.
%
%   Forget everything relrl keeps for a knowledge base (relrl_engine:engine_forget/1: its
%   record, its learner's own clauses, its plans), unload the domain files consulted into
%   it and destroy the module itself, as library(modules) destroys a temporary module: a
%   process that makes and drops knowledge bases all day keeps no trace of them. Module
%   files a domain loaded (use_module(library(lists))) stay loaded: the rest of the
%   process uses them too; only their record of being loaded into Module goes.

gw_drop_kb(Module) :-
    must_be(atom, Module),
    engine_forget(Module),
    (   retract(kb_module_(Module, _))
    ->  forall(( source_file_property(File, load_context(Module, _, _)),
                 \+ source_file_property(File, module(_)) ),
               unload_file(File)),
        destroy_module(Module),
        garbage_collect_clauses,
        garbage_collect_atoms
    ;   true
    ).

%   The clause and atom garbage collections run at once: what the knowledge base's
%   clauses and compiled programs held is freed now, not once some 10,000 atoms more
%   (the atom collector's margin) have been made, which a process stepping one knowledge
%   base after another may take thousands of them to reach.

%!  destroy_module(+Module) is det.
%
%   Destroy the temporary module Module, its clauses and its records of loaded files.
%   SWI-Prolog 9.0.4 has no public predicate for this outside the goal of
%   in_temporary_module/3, whose module lives only while that goal runs; a knowledge base
%   lives across many calls from Python. library(modules) destroys its temporary modules with
%   its own destroy_module/1, which it does not export: this is the one place relrl calls it,
%   so that SWI-Prolog's internals stay SWI-Prolog's business. tests/prolog/test_kb_load.plt
%   fails if it stops destroying the module.

destroy_module(Module) :-
    modules:destroy_module(Module).

%!  gw_load(+File, +Module, -Problems:list) is det.
%
%   Consult File into Module. Problems lists every error and warning printed while
%   loading, as problem(Kind, File, Line, Message), in order; nothing is printed. A file
%   that does not exist gives one problem with line 0; a directive that runs past the
%   call's time limit or calls halt/0,1 gives an error at its line.

:- dynamic collecting/1, collected/2.

gw_load(File, Module, Problems) :-
    must_be(atom, Module),
    (   exists_file(File)
    ->  absolute_file_name(File, Abs),
        atomic_list_concat([Abs, '#', Module], Id),
        gensym(load_, Key),
        set_call_context(timeout_where, none),
        setup_call_cleanup(
            asserta(collecting(Key)),
            guarded(load_stream(Abs, Id, Module), Result),
            retract(collecting(Key))),
        (   Result = error(interrupted, _)      % Ctrl-C between directives: a stop,
        ->  retractall(collected(Key, _)),      % not a problem of the file
            throw(relrl_interrupted)
        ;   note_result(Result, Key, Abs)
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

%   The load's own result as a problem: an exception that ended it, or a halt.
note_result(true, _, _).
note_result(false, _, _).
note_result(error(Kind, Message), Key, File) :-
    (   Kind == time_limit_exceeded
    ->  call_context(timeout_where, Where),
        (   Where = F:L
        ->  true
        ;   F = File, L = 0
        ),
        Msg = "loading ran longer than the time limit: a directive that never ends?"
    ;   Kind = halt_called(F:L)
    ->  Msg = "halt/0,1 called while loading (a loaded file cannot end relrl)"
    ;   Kind == aborted
    ->  set_call_context(abort, File:0),
        F = File, L = 0, Msg = "abort/0 called while loading"
    ;   Kind = error(_, Context), nonvar(Context), Context = file(F, L, _, _)
    ->  Msg = Message
    ;   F = File, L = 0, Msg = Message
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
