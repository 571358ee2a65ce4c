/*  plunit tests of relrl_percept_check (prolog/percept_check.pl) and of relrl's declarations for
    domain files (prolog/declarations.pl). Run from pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_percept_check.plt
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').

%   A knowledge base holding the clauses of Text, loaded as relrl loads a domain file.
kb_with(Text, KB) :-
    relrl_gateway:gw_new_kb(KB),
    tmp_file_stream(text, File, Out),
    write(Out, Text),
    close(Out),
    relrl_gateway:gw_load(File, KB, Problems),
    delete_file(File),
    assertion(Problems == []).

sis([see(face), see(toy), see(environment), pose(face, frontal), pose(face, left),
     at(toy, left), colour(toy, _), at(centre), at(left), hear(attention)]).
episodes([see(face), see(object), see(environment), pose(face, frontal),
          pose(face, left_2), colour(object, red), at(object, left), at(centre), at(left),
          hear(_)]).

domain("stimulus(face).
fact(gaze_left(face)).
gaze_left(face) :- percept(pose(face, left)).
fact(profile(face)).
profile(face) :- percept(pose(face, left_2)).
fact(any_left(face)).
any_left(face) :- ( percept(pose(face, left)) -> true ; percept(pose(face, left_2)) ).
fact(helped(face)).
helped(face) :- helper(left).
helper(P) :- see(face), percept(pose(face, P)).
fact(not_left(face)).
not_left(face) :- \\+ percept(pose(face, left)).
fact(seen_left(face)).
seen_left(face) :- see(gaze_left(face)).
response(look(centre)).
").

%   The facts named by problem messages "fact F can never hold ...".
facts(Problems, Facts) :-
    findall(F, ( member(problem(_, _, M), Problems),
                 once(sub_string(M, Before, _, _, " can never hold")),
                 Length is Before - 5,
                 sub_string(M, 5, Length, _, F0),
                 atom_string(F, F0) ), Facts).

:- begin_tests(world_problems).

test(sis_world, [Facts == ['profile(face)']]) :-
    domain(Text), kb_with(Text, KB), sis(V),
    relrl_percept_check:world_problems(KB, V, Problems),
    facts(Problems, Facts).

test(episodes_world, [Facts == ['gaze_left(face)', 'helped(face)', 'seen_left(face)']]) :-
    domain(Text), kb_with(Text, KB), episodes(V),
    relrl_percept_check:world_problems(KB, V, Problems),
    facts(Problems, Facts).

test(located_and_explained, [Where-Msg == 2-"fact gaze_left(face) can never hold in this \c
     world: it needs pose(face, left), which the world never perceives"]) :-
    domain(Text), kb_with(Text, KB), episodes(V),
    relrl_percept_check:world_problems(KB, V, [problem(_, Where, Msg)|_]).

test(stimulus_never_perceived, [Msg == "stimulus toy is never perceived in this world"]) :-
    kb_with("stimulus(toy).\nresponse(r).\n", KB),
    relrl_percept_check:world_problems(KB, [see(face)], [problem(_, 1, Msg)]).

test(recursion_terminates, [Problems == []]) :-
    kb_with("stimulus(face).\nfact(loop(face)).\nloop(X) :- loop(X).\nresponse(r).\n", KB),
    relrl_percept_check:world_problems(KB, [see(face)], Problems).

test(dynamic_may_hold, [Problems == []]) :-
    kb_with(":- dynamic remembered/1.\nstimulus(face).\nfact(remembered(face)).\n\c
             response(r).\n", KB),
    relrl_percept_check:world_problems(KB, [see(face)], Problems).

:- end_tests(world_problems).

:- begin_tests(unread_percepts).

test(unread, [Unread == [se(face), colour(face, red), see(dog)]]) :-
    domain(Text), kb_with(Text, KB),
    relrl_percept_check:unread_percepts(KB, [se(face), see(face), pose(face, left),
                                       colour(face, red), pose(face, left_2), see(dog),
                                       at(face, left)],
                                   Unread).

:- end_tests(unread_percepts).

:- begin_tests(declarations).

test(interleaved_and_at_the_end, [Rs == [look(centre), look(left)]]) :-
    kb_with("stimulus(face).\nresponse(look(centre)).\nfact(f(face)).\n\c
             f(face) :- see(face).\nresponse(look(left)).\n", KB),
    findall(R, relrl_declarations:kb_response(KB, R), Rs).

test(module_files_left_alone, [true]) :-
    relrl_gateway:gw_new_kb(KB),
    KB:use_module(library(prolog_trace)).

:- end_tests(declarations).
