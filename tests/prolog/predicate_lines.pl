/*  The lines of each predicate of the knowledge layer, as SWI-Prolog reads them: for each
    clause, from its first line to the line of its full stop, summed per Name/Arity of a
    file. Prints "Lines File Name/Arity" a line each. Directives are not counted. Used by
    tests/prolog/test_predicate_length.py:
        swipl -g main -t halt tests/prolog/predicate_lines.pl -- prolog/world.pl ...
*/
:- use_module(library(lists)).

main :-
    current_prolog_flag(argv, Files),
    forall(member(File, Files), file_lines(File)).

file_lines(File) :-
    setup_call_cleanup(open(File, read, S),
                       read_clauses(S, [], Counts),
                       close(S)),
    forall(member(PI-N, Counts), format("~d ~w ~q~n", [N, File, PI])).

read_clauses(S, Counts0, Counts) :-
    read_term(S, T, [term_position(P), module(relrl_predicate_lines)]),
    (   T == end_of_file
    ->  Counts = Counts0
    ;   stream_position_data(line_count, P, First),
        line_count(S, Last),
        Lines is Last - First + 1,
        (   clause_pi(T, PI)
        ->  add(PI, Lines, Counts0, Counts1)
        ;   Counts1 = Counts0
        ),
        read_clauses(S, Counts1, Counts)
    ).

clause_pi((:- _), _) :- !, fail.
clause_pi((H --> _), Name/Arity) :- !,
    head_pi(H, Name/Arity0),
    Arity is Arity0 + 2.
clause_pi((H :- _), PI) :- !,
    head_pi(H, PI).
clause_pi(H, PI) :-
    head_pi(H, PI).

head_pi(M:H, M:PI) :- !,
    head_pi(H, PI).
head_pi(H, Name/Arity) :-
    callable(H),
    functor(H, Name, Arity).

add(PI, N, Counts0, Counts) :-
    (   selectchk(PI-N0, Counts0, Rest)
    ->  N1 is N0 + N,
        Counts = [PI-N1|Rest]
    ;   Counts = [PI-N|Counts0]
    ).
