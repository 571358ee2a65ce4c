:- module(relrl_tg_choice,
          [ tg_q/5,               % +KB, +Facts, +Action, +Necessity, -Q
            tg_choose/6,          % +KB, +Facts, +Necessity, +Allowed, +Mode, -Action
            tg_class_values/7,    % +KB, +Facts, +Necessity, +Allowed, +Scope, -Classes, -Qs
            tg_leaf_groups/3,     % +KB, +Scope, -Groups
            tg_bonus/5,           % +KB, +Facts, +Action, +Necessity, -Bonus
            tg_look_up/9,         % +KB, +D, +Facts, +N, +Allowed0, +Scope, -Allowed, -Classes, -Ids
            tg_leaf_q/3           % +Leaves, +Id, -Q
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(pairs)).
:- use_module(engine, [engine_all_allowed/2]).
:- use_module(choice).
:- use_module(tg_tree).
:- use_module(tg_classes).
:- use_module(world, [world_action_list/2]).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> TG's values and choices

How the TG learner (tg.pl) reads its tree: the Q of an example (tg_q/5), the choice of a
response or a world's action over classes of responses (tg_choose/6: Boltzmann, epsilon
or greedy, with the stale and novelty bonuses while learning), the classes' values a
Q-target reads (tg_class_values/7, tg_look_up/9) and the novelty bonus (tg_bonus/5). The
numbers read are the learner's (tg_tree.pl); nothing here changes the tree, only the
look-up cache the next update reuses (note_choice/5). tg.pl re-exports the public
predicates.
*/

%!  tg_q(+KB, +Facts, +Action, +Necessity, -Q) is det.
%
%   Q is the tree's estimate for Action in the state Facts under Necessity.

tg_q(KB, Facts, Action, N, Q) :-
    tg_sort_(KB, Facts, Action, N, Leaf),
    tg_leaf(KB, Leaf, L),
    arg(1, L, Q).

