:- module(relrl_tg,
          [ tg_init/2,            % +KB, +Params
            tg_state/2,           % +KB, -Facts
            tg_q/5,               % +KB, +Facts, +Action, +Necessity, -Q
            tg_choose/6,          % +KB, +Facts, +Necessity, +Allowed, +Mode, -Action
            tg_update/2,          % +KB, +Transition
            tg_insert/5,          % +KB, +Facts, +Action, +Necessity, +Target
            tg_explain/4,         % +KB, +Facts, +Necessity, -Explanation
            tg_size/2,            % +KB, -Size
            tg_save/2,            % +KB, +Stream
            tg_policy_term/1,     % ?Term
            tg_restore/2,         % +KB, +Terms
            tg_graph/2,           % +KB, -Graph
            tg_text/2,            % +KB, -Text
            tg_leaf_clauses/2,    % +KB, -Clauses
            tg_candidates/3       % +KB, ?LeafId, -Texts
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(library(random)).
:- use_module(library(aggregate)).
:- use_module(library(occurs)).
:- use_module(declarations).
:- use_module(engine).
:- use_module(tg_bias).
:- use_module(tg_stats).

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
    for it (tg_bias:refinements/4), the count, sum and sum of squares of the Q-targets of the
    examples on which the candidate succeeds. With the leaf's own three numbers, they give
    the F-test of every candidate split (tg_stats.pl). When the best candidate is
    significant at level `significance` after at least `min_examples` examples, the leaf
    becomes a test node; its two children start from their partitions' statistics (Q is the
    partition's mean Q-target) and from fresh candidates.

Q(s, a) for each allowed response comes from sorting (s, a) down the tree; each step one
example with Q-target r + gamma * max_a' Q(s', a') is inserted (no table of examples).

**Speed.** The hot path asserts nothing. The tree is compiled into one clause,
tg_sort_/5, and each leaf's candidate tests into one clause, tg_cands_/6, whenever the tree
changes (a split): sorting an example and testing every candidate are then compiled
Prolog over the example's own fact list (never a query of working memory). The numbers
live in a global term per knowledge base and are updated in place (nb_setarg/3).

Params (Name=Value): alpha (0: Q is the mean of the leaf's Q-targets; otherwise the rate
is max(1/n, alpha)), gamma, temperature (Boltzmann exploration; 0: epsilon-greedy),
epsilon, q_init (Q of the first, empty leaf), significance, min_examples, stale_bonus
(see tg_choose/6); the engine's reward_positive and reward_negative.
*/

:- dynamic
    tg_sort_/5,      % KB, Facts, Action, Necessity, LeafId   (the compiled tree)
    tg_cands_/6.     % KB, LeafId, Facts, Action, Necessity, Hits (a leaf's candidates)

% ---- the learner's state -------------------------------------------------------------------

%   Two global variables per knowledge base:
%
%   '$tg_tree:KB'  tree(Root, NextId, Bias, Responses), read (copied) only when the tree
%                  changes, is explained, drawn or saved. Root is a leaf(Id, PathLits,
%                  Vars, Cands) or node(Id, Lits, New, Yes, No) term; variables are shared
%                  along the path, as in the tree.
%   '$tg:KB'       tg(Params, Leaves, Cache, Version, Clock), read in place on every step:
%                  Params = p(Alpha, Gamma, Epsilon, Tau, Level, MinExamples, Kappa);
%                  Leaves = leaves(L1, ..., Lk), Li = l(Q, N, M, S, SS, C, Last) for leaf i
%                  (or `free`): the Q estimate and the examples counted in it (its
%                  partition's and its own), the count, sum and sum of squares of the
%                  Q-targets since the leaf was made, C = c(M1, S1, SS1, M2, ...) the same
%                  for each candidate, in order, and the Clock (examples inserted in the
%                  tree so far) when the leaf was last updated; the numbers are updated with
%                  nb_setarg/3.
%                  Cache = last(Facts, N, Allowed, LeafIds, Version): where the last update
%                  sorted the next state's allowed actions, reused by the choice that
%                  follows in the same step while the tree is unchanged (Version).

data(KB, D) :-
    atom_concat('$tg:', KB, K),
    (   nb_current(K, D0)
    ->  D = D0
    ;   existence_error(tg_learner, KB)
    ).

tree(KB, Tree) :-
    atom_concat('$tg_tree:', KB, K),
    (   nb_current(K, Tree0)
    ->  copy_term(Tree0, Tree)
    ;   existence_error(tg_learner, KB)
    ).

set_tree(KB, Tree) :-
    atom_concat('$tg_tree:', KB, K),
    nb_setval(K, Tree).

leaf_stats(KB, Id, L) :-
    data(KB, tg(_, Leaves, _, _, _)),
    arg(Id, Leaves, L).

%!  tg_init(+KB, +Params:list) is det.
%
%   Start KB's TG learner afresh: one leaf, Q = q_init, candidates from the domain's bias.

tg_init(KB, Params) :-
    must_be(atom, KB),
    must_be(list, Params),
    maplist(param(Params), [alpha, gamma, epsilon, temperature, q_init, significance,
                            min_examples, stale_bonus],
            [Alpha, Gamma, Epsilon, Tau, Qinit, Level, MinEx0, Kappa]),
    MinEx is max(2, round(MinEx0)),
    tg_bias(KB, Bias),
    findall(R, kb_response(KB, R), Responses),
    refinements(Bias, [], [], Cands),
    Root = leaf(1, [], [], Cands),
    length(Cands, K),
    new_stats(Qinit, 0, K, 0, L),
    empty_leaves(16, Leaves0),
    setarg(1, Leaves0, L),
    atom_concat('$tg:', KB, DK),
    nb_setval(DK, tg(p(Alpha, Gamma, Epsilon, Tau, Level, MinEx, Kappa), Leaves0, none, 0,
                     0)),
    set_tree(KB, tree(Root, 2, Bias, Responses)),
    retractall(tg_cands_(KB, _, _, _, _, _)),
    compile_leaf(KB, Root),
    compile_tree(KB, Root).

param(Params, Name, Value) :-
    (   memberchk(Name=V, Params)
    ->  must_be(number, V),
        Value = V
    ;   existence_error(tg_parameter, Name)
    ).

empty_leaves(Cap, Leaves) :-
    length(Free, Cap),
    maplist(=(free), Free),
    Leaves =.. [leaves|Free].

new_stats(Q, N, K, Clock, l(Q, N, 0, 0.0, 0.0, C, Clock)) :-
    findall(X, ( between(1, K, _), member(X, [0, 0.0, 0.0]) ), Xs),
    C =.. [c|Xs].

%!  tg_state(+KB, -Facts:list) is det.
%
%   The relational view of KB now (sorted ground facts; engine_relational_state/2).

tg_state(KB, Facts) :-
    engine_relational_state(KB, Facts).

% ---- compiling the tree --------------------------------------------------------------------

compile_tree(KB, Root) :-
    copy_term(Root, Tree),
    tree_goal(Tree, [], Facts, Action, N, Leaf, Body),
    retractall(tg_sort_(KB, _, _, _, _)),
    assertz((tg_sort_(KB, Facts, Action, N, Leaf) :- Body)).

tree_goal(leaf(Id, _, _, _), _, _, _, _, Leaf, Leaf = Id).
tree_goal(node(_, Lits, _, Yes, No), Path, F, A, N, Leaf, ( Cond -> GYes ; GNo )) :-
    append(Path, Lits, Path1),
    copy_term(Path1, Test),
    conj_goal(Test, F, A, N, last, Cond),
    tree_goal(Yes, Path1, F, A, N, Leaf, GYes),
    tree_goal(No, Path, F, A, N, Leaf, GNo).

%   The clause testing every candidate of a leaf on an example: Hits lists the positions
%   (from 1) of the candidates that succeed, in order.
compile_leaf(KB, leaf(Id, PathLits0, _, Cands0)) :-
    copy_term(PathLits0-Cands0, PathLits-Cands),
    term_variables(PathLits, PV),
    (   PV == []
    ->  foldl(cand_goal(no_path, F, A, N), Cands, Goals, 1, _)
    ;   conj_goal(PathLits, F, A, N, all, PathGoal),
        V =.. [v|PV],
        foldl(cand_goal(path(V, Sols), F, A, N), Cands, Goals0, 1, _),
        Goals = [findall(V, PathGoal, Sols)|Goals0]
    ),
    hits_body(Goals, Hits, Body),
    assertz((tg_cands_(KB, Id, F, A, N, Hits) :- Body)).

%   A candidate that shares variables with the leaf's path query is tried with each
%   solution of the path query (found once per example); one that does not, on its own.
cand_goal(no_path, F, A, N, cand(Lits, _), hit(I, Goal), I, I1) :-
    I1 is I + 1,
    conj_goal(Lits, F, A, N, last, Goal).
cand_goal(path(V, Sols), F, A, N, cand(Lits, _), hit(I, Goal), I, I1) :-
    I1 is I + 1,
    (   term_variables(Lits, LV),
        term_variables(V, PV),
        member(X, LV), member(Y, PV), X == Y
    ->  copy_term(V-Lits, V1-Lits1),
        conj_goal(Lits1, F, A, N, last, G),
        Goal = ( member(V1, Sols), G )
    ;   conj_goal(Lits, F, A, N, last, Goal)
    ).

hits_body([], [], true).
hits_body([hit(I, G)|Gs], Hits, (( G -> Hits = [I|Hits1] ; Hits = Hits1 ), Body)) :-
    !,
    hits_body(Gs, Hits1, Body).
hits_body([G|Gs], Hits, (G, Body)) :-
    hits_body(Gs, Hits, Body).

% ---- values and choices --------------------------------------------------------------------

%!  tg_q(+KB, +Facts, +Action, +Necessity, -Q) is det.
%
%   Q is the tree's estimate for Action in the state Facts under Necessity.

tg_q(KB, Facts, Action, N, Q) :-
    tg_sort_(KB, Facts, Action, N, Leaf),
    leaf_stats(KB, Leaf, L),
    arg(1, L, Q).

%!  tg_choose(+KB, +Facts, +Necessity, +Allowed, +Mode, -Action) is det.
%
%   Action is one of the Allowed responses. With Mode learn or explore: with temperature
%   T > 0, drawn with probability proportional to exp(Q / T) (Boltzmann exploration);
%   with T = 0, a random one with probability epsilon and otherwise a greedy one. With
%   Mode greedy, one with the largest Q. Ties are broken at random. While learning (Mode
%   learn), the Q of a leaf that no example has reached for the last K examples inserted
%   in the tree counts as Q + stale_bonus * sqrt(K): a part of the Q-function that went
%   stale while the rest moved is tried again (the exploration bonus of Sutton's Dyna-Q+,
%   here per leaf). Explore and greedy choices, and the Q-targets, never include it.

tg_choose(KB, Facts, N, Allowed, Mode, Action) :-
    Allowed = [_|_],
    data(KB, D),
    D = tg(p(_, _, Epsilon, Tau, _, _, Kappa), Leaves, Cache, Version, Clock),
    (   Mode \== greedy, Tau =:= 0,
        random_float < Epsilon
    ->  random_member(Action, Allowed)
    ;   (   Cache = last(F1, N1, A1, Ids, Version), F1 == Facts, N1 == N, A1 == Allowed
        ->  true
        ;   maplist(sorted_leaf(KB, Facts, N), Allowed, Ids)
        ),
        (   Mode == learn, Kappa > 0
        ->  maplist(bonus_q(Leaves, Kappa, Clock), Ids, Qs)
        ;   maplist(leaf_q(Leaves), Ids, Qs)
        ),
        max_list(Qs, Best),
        (   Mode \== greedy, Tau > 0
        ->  softmax_member(Qs, Allowed, Best, Tau, Action)
        ;   ties(Qs, Allowed, Best, Ties),
            random_member(Action, Ties)
        )
    ).

leaf_q(Leaves, Id, Q) :-
    arg(Id, Leaves, L),
    arg(1, L, Q).

bonus_q(Leaves, Kappa, Clock, Id, Q) :-
    arg(Id, Leaves, L),
    arg(1, L, Q0),
    arg(7, L, Last),
    Q is Q0 + Kappa * sqrt(max(0, Clock - Last)).

ties([], [], _, []).
ties([Q|Qs], [A|As], Best, Ties) :-
    (   Q =:= Best
    ->  Ties = [A|Ties1]
    ;   Ties = Ties1
    ),
    ties(Qs, As, Best, Ties1).

softmax_member(Qs, Allowed, Best, Tau, Action) :-
    weights(Qs, Best, Tau, Ws, 0.0, Total),
    X is random_float * Total,
    pick(Ws, Allowed, X, Action).

weights([], _, _, [], T, T).
weights([Q|Qs], Best, Tau, [W|Ws], T0, T) :-
    W is exp((Q - Best) / Tau),
    T1 is T0 + W,
    weights(Qs, Best, Tau, Ws, T1, T).

pick([W|Ws], [A|As], X, Action) :-
    (   ( X < W ; Ws == [] )
    ->  Action = A
    ;   X1 is X - W,
        pick(Ws, As, X1, Action)
    ).

%!  tg_update(+KB, +Transition) is det.
%
%   Learn from transition(S0, A0, N0, Reward, Reinforced, S1, N1, Allowed1): insert the
%   example (S0, A0, N0) with Q-target Reward + gamma * max Q(S1, a, N1) over the responses
%   Allowed1 (over every response when none is allowed).

tg_update(KB, transition(S0, A0, N0, Reward, _, S1, N1, Allowed1)) :-
    data(KB, D),
    D = tg(p(_, Gamma, _, _, _, _, _), Leaves, _, Version, _),
    (   Allowed1 == []
    ->  tree(KB, tree(_, _, _, Next))
    ;   Next = Allowed1
    ),
    maplist(sorted_leaf(KB, S1, N1), Next, Ids),
    maplist(leaf_q(Leaves), Ids, Qs),
    max_list(Qs, Max),
    Target is Reward + Gamma * Max,
    nb_setarg(3, D, last(S1, N1, Allowed1, Ids, Version)),
    insert(KB, D, S0, A0, N0, Target).

sorted_leaf(KB, Facts, N, A, Leaf) :-
    tg_sort_(KB, Facts, A, N, Leaf).

%!  tg_insert(+KB, +Facts, +Action, +Necessity, +Target:number) is det.
%
%   Insert one example: sort it to its leaf, move the leaf's Q towards Target, count Target
%   in the leaf's statistics and in those of every candidate that succeeds on the example,
%   and split the leaf when its best candidate is significant.

tg_insert(KB, Facts, A, N, Target) :-
    data(KB, D),
    insert(KB, D, Facts, A, N, Target).

insert(KB, D, Facts, A, N, Target) :-
    D = tg(p(Alpha, _, _, _, Level, MinEx, _), Leaves, _, _, Clock0),
    Clock is Clock0 + 1,
    nb_setarg(5, D, Clock),
    tg_sort_(KB, Facts, A, N, Leaf),
    arg(Leaf, Leaves, L),
    L = l(Q0, N0, M0, S0, SS0, C, _),
    N1 is N0 + 1,
    Q is Q0 + max(1 / N1, Alpha) * (Target - Q0),
    M is M0 + 1,
    S is S0 + Target,
    SS is SS0 + Target * Target,
    nb_setarg(1, L, Q), nb_setarg(2, L, N1),
    nb_setarg(3, L, M), nb_setarg(4, L, S), nb_setarg(5, L, SS), nb_setarg(7, L, Clock),
    tg_cands_(KB, Leaf, Facts, A, N, Hits),
    count_hits(Hits, C, Target),
    (   M >= 2 * MinEx,
        M /\ 3 =:= 0,                               % every fourth example
        best_candidate(C, M, S, MinEx, Best),
        Best = I-Yes,
        split_f(s(M, S, SS), Yes, F, Dof),
        functor(C, _, Arity),
        Corrected is Level * 3 / Arity,             % Bonferroni: level / candidates
        f_significant(F, Dof, Corrected)
    ->  split(KB, D, Leaf, I, Yes, s(M, S, SS))
    ;   true
    ).

count_hits([], _, _).
count_hits([I|Is], C, T) :-
    J is 3 * I - 2, J2 is J + 1, J3 is J + 2,
    arg(J, C, M0), M is M0 + 1, nb_setarg(J, C, M),
    arg(J2, C, S0), S is S0 + T, nb_setarg(J2, C, S),
    arg(J3, C, SS0), SS is SS0 + T * T, nb_setarg(J3, C, SS),
    count_hits(Is, C, T).

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

split(KB, D, LeafId, I, s(M1, S1, _), s(M, S, _)) :-
    tree(KB, tree(Root0, Next0, Bias, Responses)),
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
    M2 is M - M1, S2 is S - S1,
    QYes is S1 / M1, QNo is S2 / M2,
    length(YesCands, KY), length(NoCands, KN),
    arg(5, D, Clock),
    new_stats(QYes, M1, KY, Clock, LYes),
    new_stats(QNo, M2, KN, Clock, LNo),
    put_leaf(D, LeafId, free),
    put_leaf(D, YesId, LYes),
    put_leaf(D, NoId, LNo),
    arg(4, D, Version0),
    Version is Version0 + 1,
    nb_setarg(4, D, Version),
    set_tree(KB, tree(Root, Next, Bias, Responses)),
    retractall(tg_cands_(KB, LeafId, _, _, _, _)),
    compile_leaf(KB, Yes),
    compile_leaf(KB, No),
    compile_tree(KB, Root).

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

% ---- explaining ----------------------------------------------------------------------------

%!  tg_explain(+KB, +Facts, +Necessity, -Explanation) is det.
%
%   Explanation is tg(Ranked): for every response, choice(Action, Q, Leaf, Path) in
%   decreasing Q (ties in declaration order). Path lists the tests from the root to the
%   action's leaf as test(Id, Text, Outcome, Bindings): Text the conjunction with its
%   variables named, Outcome true or false, Bindings the Name=Value pairs of the variables
%   the test introduced, from the first solution of the query that made it true.

tg_explain(KB, Facts, N, tg(Ranked)) :-
    tree(KB, tree(Root, _, _, Responses)),
    findall(NegQ-choice(A, Q, Leaf, Path),
            ( member(A, Responses),
              explain_path(Root, [], [], Facts, A, N, Path, Leaf),
              leaf_stats(KB, Leaf, L), arg(1, L, Q),
              NegQ is -Q ),
            Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Ranked).

explain_path(leaf(Id, _, _, _), _, _, _, _, _, [], Id).
explain_path(node(Id, Lits, New, Yes, No), Path, Vars, Facts, A, N, [Step|Steps], Leaf) :-
    append(Path, Lits, Path1),
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    (   \+ \+ holds_all(Path1, Facts, A, N)
    ->  copy_term(Path1-Names, Path2-Names2),
        once(holds_all(Path2, Facts, A, N)),
        include(introduced(New, Names), Names2, Bound0),
        maplist(binding_pair, Bound0, Bound),
        Step = test(Id, Text, true, Bound),
        explain_path(Yes, Path1, Vars1, Facts, A, N, Steps, Leaf)
    ;   Step = test(Id, Text, false, []),
        explain_path(No, Path, Vars, Facts, A, N, Steps, Leaf)
    ).

holds_all(Lits, Facts, A, N) :-
    maplist([L]>>literal_holds(L, Facts, A, N), Lits).

introduced(New, Names, Name=_) :-
    member(Name=V, Names),
    member(W-_, New),
    V == W,
    !.

binding_pair(Name=Value, Name-Value).

% ---- size ----------------------------------------------------------------------------------

%!  tg_size(+KB, -Size) is det.
%
%   Size is size(Positions, Details). Positions = nodes + entries in the paper's sense: every
%   node (test or leaf) and every stored Q value (one per leaf). Details:
%   [nodes=, tests=, leaves=, entries=, candidates=, statistics=]; statistics counts the
%   numbers kept only to decide splits: count, sum and sum of squares for each leaf and for
%   each candidate of each leaf.

tg_size(KB, size(Positions, [nodes=Nodes, tests=Tests, leaves=Leaves, entries=Leaves,
                             candidates=Cands, statistics=Stats])) :-
    tree(KB, tree(Root, _, _, _)),
    tree_counts(Root, 0-0-0, Tests-Leaves-Cands),
    Nodes is Tests + Leaves,
    Positions is Nodes + Leaves,
    Stats is 3 * (Leaves + Cands).

tree_counts(leaf(_, _, _, Cs), T-L0-C0, T-L-C) :-
    L is L0 + 1,
    length(Cs, K),
    C is C0 + K.
tree_counts(node(_, _, _, Y, N), T0-L0-C0, Out) :-
    T1 is T0 + 1,
    tree_counts(Y, T1-L0-C0, Mid),
    tree_counts(N, Mid, Out).

%!  tg_candidates(+KB, ?LeafId, -Texts:list) is nondet.
%
%   Texts are the candidate tests of leaf LeafId, written with their variables named.

tg_candidates(KB, LeafId, Texts) :-
    tree(KB, tree(Root, _, _, _)),
    tree_leaf(Root, leaf(LeafId, _, Vars, Cands)),
    findall(Text, ( member(cand(Lits, New), Cands),
                    append(Vars, New, All),
                    name_variables(All, Names),
                    conj_text(Lits, Names, Text) ), Texts).

tree_leaf(L, L) :-
    L = leaf(_, _, _, _).
tree_leaf(node(_, _, _, Y, N), L) :-
    (   tree_leaf(Y, L)
    ;   tree_leaf(N, L)
    ).

% ---- the tree as text, as a graph, as rules ------------------------------------------------

%!  tg_text(+KB, -Text:string) is det.
%
%   Text draws the tree, one line per node, indented by depth.

tg_text(KB, Text) :-
    tree(KB, tree(Root, _, _, _)),
    with_output_to(string(Text), text_node(KB, Root, [], "", "")).

text_node(KB, leaf(Id, _, _, _), _, Indent, Label) :-
    leaf_stats(KB, Id, l(Q, N, _, _, _, _, _)),
    format("~w~wleaf [~d] Q=~4f  (n=~d)~n", [Indent, Label, Id, Q, N]).
text_node(KB, node(Id, Lits, New, Yes, No), Vars, Indent, Label) :-
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    format("~w~w[~d] ~w ?~n", [Indent, Label, Id, Text]),
    string_concat(Indent, "    ", Deeper),
    text_node(KB, Yes, Vars1, Deeper, "yes: "),
    text_node(KB, No, Vars, Deeper, "no:  ").

%!  tg_graph(+KB, -Graph) is det.
%
%   Graph is graph(Nodes, Edges): node(Id, test, Label) and node(Id, leaf, Label) (Label a
%   string), edge(From, To, yes) and edge(From, To, no).

tg_graph(KB, graph(Nodes, Edges)) :-
    tree(KB, tree(Root, _, _, _)),
    graph_node(KB, Root, [], Nodes, [], Edges, []).

graph_node(KB, leaf(Id, _, _, _), _, [node(Id, leaf, Label)|Ns], Ns, Es, Es) :-
    leaf_stats(KB, Id, l(Q, N, _, _, _, _, _)),
    format(string(Label), "Q=~2f (n=~d)", [Q, N]).
graph_node(KB, node(Id, Lits, New, Yes, No), Vars, [node(Id, test, Text)|Ns0], Ns,
           [edge(Id, YId, yes), edge(Id, NId, no)|Es0], Es) :-
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    arg(1, Yes, YId), arg(1, No, NId),
    graph_node(KB, Yes, Vars1, Ns0, Ns1, Es0, Es1),
    graph_node(KB, No, Vars, Ns1, Ns, Es1, Es).

%!  tg_leaf_clauses(+KB, -Clauses:list) is det.
%
%   One clause per leaf, q(Action, Necessity, Q) :- Body, that a person can read and plain
%   swipl can run in the domain's knowledge base: Body holds the leaf's path query and, for
%   each no-branch on the path, the negation of that test's query (a renamed copy: TILDE's
%   semantics). action(T) becomes the head's action, necessity(T) its necessity; Q is
%   rounded to three decimals. Inside a negation, what the clause already makes true is
%   left out (an action the head fixes, a ground literal of the body), and a negated
%   equality is written as X \= Y on the arguments that differ. Variables are named by
%   type (P for a place, T for a toy), Action and Necessity in the head; a variable used
%   once is written _.

tg_leaf_clauses(KB, Clauses) :-
    leaf_rules(KB, Rules),
    maplist(named_rule, Rules, Clauses).

named_rule(Rule-Names, Rule) :-
    term_variables(Rule, Vs),
    foldl(occurrences(Rule), Vs, Counts, []),
    maplist(name_var(Counts), Names).

occurrences(Term, V, [V-N|Cs], Cs) :-
    aggregate_all(count, ( sub_term(X, Term), X == V ), N).

name_var(Counts, Name=V) :-
    (   var(V)
    ->  (   member(W-1, Counts), W == V
        ->  V = '$VAR'('_')
        ;   V = '$VAR'(Name)
        )
    ;   true
    ).

%   Rule-Names for every leaf: the rule with its variables, and Name=Var for each.
leaf_rules(KB, Rules) :-
    tree(KB, tree(Root, _, _, _)),
    findall(R, leaf_clause(KB, Root, [], [], [], R), Rules).

leaf_clause(KB, leaf(Id, _, _, _), Pos, Neg, Vars, Clause-Names) :-
    leaf_stats(KB, Id, l(Q0, _, _, _, _, _, _)),
    Q is round(Q0 * 1000) / 1000.0,
    Head = q(Action, Necessity, Q),
    foldl(positive(Action, Necessity), Pos, Goals0, []),
    pairs_keys_values(Neg, NegTests, NegVars),
    maplist(negative(Action, Necessity, Goals0), NegTests, NegGoals),
    append(Goals0, NegGoals, Goals),
    append([Vars|NegVars], AllVars),
    name_variables(AllVars, Names0),
    Names = ['Action'=Action, 'Necessity'=Necessity|Names0],
    (   Goals == []
    ->  Clause = Head
    ;   list_conj_(Goals, Body),
        Clause = (Head :- Body)
    ).
leaf_clause(KB, node(_, Lits, New, Yes, No), Pos, Neg, Vars, Clause) :-
    append(Pos, Lits, Pos1),
    append(Vars, New, Vars1),
    (   leaf_clause(KB, Yes, Pos1, Neg, Vars1, Clause)
    ;   copy_term(Pos1-Vars1, Test-TestVars),
        append(Neg, [Test-TestVars], Neg1),
        leaf_clause(KB, No, Pos, Neg1, Vars, Clause)
    ).

positive(A, _, action(T), Gs, Gs) :- !, A = T.
positive(_, N, necessity(T), Gs, Gs) :- !, N = T.
positive(_, _, L, [L|Gs], Gs).

%   The negation of a test's query (run after the positive goals Known).
negative(A, N, Known, Lits, Goal) :-
    maplist(body_literal(A, N), Lits, Goals0),
    exclude(known_true(Known), Goals0, Goals),
    (   Goals == []
    ->  Goal = fail                        % the query holds whenever Known does
    ;   Goals = [X = Y]
    ->  differing(X, Y, X1, Y1),
        Goal = (X1 \= Y1)
    ;   list_conj_(Goals, Conj),
        Goal = (\+ Conj)
    ).

body_literal(A, _, action(T), A = T) :- !.
body_literal(_, N, necessity(T), N = T) :- !.
body_literal(_, _, L, L).

known_true(_, X = Y) :-
    X == Y,
    !.
known_true(Known, G) :-
    ground(G),
    member(K, Known),
    K == G,
    !.

%   f(..., X, ...) \= f(..., Y, ...) is X \= Y when every other argument is the same.
differing(X, Y, X1, Y1) :-
    (   compound(X), compound(Y),
        X =.. [F|As], Y =.. [F|Bs],
        same_length(As, Bs),
        one_differs(As, Bs, A, B)
    ->  differing(A, B, X1, Y1)
    ;   X1 = X, Y1 = Y
    ).

one_differs([A|As], [B|Bs], X, Y) :-
    (   A == B
    ->  one_differs(As, Bs, X, Y)
    ;   As == Bs,
        X = A, Y = B
    ).

list_conj_([G], G) :- !.
list_conj_([G|Gs], (G, C)) :- list_conj_(Gs, C).

% ---- saving and restoring ------------------------------------------------------------------

%!  tg_save(+KB, +Stream) is det.
%
%   Write the learned tree to Stream: tg_tree/1 (the tree itself, read back by relrl) and
%   the leaves as q/3 rules (for a person, and for plain swipl).

tg_save(KB, S) :-
    tree(KB, tree(Root, _, _, _)),
    saved_tree(KB, Root, [], Saved, Vars),
    name_variables(Vars, Names),
    maplist([Name=V]>>(V = '$VAR'(Name)), Names),
    format(S, "% The tree: tests (conjunctions; a variable is used only in the yes-branch of~n", []),
    format(S, "% the test that introduces it) and leaves (Q estimate, examples counted).~n", []),
    portray_clause(S, tg_tree(Saved)),
    nl(S),
    format(S, "% The same knowledge as rules: Q of an action in the state working memory~n", []),
    format(S, "% holds now, under the active necessity (one clause per leaf).~n", []),
    tg_leaf_clauses(KB, Clauses),
    forall(member(C, Clauses), portray_clause(S, C)).

saved_tree(KB, leaf(Id, _, _, _), _, leaf(Id, Q, N), []) :-
    leaf_stats(KB, Id, l(Q, N, _, _, _, _, _)).
saved_tree(KB, node(Id, Lits, New, Y, N), Vars, node(Id, Lits, New, SY, SN), All) :-
    append(Vars, New, Vars1),
    saved_tree(KB, Y, Vars1, SY, AY),
    saved_tree(KB, N, Vars, SN, AN),
    append([New, AY, AN], All).

%!  tg_policy_term(?Term) is semidet.
%
%   Term may appear in a tg policy file: tg_tree/1 or a q/3 clause.

tg_policy_term(Term) :-
    nonvar(Term),
    (   Term = tg_tree(_)
    ->  true
    ;   Term = (q(_, _, _) :- _)
    ->  true
    ;   Term = q(_, _, _)
    ).

%!  tg_restore(+KB, +Terms:list) is det.
%
%   Rebuild KB's tree from the terms of a policy file (tg_tree/1; the q/3 rules must be
%   the ones the tree gives). Candidates and their statistics start afresh.
%
%   @error existence_error(tg_tree, Terms) if there is no tg_tree/1 term.
%   @error domain_error(tg_tree, Node) for a malformed node.
%   @error domain_error(tg_rules_match_tree, Clause) for a q/3 rule the tree does not give.

tg_restore(KB, Terms) :-
    (   memberchk(tg_tree(Saved), Terms)
    ->  true
    ;   existence_error(tg_tree, Terms)
    ),
    tree(KB, tree(_, _, Bias, Responses)),
    restored(Saved, Bias, [], [], Root, Stats),
    pairs_keys(Stats, Ids),
    (   sort(Ids, Unique), length(Unique, U), length(Ids, U)
    ->  true
    ;   domain_error(tg_tree_unique_ids, Ids)
    ),
    max_list(Ids, MaxId),
    Cap is max(16, MaxId),
    empty_leaves(Cap, Leaves),
    foldl(place_leaf(Leaves), Stats, _, _),
    data(KB, D),
    nb_setarg(2, D, Leaves),
    nb_setarg(3, D, none),
    arg(4, D, Version0), Version is Version0 + 1, nb_setarg(4, D, Version),
    nb_setarg(5, D, 0),
    Next is MaxId + 1,
    set_tree(KB, tree(Root, Next, Bias, Responses)),
    retractall(tg_cands_(KB, _, _, _, _, _)),
    forall(tree_leaf(Root, Leaf), compile_leaf(KB, Leaf)),
    compile_tree(KB, Root),
    check_rules(KB, Terms).

restored(leaf(Id, Q, N), Bias, Path, Vars, leaf(Id, Path, Vars, Cands), [Id-L]) :-
    !,
    (   integer(Id), Id > 0, number(Q), integer(N), N >= 0
    ->  true
    ;   domain_error(tg_tree, leaf(Id, Q, N))
    ),
    refinements(Bias, Path, Vars, Cands),
    length(Cands, K),
    new_stats(Q, N, K, 0, L).
restored(node(Id, Lits, New, Y, N), Bias, Path, Vars, node(Id, Lits, New, RY, RN), Stats) :-
    !,
    (   integer(Id), Id > 0, is_list(Lits), Lits \== [], maplist(callable, Lits),
        is_list(New), maplist(typed_var, New)
    ->  true
    ;   domain_error(tg_tree, node(Id, Lits, New))
    ),
    append(Path, Lits, Path1),
    append(Vars, New, Vars1),
    restored(Y, Bias, Path1, Vars1, RY, SY),
    restored(N, Bias, Path, Vars, RN, SN),
    append([Id-test|SY], SN, Stats).
restored(Other, _, _, _, _, _) :-
    domain_error(tg_tree, Other).

place_leaf(Leaves, Id-L, _, _) :-
    (   L == test
    ->  true
    ;   setarg(Id, Leaves, L)
    ).

typed_var(V-T) :-
    var(V),
    atom(T).

%   The q/3 rules of a policy are the tree written as rules: refuse a file whose rules
%   say something else (an edited rule would otherwise be silently ignored).
check_rules(KB, Terms) :-
    leaf_rules(KB, Mine),
    include(is_rule, Terms, Rules),
    forall(member(R, Rules),
           (   member(M-_, Mine), same_rule(R, M)
           ->  true
           ;   domain_error(tg_rules_match_tree, R)
           )).

is_rule((q(_, _, _) :- _)).
is_rule(q(_, _, _)).

same_rule(R, M) :-
    rule_parts(R, q(A, N, Q), B),
    rule_parts(M, q(A1, N1, Q1), B1),
    number(Q),
    abs(Q - Q1) =< 0.0011,
    q(A, N)-B =@= q(A1, N1)-B1.

rule_parts((H :- B), H, B) :- !.
rule_parts(H, H, true).

% ---- the engine's hooks (see engine.pl) ----------------------------------------------------

relrl_engine:learner(tg).

relrl_engine:learner_init(tg, KB, Params) :-
    tg_init(KB, Params).

relrl_engine:learner_state(tg, KB, _Code, Facts) :-
    tg_state(KB, Facts).

relrl_engine:learner_choose(tg, KB, Facts, N, Allowed, Mode, Action) :-
    tg_choose(KB, Facts, N, Allowed, Mode, Action).

relrl_engine:learner_update(tg, KB, Transition) :-
    tg_update(KB, Transition).

relrl_engine:learner_explain(tg, KB, Facts, N, Explanation) :-
    tg_explain(KB, Facts, N, Explanation).

relrl_engine:learner_size(tg, KB, Size) :-
    tg_size(KB, Size).

relrl_engine:learner_save(tg, KB, Stream) :-
    tg_save(KB, Stream).

relrl_engine:learner_policy_term(tg, Term) :-
    tg_policy_term(Term).

relrl_engine:learner_restore(tg, KB, Terms) :-
    tg_restore(KB, Terms).

relrl_engine:learner_text(tg, KB, Text) :-
    tg_text(KB, Text).

relrl_engine:learner_graph(tg, KB, Graph) :-
    tg_graph(KB, Graph).
