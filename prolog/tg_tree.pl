:- module(relrl_tg_tree,
          [ tg_data/2,            % +KB, -Data
            tg_get_tree/2,        % +KB, -Tree
            tg_put_tree/2,        % +KB, +Tree
            tg_put_data/2,        % +KB, +Data
            tg_forget/1,          % +KB
            tg_leaf/3,            % +KB, +LeafId, -Stats
            tg_new_stats/6,       % +Q, +N, +K, +Clock, +Keep, -Stats
            tg_empty_leaves/2,    % +Capacity, -Leaves
            tg_compile_tree/2,    % +KB, +Root
            tg_compile_leaf/2,    % +KB, +Leaf
            tg_forget_leaf/2,     % +KB, +LeafId
            tg_forget_leaves/1,   % +KB
            tg_tree_leaf/2,       % +Tree, ?Leaf
            tg_sort_/5,           % +KB, +Facts, +Action, +Necessity, -LeafId
            tg_cands_/6,          % +KB, +LeafId, +Facts, +Action, +Necessity, -Hits
            tg_path_/5,           % +KB, +LeafId, +Index, ?Action, +Necessity
            tg_leaves_/3          % +KB, -LeafIds, -MaxId
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(tg_bias).
:- use_module(kbstate).

/** <module> The TG learner's state and its compiled tree

What the TG learner (tg.pl) knows, kept per knowledge base, and the tree compiled into
clauses: tg_sort_/5 sorts an example (facts, action, necessity) to its leaf, tg_cands_/6
tests every candidate of a leaf on an example, tg_path_/5 proves a leaf's path query (the
tests on the yes-branches above it) with the action left open, so that it binds the
action's arguments from the facts, looked up in an index of them (tg_bias:facts_index/2;
tg_classes.pl: the leaves some legal action of a world reaches), and tg_leaves_/3 lists
the leaves. They are recompiled when the tree changes
(a split, a restore), never on the hot path. tg.pl learns with them; tg_knowledge.pl
explains, draws, saves and restores them.
*/

:- dynamic
    tg_sort_/5,      % KB, Facts, Action, Necessity, LeafId   (the compiled tree)
    tg_cands_/6,     % KB, LeafId, Facts, Action, Necessity, Hits (a leaf's candidates)
    tg_path_/5,      % KB, LeafId, Index, Action, Necessity    (a leaf's path query)
    tg_leaves_/3.    % KB, LeafIds, MaxId                       (the leaves, left to right)

% ---- the learner's state -------------------------------------------------------------------

%   Two parts of the knowledge base's record (kbstate.pl):
%
%   tree           tree(Root, NextId, Bias, Responses), read (copied) only when the
%                  tree changes, is explained, drawn or saved. Root is a leaf(Id, PathLits,
%                  Vars, Cands) or node(Id, Lits, New, Yes, No) term; variables are shared
%                  along the path, as in the tree.
%   learner        tg(Params, Leaves, Cache, Version, Clock, Index), read in place on every
%                  step:
%                  Leaves = leaves(L1, ..., Lk), Li = l(Q, N, M, S, SS, C, Last, Base,
%                  Ring) for leaf i (or `free`): the Q estimate and the examples counted in
%                  it (its partition's and its own), the count, sum and sum of squares of
%                  the TD errors of its own examples (tg.pl), C = c(M1, S1, SS1, M2, ...)
%                  the same for each candidate, in order, the Clock (examples inserted in
%                  the tree so far) when the leaf was last updated, the Clock its sums are
%                  weighed from (forgetting, tg.pl's weight/4), and Ring = ring(Next, X1,
%                  ..., XKeep) its last Keep examples, ex(Facts, Action, Necessity,
%                  TDError, Clock) or `none` (a split sorts them into its children); the
%                  numbers are updated with nb_setarg/3. Params = p(Alpha, Gamma, Epsilon,
%                  Tau, Level, MinExamples, Kappa, HalfLife, novelty(Beta, Confidence),
%                  Keep, Gap) (Kappa the stale bonus, Beta the novelty bonus, Gap the
%                  action gap). Cache =
%                  last(Facts, N, Allowed, Classes, LeafIds, Version, Chose): the classes
%                  of the next state's allowed responses (tg_classes.pl) and their leaves,
%                  found by the last update and reused by the choice that follows in the
%                  same step while the tree is unchanged (Version); Chose is
%                  chose(Action, Leaf, Hits) once that choice has found the chosen class's
%                  leaf and candidate hits (reused by the next update's insertion), or
%                  none. Index is the response index
%                  (tg_classes:tg_response_index/3).

%!  tg_data(+KB, -Data) is det.
%
%   Data is KB's tg/5 term (above), the live term: change it with nb_setarg/3 only.
%
%   @error existence_error(tg_learner, KB) when KB has no tg learner.

tg_data(KB, D) :-
    kb_get(KB, learner, D0),
    (   D0 = tg(_, _, _, _, _, _)
    ->  D = D0
    ;   existence_error(tg_learner, KB)
    ).

%!  tg_put_data(+KB, +Data) is det.
%
%   Data becomes KB's tg/6 term (a copy; change it afterwards with nb_setarg/3 only).

tg_put_data(KB, D) :-
    kb_set(KB, learner, D).

%!  tg_get_tree(+KB, -Tree) is det.
%
%   Tree is a copy of KB's tree/4 term (above).

tg_get_tree(KB, Tree) :-
    kb_get(KB, tree, Tree0),
    (   Tree0 = tree(_, _, _, _)
    ->  copy_term(Tree0, Tree)
    ;   existence_error(tg_learner, KB)
    ).

%!  tg_put_tree(+KB, +Tree) is det.
%
%   Tree becomes KB's tree/4 term.

tg_put_tree(KB, Tree) :-
    kb_set(KB, tree, Tree).

%!  tg_leaf(+KB, +LeafId, -Stats) is det.
%
%   Stats is the live l/9 term of leaf LeafId (above).

tg_leaf(KB, Id, L) :-
    tg_data(KB, tg(_, Leaves, _, _, _, _)),
    arg(Id, Leaves, L).

%!  tg_empty_leaves(+Capacity, -Leaves) is det.
%
%   Leaves is leaves(free, ...) with Capacity arguments.

tg_empty_leaves(Cap, Leaves) :-
    length(Free, Cap),
    maplist(=(free), Free),
    Leaves =.. [leaves|Free].

%!  tg_new_stats(+Q, +N, +K, +Clock, +Keep, -Stats) is det.
%
%   Stats is a new leaf's l/9 term: estimate Q from N examples, no examples of its own
%   yet, K candidates with empty statistics, last updated at Clock, sums in units of
%   Clock's weight, room for its last Keep examples (none kept yet).

tg_new_stats(Q, N, K, Clock, Keep, l(Q, N, 0, 0.0, 0.0, C, Clock, Clock, Ring)) :-
    findall(X, ( between(1, K, _), member(X, [0, 0.0, 0.0]) ), Xs),
    C =.. [c|Xs],
    length(Slots, Keep),
    maplist(=(none), Slots),
    Ring =.. [ring, 1|Slots].

% ---- compiling the tree --------------------------------------------------------------------

%!  tg_compile_tree(+KB, +Root) is det.
%
%   Compile the tree Root into KB's tg_sort_/5 clause: an if-then-else per node, whose
%   condition proves the node's query (its path and its test) on the example's facts, each
%   part of it that shares no variable with the rest once (tg_bias:query_goal/6); and
%   its tg_leaves_/3 fact: the leaf ids left to right and the largest.

tg_compile_tree(KB, Root) :-
    copy_term(Root, Tree),
    tree_goal(Tree, [], Facts, Action, N, Leaf, Body),
    retractall(tg_sort_(KB, _, _, _, _)),
    assertz((tg_sort_(KB, Facts, Action, N, Leaf) :- Body)),
    findall(Id, tg_tree_leaf(Root, leaf(Id, _, _, _)), Ids),
    max_list(Ids, Max),
    retractall(tg_leaves_(KB, _, _)),
    assertz(tg_leaves_(KB, Ids, Max)).

tree_goal(leaf(Id, _, _, _), _, _, _, _, Leaf, Leaf = Id).
tree_goal(node(_, Lits, _, Yes, No), Path, F, A, N, Leaf, ( Cond -> GYes ; GNo )) :-
    append(Path, Lits, Path1),
    copy_term(Path1, Test),
    query_goal(Test, F, A, N, last, Cond),
    tree_goal(Yes, Path1, F, A, N, Leaf, GYes),
    tree_goal(No, Path, F, A, N, Leaf, GNo).

%!  tg_compile_leaf(+KB, +Leaf) is det.
%
%   Add the tg_cands_/6 clause of Leaf: it tests every candidate of the leaf on an example,
%   Hits listing the positions (from 1) of those that succeed, in order; and its tg_path_/5
%   clause: every solution of its path query (the action an open term the query binds; a
%   part of the query that shares no variable with the action proved once), on
%   an index of the facts (tg_bias:facts_index/2): with the action open, a literal is
%   proved once per solution of the literals before it, each a look-up.

tg_compile_leaf(KB, leaf(Id, PathLits0, _, Cands0)) :-
    copy_term(PathLits0, PathLits1),
    query_goal(PathLits1, PF, PA, PN, index, PathBody),
    assertz((tg_path_(KB, Id, PF, PA, PN) :- PathBody)),
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

%!  tg_forget_leaf(+KB, +LeafId) is det.
%
%   Remove the tg_cands_/6 and tg_path_/5 clauses of leaf LeafId (it was split).

tg_forget_leaf(KB, Id) :-
    retractall(tg_cands_(KB, Id, _, _, _, _)),
    retractall(tg_path_(KB, Id, _, _, _)).

%!  tg_forget_leaves(+KB) is det.
%
%   Remove every tg_cands_/6 and tg_path_/5 clause of KB (a new tree follows).

tg_forget_leaves(KB) :-
    retractall(tg_cands_(KB, _, _, _, _, _)),
    retractall(tg_path_(KB, _, _, _, _)).

%!  tg_forget(+KB) is det.
%
%   Remove KB's compiled tree and leaves (the learner forgets KB).

tg_forget(KB) :-
    retractall(tg_sort_(KB, _, _, _, _)),
    retractall(tg_leaves_(KB, _, _)),
    tg_forget_leaves(KB).

hits_body([], [], true).
hits_body([hit(I, G)|Gs], Hits, (( G -> Hits = [I|Hits1] ; Hits = Hits1 ), Body)) :-
    !,
    hits_body(Gs, Hits1, Body).
hits_body([G|Gs], Hits, (G, Body)) :-
    hits_body(Gs, Hits, Body).

%!  tg_tree_leaf(+Tree, ?Leaf) is nondet.
%
%   Leaf is a leaf of Tree, left to right.

tg_tree_leaf(L, L) :-
    L = leaf(_, _, _, _).
tg_tree_leaf(node(_, _, _, Y, N), L) :-
    (   tg_tree_leaf(Y, L)
    ;   tg_tree_leaf(N, L)
    ).