%!  tg_choose(+KB, +Facts, +Necessity, +Allowed, +Mode, -Action) is det.
%
%   Action is one of the Allowed responses, chosen over the *classes* of responses no test
%   of the language bias tells apart in the state Facts (tg_classes.pl): each class is
%   scored by one representative, a class is chosen, and a member of it uniformly. Allowed
%   is a list of responses, or a world's legal actions as a goal (actions(A, Goal),
%   world.pl): its greedy choice is over the leaves a legal action reaches, its exploring
%   choice over the classes of the legal actions (world_choose/7 below). With
%   Mode learn or explore: with temperature T > 0, a class is drawn with probability
%   proportional to exp(Q / T) (Boltzmann exploration); with T = 0, a random class with
%   probability epsilon and otherwise a greedy one. With Mode greedy, one with the largest
%   Q. Ties are broken at random. While learning (Mode learn), the Q of a leaf that no
%   example has reached for the last K examples inserted in the tree counts as Q +
%   stale_bonus * sqrt(K): a part of the Q-function that went stale while the rest moved is
%   tried again (the exploration bonus of Sutton's Dyna-Q+, here per leaf).
%
%   Directed exploration (novelty_bonus Beta > 0, Mode learn): Q(s, a) counts as
%   Q + tg_bonus/5, an upper confidence bound (UCB, optimism in the face of uncertainty)
%   over the tree's own partition of the space and its candidate refinements: the
%   regions (s, a) falls in are its leaf and the yes-side of every candidate test of that
%   leaf that succeeds on it; each region's bound is its mean TD error plus
%   novelty_confidence standard errors, capped at Beta, and Beta for a region fewer than
%   two examples have reached. A (s, a) in a rarely tried region, or in one whose TD
%   errors say the leaf's estimate may be too low there, is tried until the evidence is in
%   (a split, or a bound below 0). Counts are not tabular over ground states: one count
%   covers every (s, a) a test is true of — look where the caregiver looks, at any place.
%   Explore and greedy choices, and the Q-targets, never include either bonus.

tg_choose(KB, Facts, N, Allowed, Mode, Action) :-
    tg_data(KB, D),
    D = tg(p(_, _, _, _, _, _, _, _, novelty(Beta, _), _, _), _, _, _, _, _),
    (   Allowed = actions(_, _),                % a world's legal actions (world.pl)
        \+ ( Mode == learn, Beta > 0 )
    ->  world_choose(D, KB, Facts, N, Allowed, Mode, Action)
    ;   class_choose(D, KB, Facts, N, Allowed, Mode, Action)
    ).

%   The choice over classes found first (a domain's; a world's with the novelty bonus, which
%   each class's witness is tested for).
class_choose(D, KB, Facts, N, Allowed, Mode, Action) :-
    (   Allowed = actions(_, _)
    ->  true
    ;   Allowed = [_|_]
    ),
    D = tg(p(_, _, Epsilon, Tau, _, _, Kappa, Half, novelty(Beta, Conf), _, _), Leaves, Cache,
           Version, Clock, Index),
    tg_look_up(KB, D, Facts, N, Allowed, all, _, Classes, Ids),
    (   Mode \== greedy, Tau =:= 0,
        random_float < Epsilon
    ->  random_member(Class, Classes),
        Noted = none
    ;   (   Mode == learn, Beta > 0
        ->  maplist(novel_q(KB, Facts, N, Leaves, b(Kappa, Beta, Conf, Half, Clock)),
                    Classes, Ids, Qs, Items)
        ;   Mode == learn, Kappa > 0
        ->  maplist(bonus_q(Leaves, Kappa, Clock), Ids, Qs),
            Items = Classes
        ;   maplist(tg_leaf_q(Leaves), Ids, Qs),
            Items = Classes
        ),
        max_list(Qs, Best),
        (   Mode \== greedy, Tau > 0
        ->  softmax_member(Qs, Items, Best, Tau, Item)
        ;   ties(Qs, Items, Best, Ties),
            random_member(Item, Ties)
        ),
        (   Item = hits(Class, Leaf, Hits)
        ->  (   Class = cls(_, leaf(_, _, _, _, _, _))
            ->  Noted = none                    % the hits were the witness's, not the
            ;   Noted = chose(Action, Leaf, Hits)   % member's that is drawn
            )
        ;   Class = Item,
            Noted = none
        )
    ),
    tg_class_member(Index, Class, Action),
    (   Noted == none
    ->  true
    ;   note_choice(Cache, Facts, N, Version, Noted)
    ).

%   A world's choice (tg_classes:tg_leaf_search/5): the leaves' values are known without a
%   search, and a leaf is searched only when the choice needs it. Greedy: the leaves by
%   their value from the largest down, until a group of equal value has a class (ties at
%   random), and a member of it uniformly. Exploring is over the classes of the legal
%   actions that no test of the bias could tell apart (tg_symmetric/4; in blocks world the
%   single moves), as over a domain's classes of responses: Boltzmann (temperature > 0),
%   drawn exactly without valuing every legal action (boltzmann_action/9); epsilon
%   (temperature 0), a class uniformly. Exploring over the leaves instead would draw
%   exploration to the regions the tree already splits finely (docs/tg.md).
world_choose(D, KB, Facts, N, Actions, Mode, Action) :-
    D = tg(p(_, _, Epsilon, Tau, _, _, Kappa, _, _, _, _), Leaves, _, _, Clock, Index),
    tg_leaf_search(KB, Facts, N, Actions, Search),
    tg_leaves_(KB, Ids, _),
    (   Mode == learn, Kappa > 0
    ->  maplist(bonus_q(Leaves, Kappa, Clock), Ids, Qs)
    ;   maplist(tg_leaf_q(Leaves), Ids, Qs)
    ),
    pairs_keys_values(Valued, Qs, Ids),
    sort(1, @>=, Valued, ByQ),
    (   Mode \== greedy, Tau =:= 0,
        random_float < Epsilon
    ->  world_action_list(Actions, Legal),
        tg_symmetry(Index, Facts, Sym),
        uniform_class_action(Sym, Legal, Action)
    ;   Mode \== greedy, Tau > 0
    ->  tg_symmetry(Index, Facts, Sym),
        boltzmann_action(KB, Facts, N, Actions, Sym, Search, ByQ, Tau, Action)
    ;   q_groups(ByQ, Groups),
        tg_leaf_classes(Search, Groups, Ties, _),
        random_member(Class, Ties),
        tg_class_member(Index, Class, Action)
    ).

%   A class of the legal actions uniformly (the actions no test could tell apart, tg_classes'
%   signatures), then a member of it uniformly: a legal action uniformly, accepted with
%   probability 1 / the size of its class.
uniform_class_action(Sym, Legal, Action) :-
    random_member(A, Legal),
    tg_symmetric(Sym, A, Legal, K),
    (   random_float * K < 1
    ->  Action = A
    ;   uniform_class_action(Sym, Legal, Action)
    ).

%   Boltzmann over the classes of the legal actions, tg's choice over classes of responses
%   (tg_classes.pl: actions no test of the bias could tell apart in the state, which in
%   blocks world are the single moves), a class with probability proportional to
%   exp(Q / T) and a member uniformly: each legal action m with probability proportional to
%   w(m) / k(m), w(m) = exp((Q(m) - Q*) / T), Q(m) its leaf's value, Q* the best value a
%   legal action reaches, k(m) the size of its class (tg_symmetric/4). By rejection: a
%   proposal is, with probability 1/2 each, a member of the best leaves uniformly (the set
%   B) or a legal action uniformly (the world's list, M actions), so q(m) = [m in B] / 2|B|
%   + 1 / 2M; it is sorted to its leaf and accepted with probability w(m) / (k(m) C q(m)),
%   C = max(2|B|, 2M w2), w2 the weight of the next value a legal action reaches, so that
%   w(m) / k(m) <= C q(m) for every m: the action taken is drawn exactly. A proposal is
%   accepted with probability (sum over classes of w) / C: at least 1/2 when the classes
%   are single actions and the best leaves stand well above the rest (C = 2|B|), about the
%   mean weight over 2 w2 when they do not. Cost: the world's list, the members of the best
%   leaves, a sort per proposal (not every legal action valued).
boltzmann_action(KB, Facts, N, Actions, Sym, Search, ByQ, Tau, Action) :-
    q_groups(ByQ, Groups),
    reached_groups(Groups, ByQ, Search, Best-QBest, Next),
    findall(A, ( member(Id, Best),
                 tg_leaf_reached(Search, Id, C),
                 tg_class_members(C, Ms),
                 member(A, Ms) ), Members),
    length(Members, NB),
    world_action_list(Actions, Legal),
    length(Legal, M),
    (   Next = _-Q2
    ->  W2 is exp((Q2 - QBest) / Tau)
    ;   W2 = 0.0
    ),
    Bound is max(2 * NB, 2 * M * W2),
    Draw = draw(KB, Facts, N, Sym, ByQ, Tau, QBest, Best, Members, NB, Legal, M, Bound),
    propose(Draw, Action).

propose(Draw, Action) :-
    Draw = draw(KB, Facts, N, Sym, ByQ, Tau, QBest, Best, Members, NB, Legal, M, Bound),
    (   random_float < 0.5
    ->  random_member(A, Members)
    ;   random_member(A, Legal)
    ),
    tg_sort_(KB, Facts, A, N, Leaf),
    memberchk(Q-Leaf, ByQ),
    W is exp((Q - QBest) / Tau),
    (   memberchk(Leaf, Best)
    ->  QA is 0.5 / NB + 0.5 / M
    ;   QA is 0.5 / M
    ),
    tg_symmetric(Sym, A, Legal, K),
    (   random_float * Bound * QA * K < W
    ->  Action = A
    ;   propose(Draw, Action)
    ).

%   The reached leaves of the first group of leaves (by value, the largest first) that a
%   legal action reaches, with its value, and the value of the next such group (or none).
reached_groups(Groups, ByQ, Search, Best-QBest, Next) :-
    append(_, [Group|Rest], Groups),
    include(reached(Search), Group, Best),
    Best = [Id|_],
    !,
    memberchk(QBest-Id, ByQ),
    (   append(_, [G2|_], Rest),
        include(reached(Search), G2, [Id2|_])
    ->  memberchk(Q2-Id2, ByQ),
        Next = Id2-Q2
    ;   Next = none
    ).

reached(Search, Id) :-
    tg_leaf_reached(Search, Id, _).

%!  tg_class_values(+KB, +Facts, +Necessity, +Allowed, +Scope, -Classes, -Qs) is det.
%
%   Classes are the classes of the Allowed responses in the state Facts (every response
%   when Allowed is []), as tg_choose/6 chooses among them (cls(Representative, Pick)
%   terms, tg_classes.pl), and Qs their representatives' Q. Scope `all`: every class;
%   `best`: for a world's actions, only the classes of the largest Q (the other leaves of
%   the tree are not searched; a domain's classes are all found either way). The last
%   update's look-up of the same state is reused while the tree is unchanged.

tg_class_values(KB, Facts, N, Allowed, Scope, Classes, Qs) :-
    must_be(oneof([all, best]), Scope),
    tg_data(KB, D),
    tg_look_up(KB, D, Facts, N, Allowed, Scope, _, Classes, Ids),
    arg(2, D, Leaves),
    maplist(tg_leaf_q(Leaves), Ids, Qs).

%   Classes are the classes of the Allowed responses in the state Facts (every response
%   when Allowed0 is [], Allowed what was looked up) and Ids the leaves their
%   representatives sort to: the last update's look-up when it was of the same state,
%   necessity, responses and tree, else found (classes/8).
tg_look_up(KB, D, Facts, N, Allowed0, Scope, Allowed, Classes, Ids) :-
    D = tg(_, _, Cache, Version, _, Index),
    (   Allowed0 == []
    ->  tg_get_tree(KB, tree(_, _, _, Allowed))
    ;   Allowed = Allowed0
    ),
    (   Cache = last(F1, N1, A1, Classes0, Ids0, Version, _), F1 == Facts, N1 == N,
        A1 == Allowed
    ->  Classes = Classes0, Ids = Ids0
    ;   classes(KB, Index, Facts, N, Allowed, Scope, Classes, Ids)
    ).

%   The chosen action with the leaf and candidate hits of its class, found for its bonus,
%   noted in the cache the update of this step made (Cache, for the same state and tree):
%   the next update inserts this step's example — if the action emitted is the one chosen —
%   which sorts to that leaf and succeeds on those candidates (every member of a class
%   does), without testing them again.
note_choice(Cache, Facts, N, Version, Noted) :-
    (   Cache = last(F1, N1, _, _, _, Version, _), F1 == Facts, N1 == N
    ->  nb_setarg(7, Cache, Noted)
    ;   true
    ).

%   The classes of the Allowed responses in the state Facts and the leaves their
%   representatives sort to. A world's legal actions (actions(A, Goal), world.pl): the
%   leaves some legal action reaches (tg_leaf_classes/4), all of them (Scope `all`) or,
%   searching the leaves by their Q from the largest down, those of the largest Q that
%   some legal action reaches (Scope `best`: what a greedy choice and a Q-target read). A
%   domain's responses (Scope is not used): when no constraint rule forbids a response
%   (Allowed is the engine's own list of every response) the classes come from the index
%   without a pass over the responses.
classes(KB, Index, Facts, N, Allowed, Scope, Classes, Ids) :-
    (   Allowed = actions(_, _)
    ->  tg_leaf_groups(KB, Scope, Groups),
        tg_leaf_search(KB, Facts, N, Allowed, Search),
        tg_leaf_classes(Search, Groups, Classes, Ids)
    ;   engine_all_allowed(KB, Allowed)
    ->  tg_classes(Index, Facts, Allowed, true, Classes),
        maplist(class_leaf(KB, Facts, N), Classes, Ids)
    ;   tg_classes(Index, Facts, Allowed, false, Classes),
        maplist(class_leaf(KB, Facts, N), Classes, Ids)
    ).

%!  tg_leaf_groups(+KB, +Scope, -Groups:list) is det.
%
%   Groups are the leaves of KB's tree to search for classes of a world's actions
%   (tg_classes:tg_leaf_classes/4): Scope `all`, every leaf in one group; `best`, the leaves
%   grouped by their Q, the largest first (leaves of one Q in tree order).

tg_leaf_groups(KB, Scope, Groups) :-
    must_be(oneof([all, best]), Scope),
    tg_leaves_(KB, Ids, _),
    (   Scope == all
    ->  Groups = [Ids]
    ;   tg_data(KB, D),
        arg(2, D, Leaves),
        maplist(tg_leaf_q(Leaves), Ids, Qs),
        pairs_keys_values(Keyed, Qs, Ids),
        sort(1, @>=, Keyed, ByQ),                   % stable: one value in tree order
        q_groups(ByQ, Groups)
    ).

q_groups([], []).
q_groups([Q-Id|More], [[Id|Ids]|Groups]) :-
    same_q(More, Q, Ids, Rest),
    q_groups(Rest, Groups).

same_q([], _, [], []).
same_q([Q1-Id|More], Q, Ids, Rest) :-
    (   Q1 =:= Q
    ->  Ids = [Id|Ids1],
        same_q(More, Q, Ids1, Rest)
    ;   Ids = [],
        Rest = [Q1-Id|More]
    ).

class_leaf(KB, Facts, N, cls(A, _), Leaf) :-
    tg_sort_(KB, Facts, A, N, Leaf).

tg_leaf_q(Leaves, Id, Q) :-
    arg(Id, Leaves, L),
    arg(1, L, Q).

bonus_q(Leaves, Kappa, Clock, Id, Q) :-
    arg(Id, Leaves, L),
    arg(1, L, Q0),
    arg(7, L, Last),
    Q is Q0 + Kappa * sqrt(max(0, Clock - Last)).

novel_q(KB, Facts, N, Leaves, b(Kappa, Beta, Conf, Half, Clock), Class, Id, Q,
        hits(Class, Id, Hits)) :-
    Class = cls(A, _),
    arg(Id, Leaves, L),
    arg(1, L, Q0),
    arg(7, L, Last),
    novelty(KB, Facts, A, N, Id, L, u(Beta, Conf, Half, Clock), Hits, Bonus),
    Q is Q0 + Kappa * sqrt(max(0, Clock - Last)) + Bonus.

%!  tg_bonus(+KB, +Facts, +Action, +Necessity, -Bonus:number) is det.
%
%   Bonus is the novelty bonus the example (Facts, Action, Necessity) gets while learning
%   (tg_choose/6; 0 when novelty_bonus is 0).

tg_bonus(KB, Facts, A, N, Bonus) :-
    tg_data(KB, tg(p(_, _, _, _, _, _, _, Half, novelty(Beta, Conf), _, _), Leaves, _, _, Clock,
                   _)),
    (   Beta > 0
    ->  tg_sort_(KB, Facts, A, N, Id),
        arg(Id, Leaves, L),
        novelty(KB, Facts, A, N, Id, L, u(Beta, Conf, Half, Clock), _, Bonus)
    ;   Bonus = 0
    ).

%   The regions of leaf Id's partition the example falls in are the leaf itself and the
%   yes-side of every candidate test that succeeds on it. For each, the counts, sums and
%   sums of squares the leaf keeps give n (today's weights), Mean and Var of its TD errors;
%   its upper confidence bound is Mean + Conf * sqrt(Var / n), capped at Beta, and Beta
%   when n < 2. The bonus is the largest bound, and 0 when all are below 0. Hits are the
%   candidates that succeed on the example.
novelty(KB, Facts, A, N, Id, L, u(Beta, Conf, Half, Clock), Hits, Bonus) :-
    L = l(_, _, M, S, SS, C, _, Base, _),
    (   Half =:= 0
    ->  W = 1
    ;   W is 2 ** ((Clock - Base) / Half)       % stored units / W = today's weights
    ),
    U = u(W, Conf, Beta),
    ucb(U, M, S, SS, 0, B0),
    tg_cands_(KB, Id, Facts, A, N, Hits),
    ucb_hits(Hits, C, U, B0, Bonus).

ucb_hits([], _, _, B, B).
ucb_hits([I|Is], C, U, B0, B) :-
    (   U = u(_, _, Beta), B0 >= Beta
    ->  B = B0                                  % capped: nothing can be larger
    ;   J is 3 * I - 2,
        arg(J, C, M), J2 is J + 1, arg(J2, C, S), J3 is J + 2, arg(J3, C, SS),
        ucb(U, M, S, SS, B0, B1),
        ucb_hits(Is, C, U, B1, B)
    ).

%   With counts M in stored units (today's n = M / W): Mean = S / M and
%   Var / n = W * (SS * M - S^2) / M^3.
ucb(u(W, Conf, Beta), M, S, SS, B0, B) :-
    (   M < 2 * W
    ->  B is max(B0, Beta)
    ;   B is max(B0, min(Beta, (S + Conf * sqrt(max(0.0, W * (SS * M - S * S) / M))) / M))
    ).

