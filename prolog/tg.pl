:- module(relrl_tg,
          [ tg_init/2,            % +KB, +Params
            tg_init/3,            % +Key, +KB, +Params
            tg_state/2,           % +KB, -Facts
            tg_update/2,          % +KB, +Transition
            tg_insert/5,          % +KB, +Facts, +Action, +Necessity, +Target
            tg_size/2,            % +KB, -Size
            tg_candidates/3,      % +KB, ?LeafId, -Texts
            tg_policy_info/2      % +KB, -Info
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(declarations).
:- use_module(engine).
:- use_module(learner_hooks).
:- use_module(tg_bias).
:- use_module(tg_stats).
:- use_module(tg_tree).
:- use_module(tg_classes).
:- use_module(tg_choice, [tg_look_up/9, tg_leaf_q/3]).
:- use_module(kbstate, [kb_get/3, kb_set/3]).
:- reexport(tg_knowledge).
:- reexport(tg_choice, [ tg_q/5,         % +KB, +Facts, +Action, +Necessity, -Q
                         tg_choose/6,    % +KB, +Facts, +Necessity, +Allowed, +Mode, -Action
                         tg_class_values/7, % +KB, +Facts, +N, +Allowed, +Scope, -Cs, -Qs
                         tg_leaf_groups/3, % +KB, +Scope, -Groups
                         tg_bonus/5      % +KB, +Facts, +Action, +Necessity, -Bonus
                       ]).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> TG: a first-order incremental regression-tree Q-learner

In the line of RRL-TG (Driessens, Ramon & Blockeel, ECML 2001). The Q-function is one
first-order regression tree over examples (State, Action, Necessity, Q-target):

  - State is the relational view of the domain (a sorted list of ground facts, see
    engine:engine_relational_state/2), Action the response the value is for, Necessity the active
    necessity;
  - an internal node holds a conjunction of literals from the language bias (rmode/1); it
    succeeds on an example when the conjunction of every test on the yes-branches from the
    root down to it (the node's query) has a solution in the example — TILDE's semantics. A
    variable introduced in a node is used only in its yes-subtree;
  - a leaf holds the Q estimate and, for each candidate test the refinement operator gives
    for it (tg_bias:refinements/4), the count, sum and sum of squares of the TD errors
    (Q-target minus the leaf's Q just before the example moved it) of the examples on
    which the candidate succeeds. With the leaf's own three numbers, they give the F-test
    of every candidate split (tg_stats.pl). When the best candidate is significant at
    level `significance` after at least `min_examples` examples, the leaf becomes a test
    node; its two children start from their partitions' statistics (Q is the leaf's Q plus
    the partition's mean TD error) and from fresh candidates.

The statistics are kept over TD errors rather than the Q-targets themselves because the
targets drift while the Q-function is learned (from q_init towards the task's values): the
drift the leaf's own Q follows is not in the TD errors, so a split answers "is the leaf's
estimate wrong on one side of this test?" rather than "were the targets on that side from
another time?".

Q(s, a) comes from sorting (s, a) down the tree. Choices and Q-targets are over classes of
responses that no test of the bias tells apart in the state (tg_classes.pl), each scored by
one representative: their number does not grow with the world. Each step one example with
Q-target r + gamma * max_a' Q(s', a') is inserted; no table of examples is kept, only each
leaf's last keep_examples examples, so that the children of a split start with statistics.

The learner's state and the compiled tree are kept by tg_tree.pl; values and choices are
tg_choice.pl's, explanations, drawings, rules and policy files tg_knowledge.pl's (both
re-exported here).

**Speed.** The hot path asserts nothing. The tree is compiled into one clause,
tg_sort_/5, and each leaf's candidate tests into one clause, tg_cands_/6, whenever the tree
changes (a split): sorting an example and testing every candidate are then compiled
Prolog over the example's own fact list (never a query of working memory). The numbers
live in a global term per knowledge base and are updated in place (nb_setarg/3).

Params (Name=Value): alpha (0: Q is the mean of the leaf's Q-targets; otherwise the rate
is max(1/n, alpha)), gamma, temperature (Boltzmann exploration; 0: epsilon-greedy),
epsilon, q_init (Q of the first, empty leaf), significance, min_examples, stale_bonus,
half_life, novelty_bonus and novelty_confidence (see tg_choose/6), keep_examples, action_gap
(advantage learning, tg_update/2), return_lambda (optional, 0 when not given: the episode's
return in the Q-target, tg_update/2); the engine's reward_positive and reward_negative.
*/

% ---- starting ------------------------------------------------------------------------------

%!  tg_init(+KB, +Params:list) is det.
%
%   Start KB's TG learner afresh: one leaf, Q = q_init, candidates from the domain's bias.

tg_init(KB, Params) :-
    tg_init(KB, KB, Params).

%!  tg_init(+Key, +KB, +Params:list) is det.
%
%   Start a TG tree afresh under Key, with KB's language bias and responses: tg_init/2 is
%   tg_init(KB, KB, Params). Every predicate of this module that takes a KB then works on
%   the tree of Key; a learner that keeps a second tree beside KB's (ptg.pl's P-tree) gives
%   it a key of its own.

tg_init(Key, KB, Params) :-
    must_be(atom, Key),
    must_be(atom, KB),
    must_be(list, Params),
    maplist(param(Params), [alpha, gamma, epsilon, temperature, q_init, significance,
                            min_examples, stale_bonus, half_life, novelty_bonus,
                            novelty_confidence, keep_examples, action_gap],
            [Alpha, Gamma, Epsilon, Tau, Qinit, Level, MinEx0, Kappa, Half0, Beta, Conf,
             Keep0, Gap]),
    Keep is max(0, round(Keep0)),
    MinEx is max(2, round(MinEx0)),
    tg_bias(KB, Bias),
    findall(R, kb_response(KB, R), Responses),
    tg_response_index(Bias, Responses, Index),
    refinements(Bias, [], [], Cands),
    Root = leaf(1, [], [], Cands),
    length(Cands, K),
    tg_new_stats(Qinit, 0, K, 0, Keep, L),
    tg_empty_leaves(16, Leaves0),
    setarg(1, Leaves0, L),
    Half is max(0, round(Half0)),
    tg_put_data(Key, tg(p(Alpha, Gamma, Epsilon, Tau, Level, MinEx, Kappa, Half,
                          novelty(Beta, Conf), Keep, Gap), Leaves0, none, 0, 0, Index)),
    tg_put_tree(Key, tree(Root, 2, Bias, Responses)),
    (   memberchk(return_lambda=Lambda, Params)     % (optional: 0 when not given)
    ->  must_be(number, Lambda)
    ;   Lambda = 0
    ),
    kb_set(Key, returns, ret(Lambda, none)),
    tg_forget_leaves(Key),
    tg_compile_leaf(Key, Root),
    tg_compile_tree(Key, Root).

param(Params, Name, Value) :-
    (   memberchk(Name=V, Params)
    ->  must_be(number, V),
        Value = V
    ;   existence_error(tg_parameter, Name)
    ).

%!  tg_state(+KB, -Facts:list) is det.
%
%   The relational view of KB now (sorted ground facts; engine_relational_state/2).

tg_state(KB, Facts) :-
    engine_relational_state(KB, Facts).


%!  tg_update(+KB, +Transition) is det.
%
%   Learn from transition(S0, A0, N0, Allowed0, Reward, Reinforced, S1, N1, Allowed1):
%   insert the example (S0, A0, N0) with Q-target Reward + gamma * max Q(S1, a, N1) over the
%   responses Allowed1 (over every response when none is allowed); S1 = terminal (the
%   episode ended in a world's goal): Q-target Reward alone. The max is taken over one
%   representative of each class of responses (tg_classes.pl): the members of a class have
%   the same Q. With action_gap G > 0 the target is lowered by G * (V(S0) - Q(S0, A0)),
%   V(S0) the largest Q of the responses Allowed0 (advantage learning, docs/tg.md).
%   With return_lambda L > 0 and the update before this one from S1 (a world's episode is
%   learned last first), max Q(S1) in the target is (1 - L) * max Q(S1) + L * G1, G1 that
%   update's target before its gap: the lambda-return of the steps the episode took (Peng
%   and Williams' Q(lambda), its returns computed backwards over the episode).

tg_update(KB, transition(S0, A0, N0, Allowed0, Reward, _, S1, N1, Allowed1)) :-
    tg_data(KB, D),
    D = tg(p(_, Gamma, _, _, _, _, _, _, _, _, Gap), Leaves, Cache0, Version, _, _),
    (   Cache0 = last(F0, M0, _, _, _, Version, chose(B0, Leaf0, Hits0)), F0 == S0,
        M0 == N0, B0 == A0
    ->  Known = sorted(Leaf0, Hits0)            % the choice sorted this example already
    ;   Known = none
    ),
    (   Gap > 0                                 % (S0's look-up, before S1's replaces it)
    ->  tg_look_up(KB, D, S0, N0, Allowed0, best, _, _, Ids0),
        max_q(Leaves, Ids0, V0),
        Gapped = gap(Gap, V0)
    ;   Gapped = none
    ),
    kb_get(KB, returns, Returns),
    (   Returns = ret(Lambda, Last)
    ->  true
    ;   Lambda = 0, Last = none
    ),
    (   S1 == terminal                          % the episode ended (a world's goal)
    ->  Target = Reward
    ;   tg_look_up(KB, D, S1, N1, Allowed1, best, Next, Classes, Ids),
        max_q(Leaves, Ids, Max),
        (   Lambda > 0,                         % the return from S1 this episode took
            Last = seen(S1b, N1b, G1), S1b == S1, N1b == N1
        ->  Target is Reward + Gamma * ((1 - Lambda) * Max + Lambda * G1)
        ;   Target is Reward + Gamma * Max
        ),
        (   Next = actions(_, _)                % a world's: only the best classes were
        ->  nb_setarg(3, D, none)               % found, not what a choice needs
        ;   nb_setarg(3, D, last(S1, N1, Next, Classes, Ids, Version, none))
        )
    ),
    (   Lambda > 0
    ->  kb_set(KB, returns, ret(Lambda, seen(S0, N0, Target)))
    ;   true
    ),
    insert(KB, D, S0, A0, N0, Known, Target, Gapped).

max_q(Leaves, Ids, Max) :-
    maplist(tg_leaf_q(Leaves), Ids, Qs),
    max_list(Qs, Max).

%!  tg_insert(+KB, +Facts, +Action, +Necessity, +Target:number) is det.
%
%   Insert one example: sort it to its leaf, move the leaf's Q towards Target, count the TD
%   error Target - Q (Q before the move) in the leaf's statistics and in those of every
%   candidate that succeeds on the example, and split the leaf when its best candidate is
%   significant.

tg_insert(KB, Facts, A, N, Target) :-
    tg_data(KB, D),
    insert(KB, D, Facts, A, N, none, Target, none).

%   Known is sorted(Leaf, Hits) when the choice of this example's action found its leaf and
%   candidate hits (note_choice/5), else none. Gapped is gap(G, V) (advantage learning: the
%   target lowered by G times V, the state's largest Q, less the leaf's Q) or none.
insert(KB, D, Facts, A, N, Known, Target0, Gapped) :-
    D = tg(p(Alpha, _, _, _, Level, MinEx, _, Half, _, _, _), Leaves, _, _, Clock0, _),
    Clock is Clock0 + 1,
    nb_setarg(5, D, Clock),
    (   Known = sorted(Leaf, Hits)
    ->  true
    ;   tg_sort_(KB, Facts, A, N, Leaf),
        tg_cands_(KB, Leaf, Facts, A, N, Hits)
    ),
    arg(Leaf, Leaves, L),
    L = l(Q0, N0, _, _, _, C, _, _, Ring),
    (   Gapped = gap(Gap, V)                       % (an action emitted outside the
    ->  Target is Target0 - Gap * max(0, V - Q0)   % allowed ones: no gap)
    ;   Target = Target0
    ),
    N1 is N0 + 1,
    Q is Q0 + max(1 / N1, Alpha) * (Target - Q0),
    nb_setarg(1, L, Q), nb_setarg(2, L, N1), nb_setarg(7, L, Clock),
    weight(L, Half, Clock, W),                      % (may rescale the sums)
    E is Target - Q0,                               % the TD error (module doc)
    arg(3, L, M0), arg(4, L, S0), arg(5, L, SS0),
    M is M0 + W,
    S is S0 + W * E,
    SS is SS0 + W * E * E,
    nb_setarg(3, L, M), nb_setarg(4, L, S), nb_setarg(5, L, SS),
    count_hits(Hits, C, W, E),
    keep_example(Ring, ex(Facts, A, N, E, Clock)),
    (   N1 /\ 3 =:= 0,                              % every fourth example
        MinW is MinEx * W,                          % min_examples in stored units
        M >= 2 * MinW,
        best_candidate(C, M, S, MinW, I-s(M1, S1, SS1)),
        F is 1 / W,                                 % stored sums -> today's weights
        Mt is M * F, St is S * F, SSt is SS * F,
        M1t is M1 * F, S1t is S1 * F, SS1t is SS1 * F,
        split_f(s(Mt, St, SSt), s(M1t, S1t, SS1t), FStat, Dof),
        functor(C, _, Arity),
        Corrected is Level * 3 / Arity,             % Bonferroni: level / candidates
        f_significant(FStat, Dof, Corrected)
    ->  M2t is Mt - M1t,
        DYes is S1 / M1, DNo is (S - S1) / (M - M1),  % the sides' mean TD errors
        QYes is Q + DYes, QNo is Q + DNo,
        split(KB, D, Leaf, I, s(M1t, QYes, DYes), s(M2t, QNo, DNo))
    ;   true
    ).

%   Forgetting (half_life H > 0): an example counts 2^(-k / H) in the split statistics
%   once k more examples have been inserted in the tree. The Q-function moves while it is
%   learned: without forgetting, a leaf compares TD errors from long ago (of a policy and
%   of estimates since changed) with today's, and a test that merely tells early examples
%   from later ones may look significant. A leaf's sums are kept in units of the weight an
%   example had when they were last rescaled (Base, the eighth argument of l/8): an example
%   inserted now weighs W = 2^((Clock - Base) / H) there, and dividing by W gives today's
%   weights.
%   When W grows large the leaf's sums are rescaled (once every 64 half-lives at most).
weight(L, Half, Clock, W) :-
    (   Half =:= 0
    ->  W = 1
    ;   arg(8, L, Base),
        E is (Clock - Base) / Half,
        (   E > 64
        ->  Scale is 2 ** (-E),
            rescale(L, Scale),
            nb_setarg(8, L, Clock),
            W = 1.0
        ;   W is 2 ** E
        )
    ).

%   The leaf's last Keep examples, in a ring (one slot written in place).
keep_example(Ring, Ex) :-
    functor(Ring, _, Arity),
    (   Arity =:= 1
    ->  true
    ;   arg(1, Ring, Next),
        Slot is Next + 1,
        nb_setarg(Slot, Ring, Ex),
        Next1 is Next mod (Arity - 1) + 1,
        nb_setarg(1, Ring, Next1)
    ).

rescale(L, Scale) :-
    forall(between(3, 5, I), scale_arg(L, Scale, I)),
    arg(6, L, C),
    functor(C, _, K),
    forall(between(1, K, I), scale_arg(C, Scale, I)).

scale_arg(T, Scale, I) :-
    arg(I, T, X),
    Y is X * Scale,
    nb_setarg(I, T, Y).

count_hits([], _, _, _).
count_hits([I|Is], C, W, T) :-
    J is 3 * I - 2, J2 is J + 1, J3 is J + 2,
    arg(J, C, M0), M is M0 + W, nb_setarg(J, C, M),
    arg(J2, C, S0), S is S0 + W * T, nb_setarg(J2, C, S),
    arg(J3, C, SS0), SS is SS0 + W * T * T, nb_setarg(J3, C, SS),
    count_hits(Is, C, W, T).

%   The candidate whose split explains the most variance, among those that leave at least
%   MinEx examples on each side: for a fixed total, F grows with S1^2/M1 + S2^2/M2, so only
%   that is compared. Best = I-s(M1, S1, SS1).
best_candidate(C, M, S, MinEx, I-s(M1, S1, SS1)) :-
    functor(C, _, Arity),
    Max is M - MinEx,
    best_from(1, Arity, C, M, S, MinEx, Max, none, -1.0, I),
    I \== none,
    J is 3 * I - 2, J2 is J + 1, J3 is J + 2,
    arg(J, C, M1), arg(J2, C, S1), arg(J3, C, SS1).

best_from(J, Arity, C, M, S, Min, Max, B0, G0, B) :-
    (   J > Arity
    ->  B = B0
    ;   arg(J, C, M1),
        (   M1 >= Min, M1 =< Max
        ->  J2 is J + 1, arg(J2, C, S1),
            G is S1 * S1 / M1 + (S - S1) * (S - S1) / (M - M1),
            (   G > G0
            ->  B1 is (J + 2) // 3, G1 = G
            ;   B1 = B0, G1 = G0
            )
        ;   B1 = B0, G1 = G0
        ),
        J1 is J + 3,
        best_from(J1, Arity, C, M, S, Min, Max, B1, G1, B)
    ).

% ---- splitting -----------------------------------------------------------------------------

%   Split leaf LeafId on its candidate I; the children start from their partitions:
%   s(Weight, Q, MeanTDError) each (today's weights; Q the leaf's estimate plus the mean TD
%   error on that side). Their statistics start from the leaf's kept examples (its ring):
%   each is sorted to its side and counted in the child's own sums and in those of the
%   child's candidates that succeed on it, with its TD error less the side's mean (the
%   child's Q has taken that in) and its weight of today. The rest of what the leaf
%   counted cannot be sorted (it kept only sums), so a child's statistics cover at most
%   the kept examples.
split(KB, D, LeafId, I, s(M1, QYes, DYes), s(M2, QNo, DNo)) :-
    tg_get_tree(KB, tree(Root0, Next0, Bias, Responses)),
    YesId = Next0, NoId is Next0 + 1, Next is Next0 + 2,
    replace_leaf(Root0, LeafId, Leaf, Node, Root),
    Leaf = leaf(LeafId, Path, Vars, Cands),
    nth1(I, Cands, cand(Lits, New)),
    append(Path, Lits, YesPath),
    append(Vars, New, YesVars),
    refinements(Bias, YesPath, YesVars, YesCands),
    refinements(Bias, Path, Vars, NoCands0),
    exclude(same_cand(Lits), NoCands0, NoCands),
    Yes = leaf(YesId, YesPath, YesVars, YesCands),
    No = leaf(NoId, Path, Vars, NoCands),
    Node = node(LeafId, Lits, New, Yes, No),
    length(YesCands, KY), length(NoCands, KN),
    arg(5, D, Clock),
    arg(1, D, Params), arg(8, Params, Half), arg(10, Params, Keep),
    NYes is max(1, round(M1)), NNo is max(1, round(M2)),
    tg_new_stats(QYes, NYes, KY, Clock, Keep, LYes),
    tg_new_stats(QNo, NNo, KN, Clock, Keep, LNo),
    arg(2, D, Leaves0), arg(LeafId, Leaves0, L0), arg(9, L0, Ring0),
    kept_sides(KB, LeafId, I, Ring0, YesEx, NoEx),
    put_leaf(D, LeafId, free),
    put_leaf(D, YesId, LYes),
    put_leaf(D, NoId, LNo),
    arg(4, D, Version0),
    Version is Version0 + 1,
    nb_setarg(4, D, Version),
    tg_put_tree(KB, tree(Root, Next, Bias, Responses)),
    tg_forget_leaf(KB, LeafId),
    tg_compile_leaf(KB, Yes),
    tg_compile_leaf(KB, No),
    tg_compile_tree(KB, Root),
    arg(2, D, Leaves),                  % the live leaf terms (put_leaf/3 copied them)
    arg(YesId, Leaves, LYes1), arg(NoId, Leaves, LNo1),
    replay(YesEx, KB, YesId, LYes1, DYes, Half, Clock),
    replay(NoEx, KB, NoId, LNo1, DNo, Half, Clock).

%   The leaf's kept examples on the yes-side (candidate I succeeds) and on the no-side.
kept_sides(KB, LeafId, I, Ring, YesEx, NoEx) :-
    Ring =.. [ring, _|Slots],
    exclude(==(none), Slots, Kept),
    partition(on_yes_side(KB, LeafId, I), Kept, YesEx, NoEx).

on_yes_side(KB, LeafId, I, ex(Facts, A, N, _, _)) :-
    once(tg_cands_(KB, LeafId, Facts, A, N, Hits)),
    memberchk(I, Hits).

%   Count the kept examples Exs in the new leaf Id (l/9 term L, sums in units of Clock's
%   weight, so an example of time T weighs 2^((T - Clock) / Half)) and keep them there.
replay([], _, _, _, _, _, _).
replay([ex(Facts, A, N, E0, T)|Exs], KB, Id, L, Shift, Half, Clock) :-
    E is E0 - Shift,
    (   Half =:= 0
    ->  W = 1.0
    ;   W is 2 ** ((T - Clock) / Half)
    ),
    arg(3, L, M0), arg(4, L, S0), arg(5, L, SS0),
    M is M0 + W, S is S0 + W * E, SS is SS0 + W * E * E,
    nb_setarg(3, L, M), nb_setarg(4, L, S), nb_setarg(5, L, SS),
    arg(6, L, C),
    once(tg_cands_(KB, Id, Facts, A, N, Hits)),
    count_hits(Hits, C, W, E),
    arg(9, L, Ring),
    keep_example(Ring, ex(Facts, A, N, E, T)),
    replay(Exs, KB, Id, L, Shift, Half, Clock).

%   The no-branch of a test never needs the test again.
same_cand(Lits, cand(Lits1, _)) :-
    Lits1 =@= Lits.

replace_leaf(leaf(Id, P, V, C), LeafId, Leaf, Node, Out) :-
    (   Id == LeafId
    ->  Leaf = leaf(Id, P, V, C), Out = Node
    ;   Out = leaf(Id, P, V, C)
    ).
replace_leaf(node(Id, L, N, Y0, No0), LeafId, Leaf, Node, node(Id, L, N, Y, No)) :-
    replace_leaf(Y0, LeafId, Leaf, Node, Y),
    replace_leaf(No0, LeafId, Leaf, Node, No).

put_leaf(D, Id, L) :-
    arg(2, D, Leaves0),
    functor(Leaves0, _, Cap),
    (   Id =< Cap
    ->  nb_setarg(Id, Leaves0, L)
    ;   Cap2 is max(2 * Cap, Id),
        Leaves0 =.. [F|Args0],
        Extra is Cap2 - Cap,
        length(More, Extra),
        maplist(=(free), More),
        append(Args0, More, Args),
        Leaves =.. [F|Args],
        setarg(Id, Leaves, L),
        nb_setarg(2, D, Leaves)
    ).

% ---- size ----------------------------------------------------------------------------------

%!  tg_size(+KB, -Size) is det.
%
%   Size is size(Positions, Details). Positions = nodes + entries in the paper's sense: every
%   node (test or leaf) and every stored Q value (one per leaf). Details:
%   [nodes=, tests=, leaves=, entries=, candidates=, candidates_max=, statistics=];
%   candidates counts the candidate tests of every leaf, candidates_max those of the leaf
%   with most; statistics counts the numbers kept only to decide splits: count, sum and sum
%   of squares for each leaf and for each candidate of each leaf.

tg_size(KB, size(Positions, [nodes=Nodes, tests=Tests, leaves=Leaves, entries=Leaves,
                             candidates=Cands, candidates_max=Max, statistics=Stats])) :-
    tg_get_tree(KB, tree(Root, _, _, _)),
    tree_counts(Root, c(0, 0, 0, 0), c(Tests, Leaves, Cands, Max)),
    Nodes is Tests + Leaves,
    Positions is Nodes + Leaves,
    Stats is 3 * (Leaves + Cands).

tree_counts(leaf(_, _, _, Cs), c(T, L0, C0, M0), c(T, L, C, M)) :-
    L is L0 + 1,
    length(Cs, K),
    C is C0 + K,
    M is max(M0, K).
tree_counts(node(_, _, _, Y, N), c(T0, L0, C0, M0), Out) :-
    T1 is T0 + 1,
    tree_counts(Y, c(T1, L0, C0, M0), Mid),
    tree_counts(N, Mid, Out).

%!  tg_policy_info(+KB, -Info:list) is det.
%
%   What a tg policy is tied to in the domain: [relations(Templates), rmodes(Modes),
%   rconsts(Consts)], the relational view's templates and the language bias (tg_bias/2). A bias of typed
%   variables names no place, toy or colour of the world, so these are the same in every
%   world of a family (the generated worlds of the scaling benchmark, whatever their size)
%   and a policy learned in one loads in any other.

tg_policy_info(KB, [relations(Templates), rmodes(Modes), rconsts(Consts)]) :-
    findall(T, declared(KB, relation(T)), Templates),
    tg_get_tree(KB, tree(_, _, bias(Modes, Consts), _)).

%!  tg_candidates(+KB, ?LeafId, -Texts:list) is nondet.
%
%   Texts are the candidate tests of leaf LeafId, written with their variables named.

tg_candidates(KB, LeafId, Texts) :-
    tg_get_tree(KB, tree(Root, _, _, _)),
    tg_tree_leaf(Root, leaf(LeafId, _, Vars, Cands)),
    findall(Text, ( member(cand(Lits, New), Cands),
                    append(Vars, New, All),
                    name_variables(All, Names),
                    conj_text(Lits, Names, Text) ), Texts).

% ---- the engine's hooks (see engine.pl) ----------------------------------------------------

relrl_engine:learner(tg).

relrl_engine:learner_property(tg, Cap) :-
    member(Cap, [view(relational), state, size, text, graph, policy, policy_info]).

%   Parameters (learners.pl; what each does: docs/tg.md; the defaults were chosen by
%   measurement on Experiment 1's task). In worlds, whose rewards are of size 1, Q starts
%   at 0 and both exploration bonuses are off: the novelty bonus's candidate tests for every
%   action of every choice made a learning step 17 times slower on 10-block states, and the
%   goal tasks were learned as well without it (docs/worlds.md); advantage learning is on
%   (action_gap 0.9): a leaf's value there averages states near and far from the goal, and
%   without it a leaf of wasted moves outranked the right moves of far states; 0.9 lets one
%   bias serve every task of blocks world (0.5 left unstack at 0.72 and on(A, B) at
%   0.44-0.59 of optimal on 10 blocks in seeds 0-1, docs/worlds.md). Each one-step target
%   is mixed with the return the episode earned from the next state (return_lambda 0.8,
%   a Q(lambda)-return, learned last first): a tree whose tests cannot count the moves to
%   the goal values the states after a right and a wasted move alike, and only the return
%   carries the difference; exploring at temperature 0.1 (rewards of size 1) keeps that
%   return near the greedy policy's (docs/worlds.md, One bias for every task).
relrl_engine:learner_parameter(tg, alpha, 0.2, unit).
relrl_engine:learner_parameter(tg, gamma, 0.9, unit).
relrl_engine:learner_parameter(tg, epsilon, 0.05, unit).
relrl_engine:learner_parameter(tg, temperature, 1.0, nonneg).
relrl_engine:learner_parameter(tg, q_init, 30.0, number).
relrl_engine:learner_parameter(tg, significance, 0.001, open_unit).
relrl_engine:learner_parameter(tg, min_examples, 5.0, whole(3)).
relrl_engine:learner_parameter(tg, stale_bonus, 1.0, nonneg).
relrl_engine:learner_parameter(tg, half_life, 1000.0, nonneg).
relrl_engine:learner_parameter(tg, novelty_bonus, 20.0, nonneg).
relrl_engine:learner_parameter(tg, novelty_confidence, 2.0, nonneg).
relrl_engine:learner_parameter(tg, keep_examples, 0.0, whole(0)).
relrl_engine:learner_parameter(tg, action_gap, 0.0, unit).
relrl_engine:learner_parameter(tg, return_lambda, 0.0, unit).
relrl_engine:learner_serves(tg, domains, []).
relrl_engine:learner_serves(tg, worlds, [q_init=0.0, novelty_bonus=0.0, stale_bonus=0.0,
                                         action_gap=0.9, return_lambda=0.8,
                                         temperature=0.1]).

:- learner_hooks(tg, [forget-tg_forget, init-tg_init, choose-tg_choose, update-tg_update,
                     explain-tg_explain, size-tg_size, save-tg_save,
                     policy_info-tg_policy_info, policy_term-tg_policy_term,
                     restore-tg_restore, text-tg_text, graph-tg_graph]).

relrl_engine:learner_state(tg, KB, _Code, Facts) :-
    tg_state(KB, Facts).
