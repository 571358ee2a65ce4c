:- module(relrl_ptg,
          [ ptg_init/2,           % +KB, +Params
            ptg_p/5,              % +KB, +Facts, +Action, +Necessity, -P
            ptg_choose/6,         % +KB, +Facts, +Necessity, +Allowed, +Mode, -Action
            ptg_update/2,         % +KB, +Transition
            ptg_size/2,           % +KB, -Size
            ptg_explain/4,        % +KB, +Facts, +Necessity, -Explanation
            ptg_save/2,           % +KB, +Stream
            ptg_restore/2,        % +KB, +Terms
            ptg_text/2,           % +KB, -Text
            ptg_key/2             % +KB, -Key
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(library(random)).
:- use_module(tg).
:- use_module(learner_hooks).
:- use_module(tg_tree, [tg_data/2, tg_get_tree/2, tg_forget/1, tg_leaf/3, tg_leaves_/3,
                         tg_sort_/5]).
:- use_module(kbstate, [kb_nest/3, kb_get/3, kb_forget/1]).
:- use_module(world, [world_action_list/2]).
:- use_module(tg_classes, [tg_class_members/2, tg_leaf_search/5, tg_leaf_classes/4,
                            tg_leaf_reached/3]).

/** <module> ptg: P-learning beside TG's Q-tree

Relational reinforcement learning's P-learning (Džeroski, De Raedt & Driessens, *Relational
Reinforcement Learning*, Machine Learning 43, 2001): beside the Q-function, learn the
function P(s, a) = 1 when a is optimal in s and 0 when not, as a first-order tree, and act
by it. The optimal *policy* often depends on the objects far less than the values do: in
blocks world Q(s, a) counts the moves still needed, which depends on the towers' heights and
so on the number of blocks, while "move a clear block that stands on another onto the floor"
is optimal for unstacking in a world of any size. A tree that predicts Q splits on heights
seen in small worlds; a tree that predicts optimality need not.

ptg is tg (tg.pl) with a second tree:

  - **the Q-tree** is tg's own, under the knowledge base's key, learned exactly as tg learns
    it (every transition, its Q-target, its splits), and it chooses while learning (tg's
    Boltzmann exploration over classes of responses);
  - **the P-tree** is a tree of the same code (tg_init/3 under the key of ptg_key/2): the
    same language bias and candidate tests, examples (state, action, 0/1). After each
    transition into a state s' that is not terminal, the Q-tree labels the actions legal
    in s': an action is optimal when the Q of its leaf is within `p_margin` of the best.
    `p_pairs` times, one optimal action and one that is not (when there is one), each drawn
    uniformly among the actions of its label, are inserted with targets 1 and 0: the P-tree
    learns to tell them apart with as many examples of each, and a learning step inserts a
    fixed number of P-examples whatever the number of actions (RRL labels every action of
    every state it met). Uniform over actions, not over the Q-tree's leaves: a label drawn
    by leaf would over-weigh the leaves of the regions the Q-tree splits finely;
  - **greedy choices** (evaluation, acting on a learned policy) are by P, ties by Q, further
    ties at random: a leaf's P is the share of its examples the Q-tree found optimal, so the
    class most often optimal in states like this one wins.

The P-tree's leaves move at rate max(1/n, `p_alpha`) (its labels change as the Q-tree
learns); it splits like the Q-tree (`significance`, `min_examples`, `half_life`,
`keep_examples`). Its other tg parameters are unused: it never explores.

Params: tg's (tg_init/2) and p_margin, p_alpha, p_pairs.
*/

%!  ptg_key(+KB, -Key) is det.
%
%   Key is the key the P-tree of KB is kept under (tg_init/3): the name of its compiled
%   clauses and of its record, which is kept inside KB's (kbstate.pl's kb_nest/3, with
%   ptg's own options pp(Margin, Pairs)).

ptg_key(KB, Key) :-
    atom_concat('$ptg:', KB, Key).

%!  ptg_init(+KB, +Params:list) is det.
%
%   Start KB's ptg learner afresh: tg's Q-tree (tg_init/2 with tg's parameters) and a P-tree
%   of one leaf.

ptg_init(KB, Params) :-
    must_be(atom, KB),
    must_be(list, Params),
    maplist(param(Params), [p_margin, p_alpha, p_pairs], [Margin, PAlpha, Pairs0]),
    (   Margin >= 0
    ->  true
    ;   domain_error(nonneg, Margin)
    ),
    Pairs is max(1, round(Pairs0)),
    exclude(p_param, Params, QParams),
    tg_init(KB, QParams),
    selectchk(alpha=_, QParams, alpha=PAlpha, PParams),
    ptg_key(KB, PK),
    kb_nest(KB, PK, pp(Margin, Pairs)),
    tg_init(PK, KB, PParams).

p_param(Name=_) :-
    memberchk(Name, [p_margin, p_alpha, p_pairs]).

param(Params, Name, Value) :-
    (   memberchk(Name=V, Params)
    ->  must_be(number, V),
        Value = V
    ;   existence_error(ptg_parameter, Name)
    ).

ptg_params(KB, P) :-
    (   kb_get(KB, inner, inner(_, P0, _))
    ->  P = P0
    ;   existence_error(ptg_learner, KB)
    ).

%!  ptg_p(+KB, +Facts, +Action, +Necessity, -P) is det.
%
%   P is the P-tree's estimate that Action is optimal in the state Facts under Necessity.

ptg_p(KB, Facts, A, N, P) :-
    ptg_key(KB, PK),
    tg_q(PK, Facts, A, N, P).

%!  ptg_choose(+KB, +Facts, +Necessity, +Allowed, +Mode, -Action) is det.
%
%   With Mode greedy, Action is a legal action (Allowed: a world's actions(A, Goal) term,
%   world.pl) with the largest P, ties broken by the largest Q, then at random: the P-tree's
%   leaves are searched from the largest P down until a legal action reaches one
%   (tg_class_values/7, scope best), and the members of those of that P are sorted down
%   the Q-tree. With Mode learn or explore, tg's choice (tg_choose/6: Boltzmann over the
%   Q-tree's classes, with its bonuses while learning).

ptg_choose(KB, Facts, N, Allowed, Mode, Action) :-
    (   Mode == greedy
    ->  ptg_key(KB, PK),
        tg_class_values(PK, Facts, N, Allowed, best, Classes, _),
        findall(Q-A, ( member(Class, Classes),
                       tg_class_members(Class, Members),
                       member(A, Members),
                       tg_q(KB, Facts, A, N, Q) ),
                Scored),
        pairs_keys(Scored, Qs),
        max_list(Qs, BestQ),
        findall(A, ( member(Q-A, Scored), Q =:= BestQ ), Ties),
        random_member(Action, Ties)
    ;   tg_choose(KB, Facts, N, Allowed, Mode, Action)
    ).

%!  ptg_update(+KB, +Transition) is det.
%
%   Learn from a transition as tg does (tg_update/2); then, unless its next state is
%   terminal, label the actions legal there by the Q-tree and insert p_pairs pairs of
%   P-examples: an optimal action (its leaf's Q within p_margin of the best), target 1, and
%   one that is not (when there is one), target 0, each drawn uniformly among the legal
%   actions of its label. The best Q is found by searching the Q-tree's leaves from the
%   largest Q down (tg_classes.pl); the optimal actions are the members of the optimal
%   leaves a legal action reaches; the other is found by sorting the legal actions, in a
%   random order, until one reaches a leaf that is not optimal.

ptg_update(KB, T) :-
    tg_update(KB, T),
    T = transition(_, _, _, _, _, _, S1, N1, Actions),
    (   S1 == terminal
    ->  true
    ;   ptg_params(KB, pp(Margin, Pairs)),
        tg_leaf_search(KB, S1, N1, Actions, Search),
        tg_leaf_groups(KB, best, Groups),
        tg_leaf_classes(Search, Groups, _, [BestId|_]),
        tg_leaf(KB, BestId, BestLeaf),
        arg(1, BestLeaf, Best),
        Cut is Best - Margin,
        tg_leaves_(KB, Ids, _),
        partition(optimal_leaf(KB, Cut), Ids, Optimal, Other),
        ptg_key(KB, PK),
        forall(between(1, Pairs, _),
               label_pair(KB, PK, Search, S1, N1, Actions, Optimal, Other))
    ).

optimal_leaf(KB, Cut, Id) :-
    tg_leaf(KB, Id, L),
    arg(1, L, Q),
    Q >= Cut.

%   An optimal action, uniformly among the legal actions of the optimal leaves (their
%   members), and one that is not, uniformly among the other legal actions (the legal
%   actions in a random order, each sorted until one reaches a leaf that is not optimal).
label_pair(KB, PK, Search, S, N, Actions, Optimal, Other) :-
    findall(A, ( member(Id, Optimal),
                 tg_leaf_reached(Search, Id, C),
                 tg_class_members(C, Ms),
                 member(A, Ms) ), Good),
    random_member(G, Good),
    tg_insert(PK, S, G, N, 1),
    world_action_list(Actions, Legal),
    random_permutation(Legal, Order),
    (   member(B, Order),
        tg_sort_(KB, S, B, N, Leaf),
        memberchk(Leaf, Other)
    ->  tg_insert(PK, S, B, N, 0)
    ;   true
    ).

%!  ptg_size(+KB, -Size) is det.
%
%   Size is size(Positions, Details): the positions of both trees (tg_size/2's count for
%   each), Details the Q-tree's (tg_size/2) and the P-tree's with names prefixed p_.

ptg_size(KB, size(Positions, Details)) :-
    tg_size(KB, size(QPos, QDetails)),
    ptg_key(KB, PK),
    tg_size(PK, size(PPos, PDetails0)),
    Positions is QPos + PPos,
    maplist(prefixed, PDetails0, PDetails),
    append([QDetails, [p_positions=PPos], PDetails], Details).

prefixed(Name=V, PName=V) :-
    atom_concat(p_, Name, PName).

%!  ptg_explain(+KB, +Facts, +Necessity, -Explanation) is det.
%
%   Explanation is ptg(Ranked): for every response, choice(Action, P, Q, Leaf, Path) by
%   decreasing P, then Q; Leaf and Path are the P-tree's (as tg_explain/4 gives them).

ptg_explain(KB, Facts, N, ptg(Ranked)) :-
    ptg_key(KB, PK),
    tg_explain(PK, Facts, N, tg(ByP)),
    findall(k(NegP, NegQ)-choice(A, P, Q, Leaf, Path),
            ( member(choice(A, P, Leaf, Path), ByP),
              tg_q(KB, Facts, A, N, Q),
              NegP is -P, NegQ is -Q ),
            Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Ranked).

%!  ptg_save(+KB, +Stream) is det.
%
%   Write both trees: tg's Q-tree (tg_tree/1, q/3 rules) and the P-tree (ptg_tree/1, p/3
%   rules: the policy).

ptg_save(KB, S) :-
    tg_save(KB, S),
    nl(S),
    ptg_key(KB, PK),
    tg_face(p, Face),
    tg_save(PK, Face, S).

%!  ptg_restore(+KB, +Terms:list) is det.
%
%   Rebuild both trees from a policy's terms (tg_restore/3 for each).

ptg_restore(KB, Terms) :-
    tg_restore(KB, Terms),
    ptg_key(KB, PK),
    tg_face(p, Face),
    tg_restore(PK, Face, Terms).

%!  ptg_text(+KB, -Text:string) is det.
%
%   Both trees drawn as text, the P-tree (the policy) first.

ptg_text(KB, Text) :-
    ptg_key(KB, PK),
    tg_face(p, Face),
    tg_text(PK, Face, PText),
    tg_text(KB, QText),
    format(string(Text), "P-tree (acts when greedy):~n~wQ-tree (explores, labels):~n~w",
           [PText, QText]).

policy_term(Term) :-
    (   tg_policy_term(Term)
    ->  true
    ;   nonvar(Term),
        (   Term = ptg_tree(_)
        ->  true
        ;   Term = (p(_, _, _) :- _)
        ->  true
        ;   Term = p(_, _, _)
        )
    ).

% ---- the engine's hooks (see engine.pl) ----------------------------------------------------

relrl_engine:learner(ptg).

relrl_engine:learner_property(ptg, Cap) :-
    member(Cap, [view(relational), state, size, text, graph, policy, policy_info]).

%   Parameters (learners.pl): tg's (the Q-tree's, and the P-tree's splits), then p_margin (a
%   response is labelled optimal when its Q is within this of the best response's), p_alpha
%   (a P-leaf's estimate moves at rate max(1/n, p_alpha)) and p_pairs (pairs of P-examples
%   inserted per learning step). A learner of worlds, with tg's defaults there.
relrl_engine:learner_parameter(ptg, Param, Default, Kind) :-
    relrl_engine:learner_parameter(tg, Param, Default, Kind).
relrl_engine:learner_parameter(ptg, p_margin, 0.0, nonneg).
relrl_engine:learner_parameter(ptg, p_alpha, 0.02, unit).
relrl_engine:learner_parameter(ptg, p_pairs, 1.0, whole(1)).
relrl_engine:learner_serves(ptg, worlds, Overrides) :-
    relrl_engine:learner_serves(tg, worlds, Overrides).

%   The Q-tree is tg's under KB; the P-tree is a tree of its own, under its own key: its
%   compiled clauses go here, its record (kept inside KB's, with ptg's options) with
%   KB's learner (engine.pl's forget_learner/1).
relrl_engine:learner_forget(ptg, KB) :-
    tg_forget(KB),
    ptg_key(KB, PK),
    tg_forget(PK),
    kb_forget(PK).

:- learner_hooks(ptg, [init-ptg_init, choose-ptg_choose, update-ptg_update,
                      explain-ptg_explain, size-ptg_size, save-ptg_save,
                      policy_info-tg_policy_info, policy_term-policy_term,
                      restore-ptg_restore, text-ptg_text]).

relrl_engine:learner_state(ptg, KB, _Code, Facts) :-
    tg_state(KB, Facts).

relrl_engine:learner_graph(ptg, KB, Graph) :-
    ptg_key(KB, PK),
    tg_face(p, Face),
    tg_graph(PK, Face, Graph).
