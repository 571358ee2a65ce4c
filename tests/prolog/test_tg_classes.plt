/*  plunit tests of the tg learner at any size: classes of responses the bias cannot tell
    apart (choices, Q-targets), statistics that survive a split, the engine computing only
    what tg reads, and the check of a bias whose constants grow with the world. Run from
    pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_tg_classes.plt
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(aggregate)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').
:- use_module('../../prolog/tg').
:- use_module('../../prolog/tg_bias').
:- use_module('../../prolog/tg_tree').
:- use_module('../../prolog/tg_classes').

places_kb(KB) :-
    relrl_gateway:gw_new_kb(KB),
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../tests/data/tg_places.pl'], Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

params(Extra, Params) :-
    Params0 = [alpha=0, gamma=0.9, epsilon=0, temperature=1, q_init=0, significance=0.001,
               min_examples=5, stale_bonus=0, half_life=0, novelty_bonus=0,
               novelty_confidence=2, keep_examples=0, action_gap=0, reward_positive=10,
               reward_negative= -1],
    foldl([K=V, P0, P]>>selectchk(K=_, P0, K=V, P), Extra, Params0, Params).

learner(KB, Extra) :-
    places_kb(KB),
    params(Extra, Params),
    tg_init(KB, Params).

index(KB, Index, Responses) :-
    findall(R, relrl_declarations:kb_response(KB, R), Responses),
    tg_bias(KB, Bias),
    tg_response_index(Bias, Responses, Index).

members(Index, Class, Members) :-
    findall(A, member_of(Index, Class, A), Members0),
    sort(Members0, Members).

member_of(rindex(Rs, _, Groups, _, _), cls(Rep, Pick), A) :-
    (   Pick == one
    ->  A = Rep
    ;   Pick = among(Is)
    ->  member(I, Is), arg(I, Rs, A)
    ;   Pick = rest(G, Excluded),
        arg(G, Groups, grp(Ms, _)),
        Ms =.. [_|Is],
        member(I, Is), \+ memberchk(I, Excluded),
        arg(I, Rs, A)
    ).

state(1, [gaze(face, p3), toy_at(ball, p7)]).
state(2, [gaze(face, home)]).
state(3, [gaze(face, p3), toy_at(ball, p3), fed(treat)]).
state(4, []).

:- begin_tests(tg_classes).

test(classes_from_the_index,
     [Classes == [cls(look(home), one), cls(look(p1), rest(2, [4, 8])), cls(wait, one),
                  cls(look(p3), one), cls(look(p7), one)]]) :-
    % the state names p3 and p7: each is a class of its own; the ten places it does not
    % name are one class, drawn from without them
    places_kb(KB),
    index(KB, Index, Rs),
    state(1, Facts),
    tg_classes(Index, Facts, Rs, true, Classes).

test(classes_partition_the_responses) :-
    places_kb(KB),
    index(KB, Index, Rs),
    msort(Rs, All),
    forall(state(_, Facts),
           ( tg_classes(Index, Facts, Rs, true, Classes),
             maplist(members(Index), Classes, Ms),
             append(Ms, Flat),
             msort(Flat, Sorted),
             assertion(Sorted == All) )).

test(without_the_index_the_same_classes) :-
    % a constraint rule may forbid some responses: then the allowed ones are grouped one
    % by one; with all of them allowed the two ways agree
    places_kb(KB),
    index(KB, Index, Rs),
    forall(state(_, Facts),
           ( tg_classes(Index, Facts, Rs, true, C1),
             tg_classes(Index, Facts, Rs, false, C2),
             maplist(members(Index), C1, M1), msort(M1, S1),
             maplist(members(Index), C2, M2), msort(M2, S2),
             assertion(S1 == S2) )).

test(only_allowed_responses, [Members == [wait, look(p2), look(p3)]]) :-
    places_kb(KB),
    index(KB, Index, _),
    tg_classes(Index, [gaze(face, p3)], [look(p2), look(p3), wait], false, Classes),
    maplist(members(Index), Classes, Ms),
    append(Ms, Members0),
    msort(Members0, Members).

test(a_class_is_drawn_from_uniformly, [true(Counts == 10)]) :-
    places_kb(KB),
    index(KB, Index, Rs),
    state(1, Facts),
    tg_classes(Index, Facts, Rs, true, Classes),
    Classes = [_, Rest|_],
    findall(A, ( between(1, 3000, _), tg_class_member(Index, Rest, A) ), Drawn),
    assertion(\+ memberchk(look(p3), Drawn)),
    assertion(\+ memberchk(look(p7), Drawn)),
    msort(Drawn, Sorted),
    clumped(Sorted, Pairs),
    length(Pairs, Counts),
    forall(member(_-K, Pairs), assertion(abs(K - 300) < 90)),
    tg_class_size(Index, Rest, 10).

test(members_of_a_class_share_a_leaf) :-
    % what the classes rest on: no test of a grown tree (nor any candidate) tells two
    % members of a class apart
    learner(KB, []),
    forall(( between(1, 12, J), atom_concat(p, J, G) ),
           forall(member(L, [home, p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12]),
                  ( ( L == G -> T = 10 ; T = 0 ),
                    tg_insert(KB, [gaze(face, G)], look(L), curiosity, T) ))),
    tg_size(KB, size(_, Details)),
    memberchk(leaves=Leaves, Details),
    assertion(Leaves > 1),
    index(KB, Index, Rs),
    forall(state(_, Facts),
           ( tg_classes(Index, Facts, Rs, true, Classes),
             forall(member(C, Classes),
                    ( C = cls(Rep, _),
                      relrl_tg_tree:tg_sort_(KB, Facts, Rep, curiosity, Leaf),
                      relrl_tg_tree:tg_cands_(KB, Leaf, Facts, Rep, curiosity, Hits),
                      forall(member_of(Index, C, A),
                             ( relrl_tg_tree:tg_sort_(KB, Facts, A, curiosity, LeafA),
                               relrl_tg_tree:tg_cands_(KB, LeafA, Facts, A, curiosity,
                                                       HitsA),
                               assertion(LeafA-HitsA == Leaf-Hits) )) )) )).

test(boltzmann_over_classes, [true(abs(Share - 0.25) < 0.04)]) :-
    % one leaf, every Q alike: the choice is uniform over the four classes (home, the
    % place she looks at, the other places, wait), not over the fourteen responses
    learner(KB, []),
    findall(R, relrl_declarations:kb_response(KB, R), Rs),
    findall(A, ( between(1, 4000, _),
                 tg_choose(KB, [gaze(face, p3)], curiosity, Rs, explore, A) ), As),
    aggregate_all(count, member(look(p3), As), Hits),
    Share is Hits / 4000.

:- end_tests(tg_classes).

:- begin_tests(tg_kept_examples).

%   Examples of two kinds (look where she looks: target 10; elsewhere: 0), up to the
%   example that splits the root; the children then hold the kept examples of their sides.
split_stream(KB) :-
    findall(G-L, ( between(1, 3, _), member(G, [p1, p2, p3, p4]),
                   member(L, [p1, p2, p3, p4]) ), Stream),
    insert_until_split(Stream, KB).

insert_until_split([G-L|Stream], KB) :-
    ( L == G -> T = 10 ; T = 0 ),
    tg_insert(KB, [gaze(face, G)], look(L), curiosity, T),
    (   tg_get_tree(KB, tree(node(_, _, _, _, _), _, _, _))
    ->  true
    ;   insert_until_split(Stream, KB)
    ).

child_counts(KB, Counts) :-
    once(tg_get_tree(KB, tree(node(_, _, _, leaf(Y, _, _, _), leaf(N, _, _, _)), _, _, _))),
    maplist([Id, M-CandM]>>( tg_leaf(KB, Id, L), arg(3, L, M), arg(6, L, C),
                             C =.. [_|Xs], sum_counts(Xs, CandM) ), [Y, N], Counts).

sum_counts([], 0).
sum_counts([M, _, _|Xs], S) :-
    sum_counts(Xs, S0),
    S is S0 + M.

test(children_start_empty_without_kept_examples, [Counts == [0-0, 0-0]]) :-
    learner(KB, [keep_examples=0, action_gap=0]),
    split_stream(KB),
    child_counts(KB, Counts).

test(children_start_from_the_kept_examples, [true((MY > 0, MN > 0, CN > 0, MY + MN =< 32))]) :-
    learner(KB, [keep_examples=32]),
    split_stream(KB),
    child_counts(KB, [MY-_, MN-CN]).

test(kept_examples_keep_the_split_statistics_consistent) :-
    % each child's own count is the number of kept examples on its side (no forgetting),
    % and its TD errors are centred on its new Q
    learner(KB, [keep_examples=32]),
    split_stream(KB),
    once(tg_get_tree(KB, tree(node(_, _, _, leaf(Y, _, _, _), _), _, _, _))),
    tg_leaf(KB, Y, L),
    arg(3, L, M), arg(4, L, S), arg(9, L, Ring),
    Ring =.. [_, _|Slots],
    exclude(==(none), Slots, Kept),
    length(Kept, K),
    assertion(M =:= K),
    assertion(abs(S / M) < 1.0e-6).

:- end_tests(tg_kept_examples).

:- begin_tests(tg_engine_view).

test(no_state_code_for_tg, [true((Code == 0, R == true, Mask == -1))]) :-
    places_kb(KB),
    params([], Params),
    relrl_engine:engine_configure(KB, tg, Params, 0),
    relrl_engine:engine_step(KB, [see(face), pose(face, p3), smell(treat)], -1, learn, [],
                             step(Code, _, _, _, R, Mask, _, _)).

test(etg_still_gets_the_code, [true(Code > 0)]) :-
    places_kb(KB),
    relrl_engine:engine_configure(KB, etg, [alpha=0.2, gamma=0.9, epsilon=0.05,
                                            q_init=30, split_threshold=0.1,
                                            reward_positive=10, reward_negative= -1], 0),
    relrl_engine:engine_step(KB, [see(face), pose(face, p3)], -1, learn, [],
                             step(Code, _, _, _, _, _, _, _)).

test(policy_info_names_no_place, [true(\+ ( sub_term(X, Info), X == p3 ))]) :-
    places_kb(KB),
    params([], Params),
    relrl_engine:engine_configure(KB, tg, Params, 0),
    relrl_engine:engine_policy_info(KB, Info),
    assertion(memberchk(rmodes(_), Info)).

:- end_tests(tg_engine_view).

:- begin_tests(tg_bias_growth).

warnings(Text, Ws) :-
    tmp_file_stream(text, File, S),
    write(S, Text), close(S),
    relrl_gateway:gw_new_kb(KB),
    relrl_gateway:gw_load(File, KB, []),
    findall(L, bias_warning(KB, problem(_, L, _)), Ws),
    delete_file(File).

test(a_constant_per_response_warns, [Ws == [5]]) :-
    warnings("response(look(a)).\nresponse(look(b)).\nresponse(look(c)).\n\c
              relation(seen(_)).\nrmode(seen(#place)).\nseen(a).\n\c
              rconst(place, a).\nrconst(place, b).\nrconst(place, c).\n", Ws).

test(many_constants_warn, [Ws == [2]]) :-
    numlist(1, 11, Ns),
    foldl([N, T0, T]>>format(string(T), "~wrconst(colour, c~w).~n", [T0, N]), Ns, "", Cs),
    format(string(Text), "relation(seen(_)).\nrmode(seen(#colour)).\nseen(c1).\n\c
                          response(r).\n~w", [Cs]),
    warnings(Text, Ws).

test(variables_and_a_few_constants_do_not_warn, [Ws == []]) :-
    warnings("response(look(a)).\nresponse(look(b)).\nresponse(look(home)).\n\c
              relation(seen(_)).\nrmode(seen(-place)).\nrmode(seen(#home)).\nseen(a).\n\c
              rconst(home, home).\n", Ws).

:- end_tests(tg_bias_growth).
