/*  plunit tests of ptg (prolog/ptg.pl): P-learning beside tg's Q-tree, on blocks world.
    Run from pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_ptg.plt
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(readutil)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').
:- use_module('../../prolog/world').
:- use_module('../../prolog/ptg').

root_file(Relative, Path) :-
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../', Relative], Path).

blocks_kb(KB) :-
    relrl_gateway:gw_new_kb(KB),
    root_file('examples/worlds/blocks.pl', Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

params(P) :-
    P = [alpha=0.2, gamma=0.9, epsilon=0.05, temperature=1, q_init=0, significance=0.001,
         min_examples=5, stale_bonus=0, half_life=1000, novelty_bonus=0,
         novelty_confidence=2, keep_examples=0, action_gap=0, reward_positive=10, reward_negative= -1,
         p_margin=0, p_alpha=0.02, p_pairs=1].

%   Towers bottom first: [[b1, b2], [b3]] is b2 on b1 on the floor, b3 on the floor.
towers(Towers, State) :-
    foldl(tower, Towers, [], Facts),
    sort(Facts, State).

tower(Tower, F0, F) :-
    tower_(Tower, floor, F0, F).

tower_([], Under, F0, [clear(Under)|F0]) :-
    Under \== floor.
tower_([B|Bs], Under, F0, F) :-
    tower_(Bs, B, [on(B, Under)|F0], F).

score(KB, Task, Size, Score) :-
    world_episodes(KB, episodes(Task, [Size], 30, greedy, [optimal(1000)]), Eps),
    findall(X, ( member(ep(_, _, St, _, R, Opt, _), Eps),
                 (   R == true
                 ->  ( St =:= 0 -> X = 1 ; X is Opt / St )
                 ;   X = 0
                 ) ),
            Xs),
    sum_list(Xs, Sum),
    length(Xs, L),
    Score is Sum / L.

%   A ptg learner that has learned unstack on 3 blocks.
unstack_learned(KB) :-
    blocks_kb(KB),
    params(P),
    relrl_engine:engine_configure(KB, ptg, P, 0),
    world_episodes(KB, episodes(unstack, [3], 150, learn, []), _).

:- begin_tests(ptg).

test(learns_3_block_unstack_to_optimal) :-
    blocks_kb(KB),
    params(P),
    relrl_engine:engine_configure(KB, ptg, P, 0),
    score(KB, unstack, 3, Before),
    assertion(Before < 0.9),
    world_episodes(KB, episodes(unstack, [3], 150, learn, []), _),
    score(KB, unstack, 3, After),
    assertion(After =:= 1).

test(p_ranks_an_optimal_move_first_in_a_larger_world) :-
    % learned on 3 blocks, asked about 7: a tower's top onto the floor is optimal, the same
    % block onto another tower is not
    unstack_learned(KB),
    towers([[b1, b2, b3, b4], [b5, b6], [b7]], S),
    world_view(KB, unstack, S, V),
    ptg_p(KB, V, move(b4, floor), none, Good),
    ptg_p(KB, V, move(b4, b6), none, Bad),
    assertion(Good > Bad),
    Moves = [move(b4, b6), move(b4, floor), move(b6, b4)],
    relrl_engine:learner_choose(ptg, KB, V, none, actions(M, member(M, Moves)), greedy, A),
    assertion(A == move(b4, floor)).

test(terminal_transition_adds_no_p_example, [N == 0]) :-
    blocks_kb(KB),
    params(P),
    relrl_engine:engine_configure(KB, ptg, P, 0),
    towers([[b1, b2], [b3]], S),
    world_view(KB, unstack, S, V),
    world_actions(KB, S, Legal),
    once(relrl_engine:learner_update(ptg, KB, transition(V, move(b2, floor), none, Legal, 1,
                                                         true, terminal, none, []))),
    ptg_size(KB, size(_, Details)),
    memberchk(p_leaves=1, Details),
    ptg_key(KB, PK),
    relrl_tg_tree:tg_leaf(PK, 1, l(_, N, _, _, _, _, _, _, _)).

test(a_step_labels_a_pair, [N == 2]) :-
    % into a state that is not terminal: one optimal class (target 1) and one other (0)
    % while the Q-tree is one leaf every class is optimal: one example only; after a split
    % the Q-tree tells the classes apart and a pair is inserted
    unstack_learned(KB),
    ptg_key(KB, PK),
    towers([[b1, b2, b3]], S0),
    towers([[b1, b2], [b3]], S1),
    world_view(KB, unstack, S0, V0),
    world_view(KB, unstack, S1, V1),
    world_actions(KB, S0, Allowed0),
    world_actions(KB, S1, Allowed),
    relrl_tg:tg_size(PK, size(_, D0)),
    memberchk(leaves=L, D0),
    findall(Id-C, ( between(1, 1000, Id), relrl_tg_tree:tg_leaf(PK, Id, l(_, C, _, _, _, _,
                                                                         _, _, _)) ), Before),
    % (tg_update/2 may leave a choice point: once/1)
    once(relrl_engine:learner_update(ptg, KB, transition(V0, move(b3, floor), none, Allowed0,
                                                         0, false, V1, none, Allowed))),
    relrl_tg:tg_size(PK, size(_, D1)),
    assertion(memberchk(leaves=L, D1)),
    findall(Id-C, ( member(Id-_, Before), relrl_tg_tree:tg_leaf(PK, Id, l(_, C, _, _, _, _,
                                                                      _, _, _)) ), After),
    foldl([_-B, _-A, S00, S01]>>(S01 is S00 + A - B), Before, After, 0, N).

test(save_and_restore_act_the_same) :-
    unstack_learned(KB),
    with_output_to(string(Text), relrl_engine:learner_save(ptg, KB, current_output)),
    once(sub_string(Text, _, _, _, "ptg_tree(")),
    once(sub_string(Text, _, _, _, "p(move(")),
    term_string_list(Text, Terms),
    blocks_kb(KB2),
    params(P),
    relrl_engine:engine_configure(KB2, ptg, P, 5),
    relrl_engine:learner_restore(ptg, KB2, Terms),
    towers([[b1, b2, b3, b4], [b5, b6], [b7]], S),
    world_view(KB, unstack, S, V),
    world_legal(KB, S, Moves),
    forall(member(M, Moves),
           ( ptg_p(KB, V, M, none, P1), ptg_p(KB2, V, M, none, P2),
             assertion(abs(P1 - P2) < 1.0e-9) )).

test(bad_margin, [error(domain_error(nonneg, -1))]) :-
    blocks_kb(KB),
    params(P0),
    selectchk(p_margin=_, P0, p_margin= -1, P),
    ptg_init(KB, P).

test(one_record_per_kb, [Globals-Names == [Own]-[PK]]) :-
    % the P-tree's record and ptg's options are kept inside the knowledge base's record:
    % one global variable per knowledge base, and reconfiguring forgets the P-tree's name
    blocks_kb(KB),
    params(P),
    relrl_engine:engine_configure(KB, ptg, P, 0),
    ptg_key(KB, PK),
    relrl_tg_tree:tg_leaf(PK, 1, _),
    findall(G, ( nb_current(G, _), atom(G), sub_atom(G, _, _, 0, KB) ), Globals),
    atom_concat('$relrl_kb:', KB, Own),
    findall(K, relrl_kbstate:inner_(K, KB), Names),
    relrl_engine:engine_configure(KB, tg, P, 0),
    assertion(\+ relrl_kbstate:inner_(_, KB)),
    catch(relrl_tg_tree:tg_leaf(PK, 1, _), error(existence_error(tg_learner, PK), _), true),
    relrl_gateway:gw_drop_kb(KB).

:- end_tests(ptg).

term_string_list(Text, Terms) :-
    setup_call_cleanup(open_string(Text, S),
                       read_terms(S, Terms),
                       close(S)).

read_terms(S, Terms) :-
    read_term(S, T, []),
    (   T == end_of_file
    ->  Terms = []
    ;   Terms = [T|Ts],
        read_terms(S, Ts)
    ).
