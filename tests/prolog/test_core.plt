/*  plunit tests of the learning core: motivation (Eq. 1, 2), contingency, the Q-tree and
    ETG (Algorithm 3, Eq. 4), the control step on hand-made percept streams, and the parts
    of the step made fast (the state plan, the rules loop, working memory's look-ups).
    Run from pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_core.plt
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').

domain_path(File, Path) :-
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../', File], Path).

kb_with(File, KB) :-
    relrl_gateway:gw_new_kb(KB),
    domain_path(File, Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

close_to(Expected, Actual) :-
    abs(Expected - Actual) < 0.0005.

etg_params([alpha=0.5, gamma=0.9, epsilon=0.0, q_init=0.0, split_threshold=1.0,
            reward_positive=10.0, reward_negative= -1.0]).

% ---------------------------------------------------------------------------------------
:- begin_tests(motivation).

test(eq1_by_hand, [true(U =:= 0.5*1 + -1.5*0 + 0.25*0.4 + 1.0)]) :-
    relrl_motivation:unit_activation([0.5-1, -1.5-0], 0.25, 0.4, 1.0, U).

test(eq2_by_hand, [true(close_to(0.768525, Y))]) :-
    relrl_motivation:unit_output(1.0, 0.2, Y).

%   docs/engine.md: alone, socialize climbs 0.769, 0.877, 0.889 towards 0.890.
test(socialize_alone_rises, [true(maplist(close_to, [0.768525, 0.877490, 0.888741], Ys))]) :-
    kb_with('examples/domains/fruits.pl', KB),
    relrl_motivation:motivation_reset(KB),
    findall(Y, ( between(1, 3, _),
                 relrl_memory:wm_insert(KB, []),
                 relrl_motivation:motivation_step(KB, [socialize-Y], _) ), Ys).

%   ... and falls to about 0.171 with attention, a frontal face and the robot looking at it.
test(socialize_satisfied_falls, [true((close_to(0.171, Y), Active == none))]) :-
    kb_with('examples/domains/fruits.pl', KB),
    relrl_motivation:motivation_reset(KB),
    forall(between(1, 30, _),
           ( relrl_memory:wm_insert(KB, []),
             relrl_motivation:motivation_step(KB, _, _) )),
    Contact = [hear(attention), see(face), pose(face, frontal), at(centre)],
    forall(between(1, 30, _),
           ( relrl_memory:wm_insert(KB, Contact),
             relrl_motivation:motivation_step(KB, _, _) )),
    relrl_memory:wm_insert(KB, Contact),
    relrl_motivation:motivation_step(KB, [socialize-Y], Active).

test(mediator_threshold, [true(Active == socialize)]) :-
    kb_with('examples/domains/fruits.pl', KB),
    relrl_motivation:motivation_reset(KB),
    relrl_memory:wm_insert(KB, []),
    relrl_motivation:motivation_step(KB, _, Active).

:- end_tests(motivation).

% ---------------------------------------------------------------------------------------
:- begin_tests(contingency).

contingency_params([default_fitness=1.0, influence=0.5, min_fitness=0.05,
                    max_fitness=10.0, default_always=0.0, extinction=1.0, satiation=0.0]).

%   A response with no rule creates one from the default fitness moved by the consequence.
test(new_rule_from_consequence, [Rules == [behaviour(state(5), a, hunger, 1.5)]]) :-
    kb_with('tests/data/tiny.pl', KB),
    contingency_params(P),
    relrl_contingency:contingency_init(KB),
    relrl_contingency:contingency_update(KB, 5, a, hunger, true, P),
    relrl_contingency:contingency_rules(KB, Rules).

%   The rule a choice used rises when the reinforcer came, falls otherwise, within bounds.
test(fitness_moves_and_clamps, [Fs == [1.5, 2.0, 1.5, 0.05]]) :-
    kb_with('tests/data/tiny.pl', KB),
    contingency_params(P),
    relrl_contingency:contingency_init(KB),
    relrl_contingency:contingency_update(KB, 1, a, hunger, true, P),
    findall(F, ( member(R, [true, false, skip]),
                 (   R == skip
                 ->  forall(between(1, 10, _),
                            ( relrl_contingency:contingency_choose(KB, 1, hunger, [a], P, _),
                              relrl_contingency:contingency_update(KB, 1, a, hunger, false, P)
                            ))
                 ;   relrl_contingency:contingency_choose(KB, 1, hunger, [a], P, a),
                     relrl_contingency:contingency_update(KB, 1, a, hunger, R, P)
                 ),
                 relrl_contingency:contingency_rules(KB, [behaviour(_, a, _, F)]) ), Fs0),
    Fs = [1.5|Fs0].

%   Roulette-wheel: a response's slice is its rules' fitness (default without one).
test(roulette_proportional, [true(abs(Share - 0.75) < 0.02)]) :-
    kb_with('tests/data/tiny.pl', KB),
    relrl_contingency:contingency_restore(KB, [behaviour(state(1), a, hunger, 3.0)]),
    contingency_params(P),
    set_random(seed(11)),
    findall(A, ( between(1, 4000, _),
                 relrl_contingency:contingency_choose(KB, 1, hunger, [a, b], P, A) ), As),
    include(==(a), As, AsA),
    length(AsA, NA),
    Share is NA / 4000.

%   A hand-made stream in state 1 under `hunger`: response a emitted four times and
%   reinforced three of them (in the order +, +, -, +), b emitted twice and never
%   reinforced, c never emitted. Each step forces the response (it is the only one allowed)
%   and learns from the given consequence.
stream_fitness(Params, Fitness, Probabilities) :-
    stream_kb(Params, KB),
    relrl_contingency:contingency_rules(KB, Rules),
    findall(R-F, member(behaviour(state(1), R, hunger, F), Rules), Fitness),
    relrl_contingency:contingency_probabilities(KB, 1, hunger, [a, b, c], Params,
                                                Probabilities).

stream_kb(Params, KB) :-
    kb_with('tests/data/tiny.pl', KB),
    relrl_contingency:contingency_init(KB),
    forall(member(R-Reinforced, [a-true, a-true, a-false, a-true, b-false, b-false]),
           ( relrl_contingency:contingency_choose(KB, 1, hunger, [R], Params, R),
             relrl_contingency:contingency_update(KB, 1, R, hunger, Reinforced, Params) )).

probabilities_close(Expected, Actual) :-
    pairs_keys(Expected, Rs), pairs_keys(Actual, Rs),
    maplist([_-E, _-A]>>close_to(E, A), Expected, Actual).

%   The fixed task's reading: a's rule 1.5, 2.0, 1.5, 2.0; b's 0.5 then 0.05 (the lower
%   bound); c keeps the default 1: execution probabilities 2/3.05, 0.05/3.05, 1/3.05.
test(execution_probabilities_fixed_task,
     [Fitness-Ok == [a-2.0, b-0.05]-true]) :-
    contingency_params(P),
    stream_fitness(P, Fitness, Probabilities),
    (   probabilities_close([a-(2/3.05), b-(0.05/3.05), c-(1/3.05)], Probabilities)
    ->  Ok = true
    ;   Ok = Probabilities
    ).

%   Fitness is an execution probability (max_fitness 1, the paper-2012 preset): a's rule
%   cannot rise above 1 (1, 1, 0.5, 1); b falls to 0.05: probabilities 1/2.05, 0.05/2.05,
%   1/2.05 - a wrong response that failed twice keeps 1/(1 + 0.05 k) of the right one's
%   chances against k of them.
test(execution_probabilities_as_probabilities,
     [Fitness-Ok == [a-1.0, b-0.05]-true]) :-
    contingency_params(P0),
    selectchk(max_fitness=_, P0, max_fitness=1.0, P),
    stream_fitness(P, Fitness, Probabilities),
    (   probabilities_close([a-(1/2.05), b-(0.05/2.05), c-(1/2.05)], Probabilities)
    ->  Ok = true
    ;   Ok = Probabilities
    ).

%   The default kept in every slice: a rule starts from nothing moved by its consequence
%   (a: 0.5, 1.0, 0.5, 1.0; b: 0.05, 0.05) and adds to the default 1: slices 2, 1.05, 1.
test(execution_probabilities_default_always,
     [Fitness-Ok == [a-1.0, b-0.05]-true]) :-
    contingency_params(P0),
    selectchk(default_always=_, P0, default_always=1.0, P),
    stream_fitness(P, Fitness, Probabilities),
    (   probabilities_close([a-(2/4.05), b-(1.05/4.05), c-(1/4.05)], Probabilities)
    ->  Ok = true
    ;   Ok = Probabilities
    ).

%   The letter of the necessity clauses: no reinforcer leaves a rule as it is (extinction
%   0), a reinforcer when no necessity is active lowers it (satiation 1).
test(no_extinction_and_satiation, [Fs == [a-1.5, b-1.0, c-0.5]]) :-
    kb_with('tests/data/tiny.pl', KB),
    contingency_params(P0),
    selectchk(extinction=_, P0, extinction=0.0, P1),
    selectchk(satiation=_, P1, satiation=1.0, P),
    relrl_contingency:contingency_init(KB),
    forall(member(R-N-Reinforced, [a-hunger-true, b-hunger-false, c-none-true]),
           ( relrl_contingency:contingency_choose(KB, 1, N, [R], P, R),
             relrl_contingency:contingency_update(KB, 1, R, N, Reinforced, P) )),
    relrl_contingency:contingency_rules(KB, Rules),
    findall(R-F, member(behaviour(state(1), R, _, F), Rules), Fs).

%   The roulette draws with those probabilities: 20,000 choices from the first stream's
%   rules land on each response within 0.01 of its execution probability.
test(roulette_draws_the_execution_probabilities, [true(Worst < 0.01)]) :-
    contingency_params(P),
    stream_kb(P, KB),
    relrl_contingency:contingency_probabilities(KB, 1, hunger, [a, b, c], P, Probabilities),
    set_random(seed(5)),
    N = 20000,
    findall(A, ( between(1, N, _),
                 relrl_contingency:contingency_choose(KB, 1, hunger, [a, b, c], P, A) ), As),
    findall(D, ( member(R-Pr, Probabilities),
                 aggregate_all(count, member(R, As), C),
                 D is abs(C / N - Pr) ), Ds),
    max_list(Ds, Worst).

%   What a choice in state 1 would weigh: each response with a rule, highest first.
test(explain_ranks_the_rules, [Ranked == [a-2.0, b-0.05]]) :-
    contingency_params(P),
    stream_kb(P, KB),
    relrl_contingency:contingency_explain(KB, 1, hunger, Ranked).

%   A response other than the one chosen, emitted and learned from twice, keeps both rules
%   (their fitness counts twice, as stored).
test(a_rule_learned_twice_counts_twice, [Rules-Size == [behaviour(state(2), b, hunger, 1.5),
                                                        behaviour(state(2), b, hunger, 1.5)]
                                                       -size(2, 2)]) :-
    kb_with('tests/data/tiny.pl', KB),
    contingency_params(P),
    relrl_contingency:contingency_init(KB),
    relrl_contingency:contingency_update(KB, 2, b, hunger, true, P),
    relrl_contingency:contingency_update(KB, 2, b, hunger, true, P),
    relrl_contingency:contingency_rules(KB, Rules),
    relrl_contingency:contingency_size(KB, Size).

%   A control step changes the rules in the knowledge base's record: the module keeps no
%   clause of its own for a knowledge base.
test(no_clauses_per_knowledge_base, [Dynamic == []]) :-
    contingency_params(P),
    stream_kb(P, _),
    findall(PI, ( predicate_property(relrl_contingency:H, dynamic),
                  \+ predicate_property(relrl_contingency:H, imported_from(_)),
                  functor(H, Name, Arity), PI = Name/Arity ), Dynamic).

:- end_tests(contingency).

% ---------------------------------------------------------------------------------------
:- begin_tests(kbstate).

%   A knowledge base's record: made at first use, a part read and replaced through the
%   record or through the knowledge base's name alike, a value stored as a copy, every
%   read deterministic, and forgotten whole.
test(record_parts, [true(Got =@= [t(1), t(1), f(_), none])]) :-
    relrl_kbstate:kb_forget(krec1),
    relrl_kbstate:kb_record(krec1, R),
    relrl_kbstate:record_set(R, task, t(1)),
    relrl_kbstate:kb_get(krec1, task, A),
    relrl_kbstate:record_get(R, task, B),
    relrl_kbstate:kb_set(krec1, learner, f(X)),
    X = 1,                                              % the stored copy is not bound
    relrl_kbstate:kb_record(krec1, R2),
    relrl_kbstate:record_get(R2, learner, C),
    relrl_kbstate:kb_forget(krec1),
    relrl_kbstate:kb_get(krec1, task, D),               % a fresh record
    relrl_kbstate:kb_forget(krec1),
    Got = [A, B, C, D].

test(parts_read_deterministically) :-
    relrl_kbstate:kb_record(krec2, R),
    forall(member(P, [engine, memory, units, learner, tree, task, kept]),
           (   call_cleanup(relrl_kbstate:record_get(R, P, V), Det1 = true),
               call_cleanup(relrl_kbstate:record_set(R, P, V), Det2 = true),
               assertion(Det1-Det2 == true-true)
           )),
    relrl_kbstate:kb_forget(krec2).

test(unknown_part, [error(domain_error(kb_part, nope)),
                    cleanup(relrl_kbstate:kb_forget(krec3))]) :-
    relrl_kbstate:kb_get(krec3, nope, _).

test(forgotten, [fail]) :-
    relrl_kbstate:kb_record(krec4, _),
    relrl_kbstate:kb_forget(krec4),
    relrl_kbstate:kb_record_exists(krec4).

test(nested_record, [V-Gone == 1-true]) :-
    % a record kept inside another: read and set under its own key, gone with its owner
    relrl_kbstate:kb_nest(krec5, krec5_inner, opts),
    relrl_kbstate:kb_set(krec5_inner, learner, 1),
    relrl_kbstate:kb_get(krec5_inner, learner, V),
    relrl_kbstate:kb_get(krec5, inner, inner(krec5_inner, opts, kb(_, _, _, 1, _, _, _, _, _))),
    \+ relrl_kbstate:kb_record_exists(krec5_inner),
    relrl_kbstate:kb_forget(krec5),
    (   relrl_kbstate:inner_(krec5_inner, _) -> Gone = false ; Gone = true ).

:- end_tests(kbstate).

:- begin_tests(qtree).

test(leaf_of_no_tree, [error(existence_error(qtree, none))]) :-
    % a hook holding `none` (the tree never made) is an error, as for every accessor
    relrl_qtree:qtree_leaf(none, 0, _, _).

test(new_tree_one_empty_leaf, [Nodes == [0-leaf(none, [])]]) :-
    relrl_qtree:qtree_new(t1, [a, b]),
    relrl_qtree:qtree(t1, T),
    findall(I-N, relrl_qtree:qtree_node(T, I, N), Nodes).

put_all(Entries, Es) :-
    foldl(put_one, Entries, [], Es).

put_one(E, L0, L) :-
    relrl_qtree:qtree_put_entry(L0, E, L).

test(entries_in_decreasing_q_ties_keep_order,
     [Es == [e(c, 3, n), e(a, 1, n), e(b, 1, n), e(a, 0, m)]]) :-
    put_all([e(a, 1, n), e(b, 1, n), e(a, 0, m), e(c, 3, n)], Es).

test(put_replaces_same_action_and_necessity, [Es == [e(b, 2, n), e(a, 0.5, n)]]) :-
    put_all([e(a, 1, n), e(b, 2, n), e(a, 0.5, n)], Es).

test(split_and_sort, [Where == [leaf(1), null(0, no), leaf(1)]]) :-
    relrl_qtree:qtree_new(t2, [x0, x1]),
    relrl_qtree:qtree(t2, T),
    relrl_qtree:qtree_set_leaf(T, 0, 1, [e(a, 1, n)]),    % representative: bit 0 set
    relrl_qtree:qtree_split(T, 0, 0),
    findall(W, ( member(D, [1, 2, 3]), relrl_qtree:qtree_sort(T, D, W) ), Where).

test(grow_on_null, [Leaf == leaf(2, [e(b, 4, n)])]) :-
    relrl_qtree:qtree_new(t3, [x0]),
    relrl_qtree:qtree(t3, T),
    relrl_qtree:qtree_set_leaf(T, 0, 1, []),
    relrl_qtree:qtree_split(T, 0, 0),
    relrl_qtree:qtree_grow(T, 0, no, 2, [e(b, 4, n)], Id),
    once(relrl_qtree:qtree_node(T, Id, Leaf)).

test(no_tree, [error(existence_error(qtree, t4))]) :-
    relrl_qtree:qtree_clear(t4),
    relrl_qtree:qtree(t4, _).

test(not_a_leaf, [error(existence_error(qtree_leaf, 0))]) :-
    relrl_qtree:qtree_new(t5, [x0]),
    relrl_qtree:qtree(t5, T),
    relrl_qtree:qtree_set_leaf(T, 0, 1, []),
    relrl_qtree:qtree_split(T, 0, 0),
    relrl_qtree:qtree_set_leaf(T, 0, 1, []).

test(first_difference_lowest_bit, [I == 1]) :-
    relrl_qtree:first_difference(0b101, 0b111, I).

%   Eq. 4 and Algorithm 3 by hand (alpha 0.5, gamma 0.9, q_init 0, split threshold 1),
%   tests: stimulus(light) 0, stimulus(dark) 1, stimulus(food) 2.
test(etg_by_hand) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    % 1. light, a, r=10, next dark: one empty leaf; Q = 0.5 * 10.
    relrl_etg:etg_update(KB, 1, a, hunger, 10, 2, hunger, [], P),
    tree_nodes(KB, [0-leaf(1, [e(a, 5.0, hunger)])]),
    % 2. light, b, r=-1: target -1 + 0.9*5 = 3.5; kept in decreasing Q.
    relrl_etg:etg_update(KB, 1, b, hunger, -1, 2, hunger, [], P),
    tree_nodes(KB, [0-leaf(1, [e(a, 5.0, hunger), e(b, 1.75, hunger)])]),
    % 3. dark, a, r=1: target 5.5, error 0.5 <= 1: dark shares light's leaf.
    relrl_etg:etg_update(KB, 2, a, hunger, 1, 1, hunger, [], P),
    tree_nodes(KB, [0-leaf(1, [e(a, 5.25, hunger), e(b, 1.75, hunger)])]),
    % 4. dark, b, r=-1: target 3.725, error 1.975 > 1: split on stimulus(light); dark
    %    grows a leaf on the empty no-branch with Q(b) = 0.5 * 3.725.
    relrl_etg:etg_update(KB, 2, b, hunger, -1, 1, hunger, [], P),
    tree_nodes(KB, [0-test(0, stimulus(light), 1, 2),
               1-leaf(1, [e(a, 5.25, hunger), e(b, 1.75, hunger)]),
               2-leaf(2, [e(b, Q4, hunger)])]),
    close_to(1.8625, Q4),
    % 5. dark, c, r=10: target 10 + 0.9*5.25; Q = 7.3625 goes first.
    relrl_etg:etg_update(KB, 2, c, hunger, 10, 1, hunger, [], P),
    relrl_qtree:qtree(KB, T),
    once(relrl_qtree:qtree_node(T, 2, leaf(2, [e(c, Q5, hunger), e(b, _, hunger)]))),
    close_to(7.3625, Q5),
    relrl_engine:engine_size(KB, Size),
    Size == size(etg, 7, [nodes=3, leaves=2, entries=4]).

tree_nodes(KB, Nodes) :-
    relrl_qtree:qtree(KB, T),
    findall(I-N, relrl_qtree:qtree_node(T, I, N), Nodes0),
    msort(Nodes0, Nodes).

:- end_tests(qtree).

% ---------------------------------------------------------------------------------------
:- begin_tests(engine_step).

%   tiny.pl: light 1, dark 2, food 4; hunger always active; food is the reinforcer; no
%   constraint rules, so every response is allowed (mask -1).
test(step_reports_code_reward_and_mask,
     [true((Code == 5, N == hunger, Reward =:= 10, R == true, Mask == -1,
            between(0, 2, A)))]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light), smell(food)], -1, learn, [],
                             step(Code, N, [Y], Reward, R, Mask, A, [])),
    assertion(Y > 0.5).

test(emitted_enters_memory, [Pairs == [0-emitted(b), 0-see(dark)]]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_step(KB, [see(dark)], 1, learn, [memory], step(_, _, _, _, _, _, _,
                                                                       [memory-M])),
    assertion(M == [0-emitted(b), 0-see(dark)]),
    relrl_memory:wm_elements(KB, Pairs).

%   The example of the previous step is learned at this step with this step's reward:
%   a (index 0) in the light, then food: Q(light, a) = 0.5 * (10 + 0.9 * q_init).
test(learns_previous_step, [Entries == [e(a, 5.0, hunger)]]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_step(KB, [see(dark), smell(food)], 0, learn, [], _),
    relrl_qtree:qtree(KB, T),
    relrl_qtree:qtree_leaf(T, 0, _, Entries).

test(greedy_and_explore_do_not_learn, [Nodes == [0-leaf(none, [])]]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light)], -1, greedy, [], _),
    relrl_engine:engine_step(KB, [see(dark), smell(food)], 0, explore, [], _),
    relrl_engine:engine_step(KB, [see(light)], 2, greedy, [], _),
    relrl_qtree:qtree(KB, T),
    findall(I-N, relrl_qtree:qtree_node(T, I, N), Nodes).

test(end_episode_cuts_the_link, [Nodes == [0-leaf(none, [])]]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_end_episode(KB),
    relrl_engine:engine_step(KB, [see(dark), smell(food)], 0, learn, [], _),
    relrl_qtree:qtree(KB, T),
    findall(I-N, relrl_qtree:qtree_node(T, I, N), Nodes).

%   Each knowledge base draws from its own random stream.
test(random_streams_per_kb, [As1 == As2]) :-
    Steps = [[see(light)], [see(dark)], [see(light), smell(food)], [see(dark)]],
    P = [alpha=0.2, gamma=0.9, epsilon=1.0, q_init=0.0, split_threshold=0.1,
         reward_positive=10.0, reward_negative= -1.0],
    kb_with('tests/data/tiny.pl', A),
    relrl_engine:engine_configure(A, etg, P, 7),
    findall(X, ( member(S, Steps),
                 relrl_engine:engine_step(A, S, -1, learn, [], step(_, _, _, _, _, _, X, _)) ),
            As1),
    kb_with('tests/data/tiny.pl', B),
    kb_with('tests/data/tiny.pl', C),
    relrl_engine:engine_configure(B, etg, P, 7),
    relrl_engine:engine_configure(C, etg, P, 8),
    findall(X, ( member(S, Steps),
                 relrl_engine:engine_step(C, S, -1, learn, [], _),
                 random(_),
                 relrl_engine:engine_step(B, S, -1, learn, [], step(_, _, _, _, _, _, X, _)) ),
            As2).

%   Between two steps the generator holds the stream of the knowledge base that stepped
%   last; engine_pause/0 puts it away, so numbers drawn afterwards are no agent's.
test(parked_stream_is_not_drawn_from, [As1 == As2]) :-
    Steps = [[see(light)], [see(dark)], [see(light), smell(food)], [see(dark)],
             [see(light)], [see(dark)], [see(light)], [see(dark), smell(food)]],
    P = [alpha=0.2, gamma=0.9, epsilon=1.0, q_init=0.0, split_threshold=0.1,
         reward_positive=10.0, reward_negative= -1.0],
    kb_with('tests/data/tiny.pl', A),
    relrl_engine:engine_configure(A, etg, P, 7),
    findall(X, ( member(S, Steps),
                 relrl_engine:engine_step(A, S, -1, learn, [], step(_, _, _, _, _, _, X, _)) ),
            As1),
    kb_with('tests/data/tiny.pl', B),
    relrl_engine:engine_configure(B, etg, P, 7),
    findall(X, ( member(S, Steps),
                 relrl_engine:engine_step(B, S, -1, learn, [], step(_, _, _, _, _, _, X, _)),
                 relrl_engine:engine_pause,
                 random(_), random(_) ),
            As2).

%   The stream a snapshot keeps is the one the knowledge base draws from now, whether the
%   generator holds it (the knowledge base stepped last) or not.
test(snapshot_takes_the_live_stream, [Same == true]) :-
    P = [alpha=0.2, gamma=0.9, epsilon=1.0, q_init=0.0, split_threshold=0.1,
         reward_positive=10.0, reward_negative= -1.0],
    kb_with('tests/data/tiny.pl', KB),
    relrl_engine:engine_configure(KB, etg, P, 5),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_snapshot(KB, snapshot(_, _, eng(_, R1), _)),
    relrl_engine:engine_pause,
    relrl_engine:engine_snapshot(KB, snapshot(_, _, eng(_, R2), _)),
    same(R1, R2, Same).          % (not the states themselves: 2.5 KB each in a message)

%   Ending an episode leaves the stream where the last step left it; reseeding replaces it,
%   whether or not the generator holds it.
test(end_episode_keeps_and_reseed_replaces_the_stream, [Same == true-true]) :-
    P = [alpha=0.2, gamma=0.9, epsilon=1.0, q_init=0.0, split_threshold=0.1,
         reward_positive=10.0, reward_negative= -1.0],
    kb_with('tests/data/tiny.pl', KB),
    relrl_engine:engine_configure(KB, etg, P, 5),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_step(KB, [see(dark)], 0, learn, [], _),
    relrl_engine:engine_snapshot(KB, snapshot(_, _, eng(_, R1), _)),
    relrl_engine:engine_end_episode(KB),
    relrl_engine:engine_snapshot(KB, snapshot(_, _, eng(_, R2), _)),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_reseed(KB, 7),
    relrl_engine:engine_snapshot(KB, snapshot(_, _, eng(_, R3), _)),
    set_random(seed(7)),
    random_property(state(R7)),
    same(R1, R2, Kept),
    same(R3, R7, Replaced),
    Same = Kept-Replaced.

same(X, Y, Same) :-
    (   X == Y
    ->  Same = true
    ;   Same = false
    ).

test(snapshot_restores_memory_and_stream, [X1 == X2]) :-
    kb_with('tests/data/tiny.pl', KB),
    P = [alpha=0.2, gamma=0.9, epsilon=1.0, q_init=0.0, split_threshold=0.1,
         reward_positive=10.0, reward_negative= -1.0],
    relrl_engine:engine_configure(KB, etg, P, 3),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_keep(KB, s),
    relrl_engine:engine_step(KB, [see(dark)], 0, greedy, [], step(_, _, _, _, _, _, X1, _)),
    relrl_engine:engine_step(KB, [see(dark)], 0, greedy, [], _),
    relrl_engine:engine_resume(KB, s),
    relrl_memory:wm_elements(KB, [0-see(light)]),
    relrl_engine:engine_step(KB, [see(dark)], 0, greedy, [], step(_, _, _, _, _, _, X2, _)).

test(unknown_learner, [error(domain_error(learner(_), sarsa))]) :-
    kb_with('tests/data/tiny.pl', KB),
    relrl_engine:engine_configure(KB, sarsa, [], 0).

%   A policy is text (relrl's writer puts it on disk): the header as comments, then terms
%   that read back, the first naming the learner.
test(policy_text_reads_back_as_terms, [true((Name/Arity == relrl_policy/2, L == etg))]) :-
    kb_with('tests/data/tiny.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    relrl_engine:engine_step(KB, [see(light)], -1, learn, [], _),
    relrl_engine:engine_policy(KB, "a policy\nof two lines", Text),
    assertion(string(Text)),
    assertion(sub_string(Text, 0, _, _, "% a policy\n% of two lines\n")),
    setup_call_cleanup(open_string(Text, S), read_term(S, T, []), close(S)),
    functor(T, Name, Arity),
    arg(1, T, L).

:- end_tests(engine_step).

% ---------------------------------------------------------------------------------------
:- begin_tests(step_parts).

%   The state plan gives the code testing each feature gives (features_code/3), on random
%   memories over the Social Interactive Simulator's percepts (and some outside them).
sis_percept(P) :-
    member(P, [see(face), see(toy), see(environment), hear(attention), at(toy, left),
               at(toy, down), at(centre), at(left), at(right), pose(face, frontal),
               pose(face, left), pose(face, down), colour(toy, red), colour(toy, green),
               emitted(look(left)), smell(nothing), at(face), see(environment(x))]).

random_memory(Elements) :-
    findall(P, ( sis_percept(P), random(X), X < 0.3 ), Elements).

test(plan_code_is_features_code, [true(Pairs1 == Pairs2)]) :-
    kb_with('examples/domains/sis.pl', KB),
    relrl_state:state_features(KB, Features),
    relrl_state:state_plan(KB, Features, Plan),
    set_random(seed(5)),
    findall(C1-C2,
            ( between(1, 300, _),
              random_memory(Elements),
              relrl_memory:wm_insert(KB, Elements),
              relrl_state:features_code(KB, Features, C1),
              relrl_state:plan_code(KB, Plan, C2) ),
            Pairs),
    pairs_keys(Pairs, Pairs1),
    pairs_values(Pairs, Pairs2).

%   Facts whose goal only looks a ground percept up in memory are read off memory by the
%   plan's pass (memory facts); the others run as goals. The code is the same either way.
test(memory_facts_of_sis, [Names == [gaze_frontal, gaze_left, gaze_left_down, gaze_down,
                                      gaze_right_down, gaze_right, head_at, head_at,
                                      head_at, head_at, head_at, head_at, toy_at, toy_at,
                                      toy_at, toy_at, toy_at]]) :-
    kb_with('examples/domains/sis.pl', KB),
    findall(Name, ( relrl_declarations:kb_fact(KB, F),
                    relrl_state:memory_fact(KB, F, _, _),
                    functor(F, Name, _) ),
            Names).

test(memory_facts_and_goals,
     [true(Found =@= [plain-see(s)-any, young-hear(s)-now, seen-see(s)-any,
                      placed(s)-at(s, left)-any, placed(t)-at(t, left)-any,
                      near(_)-see(t)-any])]) :-
    kb_with('tests/data/memory_facts.pl', KB),
    findall(F-P-W, ( relrl_declarations:kb_fact(KB, F),
                     relrl_state:memory_fact(KB, F, P, W) ),
            Found).

memory_facts_percept(P) :-
    member(P, [see(s), see(t), hear(s), hear(t), at(s, left), at(t, left), at(s, right),
               a, b, pose(s, x)]).

test(memory_facts_code_is_features_code, [true(Pairs1 == Pairs2)]) :-
    kb_with('tests/data/memory_facts.pl', KB),
    relrl_state:state_features(KB, Features),
    relrl_state:state_plan(KB, Features, Plan),
    set_random(seed(6)),
    findall(C1-C2,
            ( between(1, 300, _),
              findall(P, ( memory_facts_percept(P), random(X), X < 0.3 ), Elements),
              relrl_memory:wm_insert(KB, Elements),
              relrl_state:features_code(KB, Features, C1),
              relrl_state:plan_code(KB, Plan, C2) ),
            Pairs),
    pairs_keys(Pairs, Pairs1),
    pairs_values(Pairs, Pairs2).

%   A memory fact redefined after the plan was made (by a file loaded into the knowledge
%   base through the gateway) is run as its new goal at the next step.
test(redefined_memory_fact_runs_its_new_goal, [Plain0-Plain1 == true-false]) :-
    kb_with('tests/data/memory_facts.pl', KB),
    relrl_state:state_features(KB, Features),
    relrl_state:state_plan(KB, Features, Plan),
    once(relrl_state:feature_code(KB, fact(plain), X)),
    relrl_memory:wm_insert(KB, [see(s)]),
    relrl_state:plan_code(KB, Plan, C0),
    tmp_file_stream(text, File, S),
    format(S, "plain :- percept(see(t)).~n", []),
    close(S),
    relrl_gateway:gw_run(relrl_gateway:gw_load(File, KB, _), true),  % as Python loads
    delete_file(File),
    relrl_state:plan_code(KB, Plan, C1),
    bit(C0, X, Plain0),
    bit(C1, X, Plain1).

%   A memory fact declared with a variable (fact(near(_))) is run as declared once it is a
%   goal again: its clause's bindings (near(left)) stay out of the plan.
test(open_memory_fact_runs_as_declared, [Near0-Near1 == true-true]) :-
    kb_with('tests/data/memory_facts.pl', KB),
    relrl_state:state_features(KB, Features),
    relrl_state:state_plan(KB, Features, Plan),
    once(relrl_state:feature_code(KB, fact(near(_)), X)),
    relrl_memory:wm_insert(KB, [see(t)]),
    relrl_state:plan_code(KB, Plan, C0),
    tmp_file_stream(text, File, S),
    format(S, "near(right) :- percept(see(t)).~n", []),
    close(S),
    relrl_gateway:gw_run(relrl_gateway:gw_load(File, KB, _), true),  % as Python loads
    delete_file(File),
    relrl_state:plan_code(KB, Plan, C1),
    bit(C0, X, Near0),
    bit(C1, X, Near1).

bit(Code, X, Set) :-
    (   Code /\ (1 << X) =\= 0
    ->  Set = true
    ;   Set = false
    ).

%   A memory fact traced (wrapped, as relrl shell's trace does) after the plan was made
%   runs as its goal again, so the trace sees it.
test(traced_memory_fact_runs_as_its_goal, [Calls == 1]) :-
    kb_with('tests/data/memory_facts.pl', KB),
    relrl_state:state_features(KB, Features),
    relrl_state:state_plan(KB, Features, Plan),
    relrl_memory:wm_insert(KB, [see(s)]),
    relrl_state:plan_code(KB, Plan, _),
    flag(relrl_test_calls, _, 0),
    wrap_predicate(KB:plain, relrl_test, W, ( flag(relrl_test_calls, N, N + 1), W )),
    relrl_state:state_touch,
    relrl_state:plan_code(KB, Plan, _),
    unwrap_predicate(KB:plain, relrl_test),
    flag(relrl_test_calls, Calls, 0).

%   A stimulus declared twice owns both bits; the reinforcement check reads age 0 only.
test(scan_masks_and_reinforcer, [true(R1-R2-M == true-false-5)]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 1),
    relrl_memory:wm_insert(KB, [hear(food), at(light, left)]),
    relrl_state:state_plan(KB, [stimulus(light), stimulus(dark), stimulus(light)], [food],
                           Plan),
    relrl_state:plan_code(KB, Plan, M, R1),
    relrl_memory:wm_insert(KB, []),
    relrl_state:plan_code(KB, Plan, _, R2).

test(rules_mask_or_of_holding_goals, [M == 0b1101]) :-
    relrl_gateway:gw_new_kb(KB),
    assertz(KB:(yes)), assertz(KB:(no :- fail)),
    relrl_rules:rules_mask(KB, [yes-4, no-2, yes-8], 1, M).

%   One catch guards the loop; an error still names the goal that raised it.
test(rules_mask_error_names_its_goal,
     [throws(relrl_rule_error(boom(2), _, error(instantiation_error, _)))]) :-
    relrl_gateway:gw_new_kb(KB),
    assertz(KB:(ok)),
    assertz(KB:(boom(_) :- atom_length(_, _))),
    relrl_rules:rules_mask(KB, [ok-1, boom(2)-2, ok-4], 0, _).

test(rules_mask_passes_a_named_error_on,
     [throws(relrl_rule_error(inner, here, oops))]) :-
    relrl_gateway:gw_new_kb(KB),
    assertz(KB:(outer :- throw(relrl_rule_error(inner, here, oops)))),
    relrl_rules:rules_mask(KB, [outer-1], 0, _).

%   A compiled program gives rules_mask/4's masks and errors.
test(program_mask_as_rules_mask, [true(M1-M2 == 0b1101-0b1101)]) :-
    relrl_gateway:gw_new_kb(KB),
    assertz(KB:(yes)), assertz(KB:(no :- fail)),
    GoalBits = [yes-4, no-2, yes-8],
    relrl_rules:rules_mask(KB, GoalBits, 1, M1),
    relrl_rules:rules_program(KB, GoalBits, P),
    relrl_rules:program_mask(P, 1, M2).

test(program_error_names_its_goal,
     [throws(relrl_rule_error(boom(2), _, error(instantiation_error, _)))]) :-
    relrl_gateway:gw_new_kb(KB),
    assertz(KB:(ok)),
    assertz(KB:(boom(_) :- atom_length(_, _))),
    relrl_rules:rules_program(KB, [ok-1, boom(2)-2, ok-4], P),
    relrl_rules:program_mask(P, 0, _).

test(program_of_nothing, [M == 7]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_rules:rules_program(KB, [], P),
    relrl_rules:program_mask(P, 7, M).

%   A run's compiled rules and tables are replaced when the engine is configured again,
%   and go when it is forgotten.
test(compiled_rules_do_not_pile_up, [true((P1 > 0, N1 > P1, N2 == N1, N3 == 0))]) :-
    kb_with('examples/domains/sis.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    programs(KB, P1),
    compiled(KB, N1),
    relrl_engine:engine_configure(KB, etg, P, 1),
    compiled(KB, N2),
    relrl_engine:engine_forget(KB),
    compiled(KB, N3).

programs(KB, N) :-
    (   current_predicate(KB:'$relrl_program'/4)
    ->  aggregate_all(count, clause(KB:'$relrl_program'(_, _, _, _), _), N)
    ;   N = 0
    ).

compiled(KB, N) :-
    programs(KB, NP),
    aggregate_all(count, ( relrl_state:plan_kb_(Id, KB),
                           (   relrl_state:plan_stimulus_(Id, _, _)
                           ;   relrl_state:plan_fact_(Id, _, _, _)
                           ;   relrl_state:plan_memory_fact_(Id, _, _, _)
                           ) ), NS),
    N is NP + NS.

%   Memory is linked into its global variable (no second copy): what an insertion keeps
%   must survive backtracking and garbage collection, even when the percepts were bound
%   under a choice point (Z below is bound and unbound again by backtracking).
test(memory_survives_backtracking,
     [true(Pairs == [0-t(y), 1-t(x), 2-see(a)])]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 5),
    relrl_memory:wm_insert(KB, [see(a)]),
    relrl_memory:wm_insert(KB, [see(a)]),
    relrl_memory:wm_insert(KB, [see(a), see(a)]),
    (   true
    ;   relrl_memory:wm_insert(KB, [see(a)])
    ),
    !,
    T = t(Z),
    (   member(V, [x, y]),
        Z = V,
        relrl_memory:wm_insert(KB, [T]),
        fail
    ;   true
    ),
    var(Z),
    garbage_collect,
    findall(N, ( between(1, 2000, I), N = f(I) ), _),
    garbage_collect,
    relrl_memory:wm_elements(KB, Pairs0),
    msort(Pairs0, Pairs1),
    Pairs1 = Pairs.

test(memory_state_round_trip, [true(Now-All == [see(b)]-[0-see(b), 1-see(a)])]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 1),
    relrl_memory:wm_insert(KB, [see(a)]),
    relrl_memory:wm_insert(KB, [see(b)]),
    relrl_memory:wm_state(KB, State),
    relrl_memory:wm_clear(KB),
    relrl_memory:wm_set_state(KB, State),
    findall(E, relrl_memory:wm_now(KB, E), Now),
    relrl_memory:wm_elements(KB, All).

test(ground_lookups_ages, [true(L == [yes, no, yes, no])]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 1),
    relrl_memory:wm_insert(KB, [see(a)]),
    relrl_memory:wm_insert(KB, [see(b), see(b)]),
    findall(X, ( member(G, [wm_now(KB, see(b)), wm_now(KB, see(a)),
                            wm_has(KB, see(a)), wm_has(KB, see(c))]),
                 ( relrl_memory:G -> X = yes ; X = no ) ), L).

%   relrl declares forbidden/1 in every knowledge base: without clauses there are no
%   constraints; a dynamic forbidden/1 may get clauses during a run.
test(constraints_detected_by_clauses, [true(A-B == false-true)]) :-
    kb_with('tests/data/tiny.pl', KB1),
    relrl_engine:engine_configure(KB1, etg, [], 0),
    relrl_engine:engine_config(KB1, constraints, A),
    relrl_gateway:gw_new_kb(KB2),
    KB2:dynamic(forbidden/1),
    assertz(KB2:response(r)),
    relrl_engine:engine_configure(KB2, external, [], 0),
    relrl_engine:engine_config(KB2, constraints, B).

test(step_leaves_no_choice_point, [Det == true]) :-
    kb_with('examples/domains/sis.pl', KB),
    etg_params(P),
    relrl_engine:engine_configure(KB, etg, P, 0),
    call_cleanup(relrl_engine:engine_step(KB, [see(face), pose(face, frontal), at(centre)],
                                          -1, learn, [], _),
                 Det = true).

%   ETG's max over the next leaf gives what the plain definition gives (max/2 over every
%   entry for N of an allowed action; q_init when one is untried), entries in any order,
%   with integer and float values, ties, and every subset of allowed actions.
plain_max_q(Entries, N, Allowed, Qinit, Max) :-
    findall(Q, ( member(e(A, Q, N1), Entries), N1 == N,
                 ( Allowed == [] -> true ; memberchk(A, Allowed) ) ), Qs),
    length(Qs, K),
    (   K =:= 0
    ->  Max = Qinit
    ;   Qs = [Q1|Qs1],
        foldl(max_of, Qs1, Q1, Max1),
        (   Allowed \== [], length(Allowed, L), K < L
        ->  Max is max(Max1, Qinit)
        ;   Max = Max1
        )
    ).

max_of(Q, M0, M) :-
    M is max(M0, Q).

put_entry(E, L0, L) :-
    relrl_qtree:qtree_put_entry(L0, E, L).

random_entries(Es) :-
    findall(e(A, Q, N),
            ( member(A, [a, b, c, d]), member(N, [n, m]), random(X), X < 0.6,
              random_member(Q, [0, 1, 2.5, 2.5, 30, 30.0, -1.0, 31.25, 29.5, 40]) ),
            Es0),
    random_permutation(Es0, Es).

test(etg_max_q_is_plain_max, [true(Bad == [])]) :-
    set_random(seed(11)),
    findall(Es-N-Allowed-Got-Want,
            ( between(1, 2000, _),
              random_entries(Es),
              random_member(N, [n, m]),
              random_member(Allowed, [[], [a], [a, b], [b, c, d], [a, b, c, d],
                                      [a, b, c, d, e]]),
              random_member(Qinit, [30, 30.0, 0]),
              relrl_etg:max_q(Es, N, Allowed, Qinit, Got),
              plain_max_q(Es, N, Allowed, Qinit, Want),
              Got \== Want ),
            Bad).

%   Sorted leaves too (as the tree keeps them): the first allowed entry is the max.
test(etg_max_q_sorted_leaves, [true(Bad == [])]) :-
    set_random(seed(12)),
    findall(Es-Got-Want,
            ( between(1, 1000, _),
              random_entries(Es0),
              foldl(put_entry, Es0, [], Es),
              random_member(Allowed, [[], [a, b], [a, b, c, d]]),
              relrl_etg:max_q(Es, n, Allowed, 30, Got),
              plain_max_q(Es, n, Allowed, 30, Want),
              Got \== Want ),
            Bad).

%   A ground leaf is linked into the tree, not copied: it survives backtracking to before
%   it was made and garbage collection.
test(qtree_linked_leaf_survives, [true(Entries == [e(a, 2.5, n), e(b, 1.0, n)])]) :-
    relrl_qtree:qtree_new(tlink, [t0]),
    relrl_qtree:qtree(tlink, T),
    (   X is 1.5 + 1.0, Y is 0.5 * 2,
        relrl_qtree:qtree_set_leaf(T, 0, 1, [e(a, X, n), e(b, Y, n)]),
        fail
    ;   true
    ),
    findall(Z, ( between(1, 20000, I), Z = f(I, I) ), _),
    garbage_collect,
    relrl_qtree:qtree_leaf(T, 0, _, Entries).

:- end_tests(step_parts).
