:- module(relrl_world_states,
          [ world_read_states/4,  % +KB, +File, +Task, -Answer
            world_state_texts/4   % +KB, +Texts, +Task, -Answer
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(world, [world_task/3]).

/** <module> Start states of a world, read as data

`relrl evaluate --states FILE` runs a saved policy from start states a researcher writes.
This module reads them and checks them against the world loaded into a knowledge base;
nothing in them is ever run.

A Prolog states file holds one term per state, each ended by a full stop:

    [on(b1, floor), on(b2, b1), clear(b2)].                 % a list of facts
    state([on(b1, floor), on(b2, floor), clear(b1), clear(b2)], on(b1, b2)).

`state(Facts)` is the same as the plain list; `state(Facts, Task)` gives the episode's
task, an instance of the evaluated task (its goal is then that instance's). The file is read
term by term with read_term/3: a clause or a directive is a term like any other, and one
that is not a state is refused. A JSON states file (the Python side reads the JSON) gives
each fact as text, which world_state_texts/4 parses as a term, again without running it.

A state must be a list of ground facts, each an instance of a relation the world declares
(relation/1; any ground fact when it declares none). A problem is answered as
problem(Line, Message), the line of the term at fault.
*/

%!  world_read_states(+KB, +File, +Task, -Answer) is det.
%
%   Answer is states(States), States a non-empty list of state(Line, Facts, Instance)
%   (Instance `none` or the episode's task, an instance of Task), or problem(Line, Message)
%   for the first term of File that is not a state of the world loaded into KB (a syntax
%   error included).

world_read_states(KB, File, Task, Answer) :-
    must_be(atom, KB),
    must_be(callable, Task),
    setup_call_cleanup(open(File, read, S, [encoding(utf8)]),
                       catch(read_states(KB, S, Task, States), states_problem(L, M),
                             Problem = problem(L, M)),
                       close(S)),
    (   nonvar(Problem)
    ->  Answer = Problem
    ;   States == []
    ->  Answer = problem(1, "no state in the file (one term per state: a list of facts)")
    ;   Answer = states(States)
    ).

read_states(KB, S, Task, States) :-
    read_state_term(S, T, Line),
    (   T == end_of_file
    ->  States = []
    ;   state_term(KB, Task, Line, T, State),
        States = [State|Rest],
        read_states(KB, S, Task, Rest)
    ).

read_state_term(S, T, Line) :-
    catch(read_term(S, T, [term_position(Pos), syntax_errors(error)]), E,
          read_problem(S, E)),
    (   nonvar(Pos)
    ->  stream_position_data(line_count, Pos, Line)
    ;   line_count(S, Line)
    ).

read_problem(S, E) :-
    (   E = error(syntax_error(What), Context)
    ->  (   Context = stream(_, Line, _, _)
        ->  true
        ;   line_count(S, Line)
        ),
        format(string(M), "syntax error: ~w", [What]),
        throw(states_problem(Line, M))
    ;   E = error(Formal, _),
        memberchk(Formal, [io_error(_, _), representation_error(_)])
    ->  line_count(S, Line),
        format(string(M), "cannot read: ~q (not a text file?)", [Formal]),
        throw(states_problem(Line, M))
    ;   throw(E)
    ).

state_term(KB, Task, Line, T, state(Line, Facts, Instance)) :-
    (   is_list(T)
    ->  Facts = T, Instance = none
    ;   T = state(Facts)
    ->  Instance = none
    ;   T = state(Facts, Instance)
    ->  instance_problem(KB, Task, Line, Instance)
    ;   format(string(M), "~q is not a state (a list of facts, state(Facts) or \c
                           state(Facts, Task))", [T]),
        throw(states_problem(Line, M))
    ),
    (   facts_problem(KB, Facts, M)
    ->  throw(states_problem(Line, M))
    ;   true
    ).

instance_problem(KB, Task, Line, Instance) :-
    (   ground(Instance),
        callable(Instance),
        subsumes_term(Task, Instance),
        world_task(KB, Instance, _)
    ->  true
    ;   format(string(M), "~q is not an instance of the task ~q", [Instance, Task]),
        throw(states_problem(Line, M))
    ).

%!  world_state_texts(+KB, +Texts:list, +Task, -Answer) is det.
%
%   Answer is facts(Facts), the facts Texts (strings, each one term) name, or
%   problem(I, Message) for the I-th text (from 1) that is not a fact of the world loaded
%   into KB (a syntax error included). Task is the evaluated task (unused by the facts;
%   kept for one signature with world_read_states/4).

world_state_texts(KB, Texts, _Task, Answer) :-
    must_be(atom, KB),
    must_be(list, Texts),
    catch(( parse_texts(Texts, 1, Facts),
            (   facts_problem(KB, Facts, M)
            ->  Answer0 = problem(0, M)
            ;   Answer0 = facts(Facts)
            )
          ),
          states_problem(I, M), Answer0 = problem(I, M)),
    Answer = Answer0.

parse_texts([], _, []).
parse_texts([Text|Texts], I, [F|Fs]) :-
    (   text(Text)
    ->  true
    ;   format(string(M), "~q is not a fact as text", [Text]),
        throw(states_problem(I, M))
    ),
    catch(term_string(F, Text, [syntax_errors(error)]), error(syntax_error(What), _),
          ( format(string(M), "~q: syntax error: ~w", [Text, What]),
            throw(states_problem(I, M)) )),
    I1 is I + 1,
    parse_texts(Texts, I1, Fs).

text(T) :-
    (   atom(T)
    ->  true
    ;   string(T)
    ).

%   The first problem of Facts as a state of KB's world.
facts_problem(KB, Facts, M) :-
    (   \+ is_list(Facts)
    ->  format(string(M), "~q is not a list of facts", [Facts])
    ;   Facts == []
    ->  M = "an empty state"
    ;   member(F, Facts),
        \+ ( callable(F), ground(F) )
    ->  copy_term(F, Shown),
        numbervars(Shown, 0, _, [singletons(true)]),
        format(string(M), "~W is not a ground fact", [Shown, [quoted(true), numbervars(true)]])
    ;   declared(KB, relation(_)),
        member(F, Facts),
        \+ ( declared(KB, relation(R)), subsumes_term(R, F) )
    ->  findall(N/A, ( declared(KB, relation(R)), functor(R, N, A) ), PIs0),
        sort(PIs0, PIs),
        format(string(M), "~q is not a fact of the world's relations (~w)", [F, PIs])
    ),
    !.
