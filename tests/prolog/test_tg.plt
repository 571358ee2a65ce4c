/*  plunit tests of the tg learner: the refinement operator, the incremental statistics and
    the F-test split, on hand-made example streams. Run from pytest
    (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_tg.plt
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').
:- use_module('../../prolog/tg').
:- use_module('../../prolog/tg_bias').
:- use_module('../../prolog/tg_stats').
:- use_module('../../prolog/tg_tree').

tg_kb(KB, File) :-
    relrl_gateway:gw_new_kb(KB),
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../', File], Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

gaze_kb(KB) :-
    tg_kb(KB, 'tests/data/tg_gaze.pl').

params(Level, MinEx,
       [alpha=0, gamma=0.9, epsilon=0, temperature=0, q_init=0, significance=Level,
        min_examples=MinEx, stale_bonus=0, half_life=0, novelty_bonus=0,
        novelty_confidence=2, keep_examples=0, action_gap=0]).

fresh_learner(KB, Level, MinEx) :-
    gaze_kb(KB),
    params(Level, MinEx, Params),
    tg_init(KB, Params).

%   A hand-made stream: every (gaze, action) pair over places P of Places, Rounds times;
%   target 10 when the action looks where the caregiver looks, else 0, plus a small
%   deterministic wobble so that the groups have variance.
feed(KB, Places, Rounds) :-
    forall(( between(1, Rounds, R), member(G, Places), member(P, Places) ),
           ( ( G == P -> T0 = 10 ; T0 = 0 ),
             atom_length(G, LG), atom_codes(P, [_, C]),
             T is T0 + ((R * 7 + C + LG) mod 5) / 10,
             tg_insert(KB, [gaze(face, G)], look(P), curiosity, T) )).

root(KB, Root) :-
    relrl_tg_tree:tg_get_tree(KB, tree(Root, _, _, _)).

:- begin_tests(tg_refinement).

test(root_candidates, [Texts == ["gaze(face, P)", "gaze(face, p1)", "gaze(face, p2)",
                                 "gaze(face, p3)", "gaze(face, p4)", "fed(treat)",
                                 "action(look(P))", "gaze(face, P), action(look(P))"]]) :-
    gaze_kb(KB),
    root_refinements(KB, Texts).

test(input_needs_a_bound_variable, [Lits == []]) :-
    % head_at(+place) with no place variable on the path: nothing to test
    Bias = bias([head_at(+place)], [place-[a, b]]),
    refinements(Bias, [], [], Cands),
    findall(L, member(cand(L, _), Cands), Lits).

test(input_uses_path_variables, [Texts == ["head_at(P)", "head_at(P1)"]]) :-
    Bias = bias([head_at(+place)], [place-[a]]),
    Vars = [P-place, Q-place, _-toy],
    refinements(Bias, [at(P), at(Q)], Vars, Cands),
    findall(T, ( member(cand(L, _), Cands), name_variables(Vars, Ns), conj_text(L, Ns, T) ),
            Texts).

test(constants_and_new_variables,
     [Texts == ["colour(red)", "colour(blue)", "toy_at(T, P)", "toy_at(T, P), near(P)"]]) :-
    Bias = bias([colour(#colour), toy_at(-toy, -place), near(+place)],
                [colour-[red, blue]]),
    refinements(Bias, [], [], Cands),
    findall(T, ( member(cand(L, New), Cands), name_variables(New, Ns), conj_text(L, Ns, T) ),
            Texts).

test(implied_candidates_left_out, [Texts == ["action(look(P1))", "action(look(P))",
                                              "gaze(face, P1), action(look(P1))"]]) :-
    % on the yes-branch of gaze(face, P), gaze(face, P1) alone is implied by the path (and
    % left out); gaze(face, P1), action(look(P1)) is not: the action may look at another
    % place the caregiver looks at
    Bias = bias([gaze(#agent, -place), action(look(-place)), action(look(+place))],
                [agent-[face]]),
    refinements(Bias, [gaze(face, P)], [P-place], Cands),
    findall(T, ( member(cand(L, New), Cands),
                 append([P-place], New, Vs), name_variables(Vs, Ns),
                 conj_text(L, Ns, T) ),
            Texts).

test(order_and_names_give_one_candidate, [N == 1]) :-
    Bias = bias([gaze(#agent, -place), gaze(#agent, +place),
                 action(look(-place)), action(look(+place))], [agent-[face]]),
    refinements(Bias, [], [], Cands),
    aggregate_all(count, ( member(cand([_, _], _), Cands) ), N).

test(scoping_yes_branch_only) :-
    tg_kb(KB, 'examples/domains/sis.pl'),
    params(0.001, 10, Params),
    tg_init(KB, Params),
    forall(( between(1, 4, R), member(G, [left, down, right]), member(P, [left, down, right]) ),
           ( ( G == P -> T0 = 10 ; T0 = 0 ),
             T is T0 + (R mod 3) / 10,
             tg_insert(KB, [gaze(face, G), head_at(centre), sees(face)], look(P), socialize,
                       T) )),
    root(KB, node(_, Lits, [P-place], leaf(_, _, YesVars, YesCands),
                  leaf(_, _, NoVars, NoCands))),
    assertion(Lits =@= [gaze(face, X), action(look(X))]),
    assertion(YesVars == [P-place]),
    assertion(NoVars == []),
    % the yes-branch may use P; the no-branch never sees it
    assertion(( member(cand(L, _), YesCands), term_variables(L, Vs),
                member(V, Vs), V == P )),
    assertion(\+ ( member(cand(L2, _), NoCands), term_variables(L2, Vs2),
                   member(V2, Vs2), V2 == P )),
    % and the no-branch does not offer the test that sent examples there
    assertion(\+ ( member(cand(L3, _), NoCands), L3 =@= Lits )).

:- end_tests(tg_refinement).

:- begin_tests(tg_stats).

test(incremental, [S == s(4, 10.0, 30.0)]) :-
    stats_empty(S0),
    foldl([V, A, B]>>stats_add(A, V, B), [1, 2, 3, 4], S0, S).

test(mean_and_sse, [M-E == 2.5-5.0]) :-
    stats_mean(s(4, 10.0, 30.0), M),
    stats_sse(s(4, 10.0, 30.0), E).

test(split_f_by_hand, [F-Dof == 54.0-4]) :-
    % yes: 1, 2, 3; no: 7, 8, 9 -> SSE 58 in all, 2 + 2 within, F = 54 / (4 / 4)
    split_f(s(6, 30.0, 208.0), s(3, 6.0, 14.0), F, Dof).

test(split_f_empty_side, [fail]) :-
    split_f(s(6, 30.0, 208.0), s(6, 30.0, 208.0), _, _).

test(split_f_perfect, [F == inf]) :-
    split_f(s(4, 20.0, 200.0), s(2, 20.0, 200.0), F, _).

test(p_value_t_test, [true(abs(P - 0.0018263) < 1.0e-6)]) :-
    % F(1, 4) = 54 is t = 7.348 with 4 degrees of freedom
    f_p_value(54, 1, 4, P).

test(p_value_two_sided_t, [true(abs(P - 0.0733880) < 1.0e-6)]) :-
    f_p_value(4.0, 1, 10, P).

test(p_value_large_dof_is_normal, [true(abs(P - 0.001) < 2.0e-5)]) :-
    f_p_value(10.828, 1, 1000000, P).

test(incomplete_beta, [true(abs(I - 0.3483) < 1.0e-9)]) :-
    incomplete_beta(0.3, 2, 3, I).

test(significance) :-
    f_significant(54.0, 4, 0.01),
    \+ f_significant(54.0, 4, 0.001),
    f_significant(inf, 4, 0.001).

:- end_tests(tg_stats).

:- begin_tests(tg_split).

test(splits_on_the_relational_test, [true(Lits =@= [gaze(face, X), action(look(X))])]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    root(KB, node(_, Lits, _, _, _)).

test(no_split_before_min_examples, [Root = leaf(_, _, _, _)]) :-
    % 54 examples, 18 of which follow the gaze: fewer than 20 on that side
    fresh_learner(KB, 0.001, 20),
    feed(KB, [p1, p2, p3], 6),
    root(KB, Root).

test(no_split_on_noise, [Root = leaf(_, _, _, _)]) :-
    % the target depends on nothing a test can see
    fresh_learner(KB, 0.001, 10),
    forall(( between(1, 40, R), member(G, [p1, p2, p3, p4]), member(P, [p1, p2, p3, p4]) ),
           ( T is ((R * 31 + 7) mod 11) / 10,
             tg_insert(KB, [gaze(face, G)], look(P), curiosity, T) )),
    root(KB, Root).

test(children_start_from_partitions, [true(abs(Q - Expected) + abs(N - 12) < 1.0e-9)]) :-
    % no wobble: targets are exactly 10 (gaze followed) and 0. The split comes with the
    % 28th example (10 followed the gaze); the yes-child starts at the leaf's Q plus the
    % mean TD error of the examples on its side, replayed here (alpha 0: Q is the running
    % mean of the targets, from q_init 0), counts them (n = 10) and then takes the two
    % followed-gaze examples among the last eight (n = 11, 12)
    fresh_learner(KB, 0.001, 10),
    findall(G-P-T, ( between(1, 4, _), member(G, [p1, p2, p3]), member(P, [p1, p2, p3]),
                     ( G == P -> T = 10 ; T = 0 ) ), Stream),
    forall(member(G-P-T, Stream), tg_insert(KB, [gaze(face, G)], look(P), curiosity, T)),
    root(KB, node(_, _, _, leaf(Yes, _, _, _), _)),
    relrl_tg_tree:tg_leaf(KB, Yes, l(Q, N, _, _, _, _, _, _, _)),
    length(First, 28), append(First, _, Stream),
    foldl(replay, First, 0-0-[], QLeaf-_-Errors),
    sum_list(Errors, Sum), length(Errors, 10),
    Q10 is QLeaf + Sum / 10,
    Q11 is Q10 + (10 - Q10) / 11,
    Expected is Q11 + (10 - Q11) / 12.

%   The running mean Q of the targets, and the TD errors of the gaze-following examples.
replay(G-P-T, Q0-K0-Es0, Q-K-Es) :-
    K is K0 + 1,
    Q is Q0 + (T - Q0) / K,
    (   G == P
    ->  E is T - Q0, Es = [E|Es0]
    ;   Es = Es0
    ).

test(generalises_to_places_never_seen, [true(Q1-Q2 =:= Yes-No)]) :-
    % p4, never seen, sorts to the same leaves as the places seen: follow (Q high) or not
    fresh_learner(KB, 0.001, 10),
    forall(( between(1, 4, _), member(G, [p1, p2, p3]), member(P, [p1, p2, p3]) ),
           ( ( G == P -> T = 10 ; T = 0 ),
             tg_insert(KB, [gaze(face, G)], look(P), curiosity, T) )),
    tg_q(KB, [gaze(face, p4)], look(p4), curiosity, Q1),
    tg_q(KB, [gaze(face, p4)], look(p1), curiosity, Q2),
    tg_q(KB, [gaze(face, p1)], look(p1), curiosity, Yes),
    tg_q(KB, [gaze(face, p1)], look(p2), curiosity, No),
    assertion(Yes - No > 9).

test(greedy_choice_follows_gaze, [A == look(p4)]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    tg_choose(KB, [gaze(face, p4)], curiosity,
              [look(p1), look(p2), look(p3), look(p4)], greedy, A).

test(stale_leaf_tried_again_while_learning, [Learn-Greedy == look(p2)-look(p1)]) :-
    % after the split, 200 examples reach only the gaze-following leaf (Q 10, no variance:
    % no further split); the other leaf (Q 0) is 200 examples stale: 0 + 1 * sqrt(200) > 10
    gaze_kb(KB),
    params(0.001, 10, Params0),
    selectchk(stale_bonus=_, Params0, stale_bonus=1, Params),
    tg_init(KB, Params),
    forall(( between(1, 4, _), member(G, [p1, p2, p3]), member(P, [p1, p2, p3]) ),
           ( ( G == P -> T = 10 ; T = 0 ),
             tg_insert(KB, [gaze(face, G)], look(P), curiosity, T) )),
    forall(between(1, 200, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 10)),
    tg_choose(KB, [gaze(face, p1)], curiosity, [look(p1), look(p2)], learn, Learn),
    tg_choose(KB, [gaze(face, p1)], curiosity, [look(p1), look(p2)], greedy, Greedy).

test(no_stale_bonus_at_first, [A == look(p1)]) :-
    % the leaf just updated and a leaf 5 examples stale: sqrt(5) < 10
    gaze_kb(KB),
    params(0.001, 10, Params0),
    selectchk(stale_bonus=_, Params0, stale_bonus=1, Params),
    tg_init(KB, Params),
    forall(( between(1, 4, _), member(G, [p1, p2, p3]), member(P, [p1, p2, p3]) ),
           ( ( G == P -> T = 10 ; T = 0 ),
             tg_insert(KB, [gaze(face, G)], look(P), curiosity, T) )),
    forall(between(1, 5, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 10)),
    tg_choose(KB, [gaze(face, p1)], curiosity, [look(p1), look(p2)], learn, A).

%   An old era: 12 examples with fed(treat) and 100 without, all with targets near 0; then
%   200 without it near 10. Only fed(treat) tells examples apart, and only by when they came.
era_stream(KB) :-
    forall(between(1, 312, K),
           ( ( K =< 12 -> Facts = [fed(treat), gaze(face, p1)] ; Facts = [gaze(face, p1)] ),
             ( K =< 112 -> T0 = 0 ; T0 = 10 ),
             T is T0 + (K mod 7) / 2,
             tg_insert(KB, Facts, look(p1), curiosity, T) )).

learner_with(KB, Extra) :-
    gaze_kb(KB),
    params(0.001, 10, Params0),
    foldl([K=V, P0, P]>>selectchk(K=_, P0, K=V, P), Extra, Params0, Params),
    tg_init(KB, Params).

test(td_errors_do_not_split_on_an_old_era, [Root = leaf(_, _, _, _)]) :-
    % the statistics are over TD errors: the targets' jump from near 0 to near 10, which
    % the leaf's Q follows, does not make fed(treat) (only in the old era) look significant
    % even without forgetting (over the targets themselves it did)
    learner_with(KB, []),
    era_stream(KB),
    root(KB, Root).

test(forgetting_does_not, [Root = leaf(_, _, _, _)]) :-
    learner_with(KB, [half_life=20]),
    era_stream(KB),
    root(KB, Root).

test(forgetting_weights, [true(abs(Today - Expected) < 1.0e-9)]) :-
    % 10 examples, half-life 10: today they weigh 2^(-j/10), j = 0..9
    learner_with(KB, [half_life=10]),
    forall(between(1, 10, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 1)),
    today_weight(KB, Today),
    aggregate_all(sum(X), ( between(0, 9, J), X is 2 ** (-J / 10) ), Expected).

test(forgetting_rescales, [true(abs(Today - Expected) < 1.0e-9)]) :-
    % half-life 1: past 64 half-lives the sums are rescaled; today's weights are unchanged
    learner_with(KB, [half_life=1]),
    forall(between(1, 100, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 1)),
    today_weight(KB, Today),
    aggregate_all(sum(X), ( between(0, 99, J), X is 2 ** (-J) ), Expected).

today_weight(KB, Today) :-
    relrl_tg_tree:tg_leaf(KB, 1, l(_, _, M, _, _, _, _, Base, _)),
    relrl_tg_tree:tg_data(KB, tg(p(_, _, _, _, _, _, _, H, _, _, _), _, _, _, Clock, _)),
    Today is M / 2 ** ((Clock - Base) / H).

test(update_uses_the_next_state, [true(abs(Q - 19.0) < 1.0e-9)]) :-
    % one leaf; Q(s', .) = 10 after the first example; target = 10 + 0.9 * 10
    fresh_learner(KB, 0.001, 1000),
    tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 10),
    tg_update(KB, transition([gaze(face, p1)], look(p2), curiosity, [look(p2)], 10, true,
                             [gaze(face, p2)], curiosity, [look(p1)])),
    tg_q(KB, [gaze(face, p1)], look(p1), curiosity, Q0),
    Q is 2 * Q0 - 10.                    % the leaf's mean of 10 and the target

test(return_lambda_mixes_the_episode_return_into_the_target,
     [true(abs(Q - Expected) < 1.0e-9)]) :-
    % one leaf, alpha 0 (the running mean). An episode learned last first: its last step
    % (from Sb, terminal, reward 4: target 4), then the step into Sb (reward 0): its target
    % is 0.9 * ((1 - 0.5) * max Q(Sb) + 0.5 * 4), the return Sb's step earned in half
    return_learner(KB, 0.5),
    Sa = [gaze(face, p1)], Sb = [gaze(face, p2)],
    tg_insert(KB, Sa, look(p1), curiosity, 10),
    tg_update(KB, transition(Sb, look(p1), curiosity, [look(p1)], 4, true, terminal,
                             curiosity, [])),
    tg_q(KB, Sb, look(p1), curiosity, Max),            % 7: the mean of 10 and 4
    tg_update(KB, transition(Sa, look(p2), curiosity, [look(p2)], 0, true, Sb, curiosity,
                             [look(p1)])),
    tg_q(KB, Sa, look(p2), curiosity, Q),
    Target is 0.9 * (0.5 * Max + 0.5 * 4),
    Expected is (10 + 4 + Target) / 3.

test(return_lambda_needs_the_next_state_learned_last, [true(abs(Q - Expected) < 1.0e-9)]) :-
    % the step before was from another state (steps learned first to last, or another
    % episode's): the target is the one-step target alone
    return_learner(KB, 0.5),
    Sa = [gaze(face, p1)], Sb = [gaze(face, p2)],
    tg_insert(KB, Sa, look(p1), curiosity, 10),
    tg_update(KB, transition(Sa, look(p1), curiosity, [look(p1)], 4, true, terminal,
                             curiosity, [])),
    tg_q(KB, Sb, look(p1), curiosity, Max),
    tg_update(KB, transition(Sa, look(p2), curiosity, [look(p2)], 0, true, Sb, curiosity,
                             [look(p1)])),
    tg_q(KB, Sa, look(p2), curiosity, Q),
    Target is 0.9 * Max,
    Expected is (10 + 4 + Target) / 3.

return_learner(KB, Lambda) :-
    gaze_kb(KB),
    params(0.001, 1000, Params),
    tg_init(KB, [return_lambda=Lambda|Params]).

test(action_gap_lowers_the_target_by_the_gap, [true(abs(Q - Expected) < 1.0e-9)]) :-
    % a split tree: following the gaze (Q near 10), not (near 0). A look away from the gaze
    % with reward 0 in a terminal step: its target 0 is lowered by 0.5 times the gap
    % between the state's best allowed response (look(p1)) and its own leaf's Q
    gap_learner(KB, 0.5),
    S0 = [gaze(face, p1)],
    tg_q(KB, S0, look(p1), curiosity, Best),
    tg_q(KB, S0, look(p2), curiosity, Q0),
    relrl_tg_tree:tg_sort_(KB, S0, look(p2), curiosity, Leaf),
    relrl_tg_tree:tg_leaf(KB, Leaf, l(_, N0, _, _, _, _, _, _, _)),
    tg_update(KB, transition(S0, look(p2), curiosity, [look(p1), look(p2)], 0, false,
                             terminal, curiosity, [])),
    tg_q(KB, S0, look(p2), curiosity, Q),
    Target is 0 - 0.5 * (Best - Q0),
    Expected is Q0 + (Target - Q0) / (N0 + 1).      % alpha 0: the running mean

test(action_gap_is_over_the_allowed_responses, [true(abs(Q - Expected) < 1.0e-9)]) :-
    % the same step when only looks away from the gaze were allowed: no gap, target 0
    gap_learner(KB, 0.5),
    S0 = [gaze(face, p1)],
    tg_q(KB, S0, look(p2), curiosity, Q0),
    relrl_tg_tree:tg_sort_(KB, S0, look(p2), curiosity, Leaf),
    relrl_tg_tree:tg_leaf(KB, Leaf, l(_, N0, _, _, _, _, _, _, _)),
    tg_update(KB, transition(S0, look(p2), curiosity, [look(p2), look(p3)], 0, false,
                             terminal, curiosity, [])),
    tg_q(KB, S0, look(p2), curiosity, Q),
    Expected is Q0 + (0 - Q0) / (N0 + 1).

test(action_gap_never_raises_a_target, [true(abs(Q - Expected) < 1.0e-9)]) :-
    % a response emitted outside the allowed ones (an agent may emit any): its own Q is
    % above the best allowed one, and the target stays 0 rather than going up
    gap_learner(KB, 0.5),
    S0 = [gaze(face, p1)],
    tg_q(KB, S0, look(p1), curiosity, Q0),
    relrl_tg_tree:tg_sort_(KB, S0, look(p1), curiosity, Leaf),
    relrl_tg_tree:tg_leaf(KB, Leaf, l(_, N0, _, _, _, _, _, _, _)),
    once(tg_update(KB, transition(S0, look(p1), curiosity, [look(p2), look(p3)], 0, false,
                                  terminal, curiosity, []))),
    tg_q(KB, S0, look(p1), curiosity, Q),
    Expected is Q0 + (0 - Q0) / (N0 + 1).

test(no_action_gap_no_change, [true(abs(Q - Expected) < 1.0e-9)]) :-
    gap_learner(KB, 0),
    S0 = [gaze(face, p1)],
    tg_q(KB, S0, look(p2), curiosity, Q0),
    relrl_tg_tree:tg_sort_(KB, S0, look(p2), curiosity, Leaf),
    relrl_tg_tree:tg_leaf(KB, Leaf, l(_, N0, _, _, _, _, _, _, _)),
    tg_update(KB, transition(S0, look(p2), curiosity, [look(p1), look(p2)], 0, false,
                             terminal, curiosity, [])),
    tg_q(KB, S0, look(p2), curiosity, Q),
    Expected is Q0 + (0 - Q0) / (N0 + 1).

%   A tree split on following the gaze (targets 10 and 0 with a wobble), action_gap Gap.
gap_learner(KB, Gap) :-
    plunit_tg_split:learner_with(KB, [action_gap=Gap]),
    feed(KB, [p1, p2, p3], 6),
    root(KB, node(_, _, _, _, _)).

test(explain_shows_bindings, [Path == [test(1, "gaze(face, P), action(look(P))", true,
                                            ['P'-p4])]]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    tg_explain(KB, [gaze(face, p4)], curiosity, tg([choice(look(p4), _, _, Path)|_])).

test(size_counts_nodes_and_entries, [P-Ds == 5-[nodes=3, tests=1, leaves=2, entries=2]]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    tg_size(KB, size(P, Details)),
    Details = [A, B, C, D|_], Ds = [A, B, C, D].

:- end_tests(tg_split).

:- begin_tests(tg_novelty).

%   Nine examples (gaze p2, look p3) with target 0, then two (gaze p1, look p1) with target
%   10; alpha 0, q_init 0, no forgetting. TD errors: nine 0 (Q stays 0), then 10 (Q becomes
%   1) and 9 (Q 20/11). No split (fewer than 2 * min_examples).
novelty_learner(KB, Beta) :-
    learner_with(KB, [novelty_bonus=Beta, novelty_confidence=2]),
    forall(between(1, 9, _), tg_insert(KB, [gaze(face, p2)], look(p3), curiosity, 0)),
    forall(between(1, 2, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 10)).

learner_with(KB, Extra) :-
    plunit_tg_split:learner_with(KB, Extra).

test(bound_of_the_best_region, [true(abs(B - Expected) < 1.0e-9)]) :-
    % gaze(face, P), action(look(P)) and gaze(face, p1): TD errors 10 and 9, mean 9.5,
    % variance 0.25: 9.5 + 2 * sqrt(0.25 / 2)
    novelty_learner(KB, 20),
    tg_bonus(KB, [gaze(face, p1)], look(p1), curiosity, B),
    Expected is 9.5 + 2 * sqrt(0.125).

test(unseen_region_gets_the_whole_bonus, [B =:= 20]) :-
    % no example has had gaze(face, p3)
    novelty_learner(KB, 20),
    tg_bonus(KB, [gaze(face, p3)], look(p2), curiosity, B).

test(bound_is_capped, [B =:= 5]) :-
    novelty_learner(KB, 5),
    tg_bonus(KB, [gaze(face, p1)], look(p1), curiosity, B).

test(well_known_region_gets_the_leafs_bound, [true(abs(B - Expected) < 1.0e-9)]) :-
    % gaze(face, p2): nine TD errors 0, bound 0; gaze(face, P) and action(look(P)) hold of
    % every example, as the leaf: 11 TD errors, sum 19, sum of squares 181
    novelty_learner(KB, 20),
    tg_bonus(KB, [gaze(face, p2)], look(p3), curiosity, B),
    Mean is 19 / 11,
    Var is 181 / 11 - Mean * Mean,
    Expected is Mean + 2 * sqrt(Var / 11).

test(nothing_to_learn_no_bonus, [B =:= 0]) :-
    % every TD error 0: every bound is 0
    learner_with(KB, [novelty_bonus=20, novelty_confidence=2]),
    forall(between(1, 9, _), tg_insert(KB, [gaze(face, p2)], look(p3), curiosity, 0)),
    tg_bonus(KB, [gaze(face, p2)], look(p3), curiosity, B).

test(off_when_zero, [B =:= 0]) :-
    novelty_learner(KB, 0),
    tg_bonus(KB, [gaze(face, p3)], look(p2), curiosity, B).

test(learning_choice_only) :-
    % one leaf: Q is the same for both; while learning look(p2) has the bound 10.21 of
    % gaze(face, P), action(look(P)), look(p3) the leaf's 3.94 (temperature 0, epsilon 0:
    % greedy on Q + bonus). Exploring without learning, the tie is broken at random.
    novelty_learner(KB, 20),
    Allowed = [look(p2), look(p3)],
    forall(between(1, 20, _),
           ( tg_choose(KB, [gaze(face, p2)], curiosity, Allowed, learn, A),
             assertion(A == look(p2)) )),
    findall(A, ( between(1, 50, _),
                 tg_choose(KB, [gaze(face, p2)], curiosity, Allowed, explore, A) ), As),
    assertion(memberchk(look(p3), As)).

test(forgotten_examples_count_less, [true(abs(B - Expected) < 1.0e-9)]) :-
    % half-life 1: of the two examples of gaze(face, p1) the older weighs 1/2 today,
    % n = 1.5 < 2: the region is as good as unseen
    learner_with(KB, [novelty_bonus=20, novelty_confidence=2, half_life=1]),
    forall(between(1, 2, _), tg_insert(KB, [gaze(face, p1)], look(p1), curiosity, 10)),
    tg_bonus(KB, [gaze(face, p1)], look(p1), curiosity, B),
    Expected = 20.

:- end_tests(tg_novelty).

:- begin_tests(tg_policy).

saved_terms(KB, Terms) :-
    with_output_to(string(Text), tg_save(KB, current_output)),
    setup_call_cleanup(open_string(Text, S),
                       read_all(S, Terms),
                       close(S)).

read_all(S, Terms) :-
    read_term(S, T, []),
    (   T == end_of_file
    ->  Terms = []
    ;   Terms = [T|Ts],
        read_all(S, Ts)
    ).

test(save_restore_same_values) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    saved_terms(KB, Terms),
    assertion(forall(member(T, Terms), tg_policy_term(T))),
    fresh_learner(KB2, 0.001, 10),
    tg_restore(KB2, Terms),
    forall(( member(G, [p1, p2, p3, p4]), member(P, [p1, p2, p3, p4]) ),
           ( tg_q(KB, [gaze(face, G)], look(P), curiosity, Q1),
             tg_q(KB2, [gaze(face, G)], look(P), curiosity, Q2),
             assertion(Q1 =:= Q2) )).

test(rules_are_readable, [Text == "q(look(P), _, 10.692) :-\n    gaze(face, P).\n"]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    tg_leaf_clauses(KB, [Rule|_]),
    with_output_to(string(Text), portray_clause(Rule)).

test(negations_read_simply,
     [Texts == ["q(look(p1), _, 1.0).\n",
                "q(look(P), _, 2.0) :-\n    gaze(face, P),\n    P\\=p1.\n",
                "q(Action, _, 3.0) :-\n    Action\\=look(p1),\n    \\+ ( gaze(face, P),\n         Action=look(P)\n       ).\n"]]) :-
    % the no-branch of action(look(p1)) under the gaze test is P \= p1, not
    % \+ look(P) = look(p1); the last leaf negates both tests
    fresh_learner(KB, 0.001, 10),
    tg_restore(KB, [tg_tree(node(1, [action(look(p1))], [],
                                 leaf(2, 1.0, 1),
                                 node(3, [gaze(face, P), action(look(P))], [P-place],
                                      leaf(4, 2.0, 1), leaf(5, 3.0, 1))))]),
    tg_leaf_clauses(KB, Rules),
    findall(T, ( member(R, Rules),
                 with_output_to(string(T), portray_clause(R)) ), Texts).

test(edited_rule_refused, [error(domain_error(tg_rules_match_tree, _))]) :-
    fresh_learner(KB, 0.001, 10),
    feed(KB, [p1, p2, p3], 6),
    saved_terms(KB, Terms0),
    select((q(A, N, _) :- B), Terms0, (q(A, N, 99.0) :- B), Terms),
    fresh_learner(KB2, 0.001, 10),
    tg_restore(KB2, Terms).

test(malformed_tree_refused, [error(domain_error(tg_tree, _))]) :-
    fresh_learner(KB, 0.001, 10),
    tg_restore(KB, [tg_tree(leaf(one, 2.0, 3))]).

:- end_tests(tg_policy).

:- begin_tests(tg_bias_check).

bias_messages(Text, Msgs) :-
    tmp_file_stream(text, File, S),
    write(S, Text), close(S),
    relrl_gateway:gw_new_kb(KB),
    relrl_gateway:gw_load(File, KB, []),
    findall(L-M, bias_problem(KB, problem(_, L, M)), Msgs0),
    msort(Msgs0, Msgs),
    delete_file(File).

test(undeclared_relation, [Msgs == [3-"rmode gaze(#agent,-place): gaze/2 is not a declared relation (add relation(gaze(_,_)).)"]]) :-
    bias_messages("response(look(a)).\nrconst(agent, face).\nrmode(gaze(#agent, -place)).\n",
                  Msgs).

test(missing_constants, [Msgs == [2-"rmode head_at(#place): no constants of type place (add rconst(place, Value).)"]]) :-
    bias_messages("relation(head_at(_)).\nrmode(head_at(#place)).\nhead_at(a).\n", Msgs).

test(unbindable_input, [Msgs == [2-"rmode head_at(+place): +place can never be bound (no rmode introduces a variable of type place with -place)"]]) :-
    bias_messages("relation(head_at(_)).\nrmode(head_at(+place)).\nhead_at(a).\n", Msgs).

test(bad_mode_argument, [Msgs = [2-_]]) :-
    bias_messages("relation(head_at(_)).\nrmode(head_at(+_)).\nhead_at(a).\n", Msgs).

test(action_matches_no_response, [Msgs == [2-"rmode action(point(-place)) matches no declared response"]]) :-
    bias_messages("response(look(a)).\nrmode(action(point(-place))).\n", Msgs).

test(reserved_relation, [Msgs = [1-_]]) :-
    bias_messages("relation(action(_)).\n", Msgs).

test(shipped_domains_clean, [Msgs == []]) :-
    findall(M, ( member(F, ['examples/domains/sis.pl', 'examples/domains/fruits.pl',
                            'tests/data/tg_gaze.pl']),
                 tg_kb(KB, F),
                 bias_problem(KB, M) ), Msgs).

:- end_tests(tg_bias_check).
