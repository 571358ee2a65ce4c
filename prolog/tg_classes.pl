:- module(relrl_tg_classes,
          [ tg_response_index/3,  % +Bias, +Responses, -Index
            tg_classes/5,         % +Index, +Facts, +Allowed, +All, -Classes
            tg_leaf_search/5,     % +KB, +Facts, +Necessity, +Actions, -Search
            tg_leaf_reached/3,    % +Search, +LeafId, -Class
            tg_leaf_classes/4,    % +Search, +Groups, -Classes, -LeafIds
            tg_class_member/3,    % +Index, +Class, -Action
            tg_class_members/2,   % +Class, -Actions
            tg_class_size/3,      % +Index, +Class, -Size
            tg_signature/3,       % +Response, +Known, -Signature
            tg_symmetry/3,        % +Index, +Facts, -Symmetry
            tg_symmetric/4        % +Symmetry, +Action, +Actions, -Count
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(library(assoc)).
:- use_module(library(random)).
:- use_module(tg_bias, [bias_constants/2, term_constant/2, facts_index/2]).
:- use_module(tg_tree, [tg_sort_/5, tg_path_/5, tg_leaves_/3]).

/** <module> Classes of responses the TG learner cannot tell apart

A test of the language bias sees a constant of the world only if the bias names it (rconst/2,
a constant in an rmode/1 template, a necessity) or the relational state holds it. Two
responses that differ only in constants that neither the bias nor the state names — look(P)
and look(Q) for two places nothing in the state mentions — are told apart by no test the
tree has and by none it could grow: swapping the two constants maps the example of one to
the example of the other and leaves every test's answer as it was. They are one *class*:
they sort to the same leaf, succeed on the same candidate tests, have the same Q and the
same exploration bonus.

The learner chooses over classes (tg_choice.pl): each class is scored by one representative, the
choice among classes is Boltzmann (or greedy), and within the chosen class a member is drawn
uniformly. With a world of P places and a state that mentions a few of them, there are a
few classes whatever P is: "look at one of the places nothing is at" is one choice, not P
of them.

**Cost.** The index (tg_response_index/3) is built once: every response's *signature* (its
arguments with the constants the bias does not name replaced by numbered placeholders)
groups the responses, and each constant points to the responses it occurs in. A step's
classes (tg_classes/5) then cost a look-up per constant of the state: the responses the
state names are grouped by their signature given the state, and every group of the index
keeps the rest as one class ("all but these"), drawn from by rejection. No pass over the
responses, unless constraint rules allow only some of them (then the allowed ones are
grouped one by one).

**A world's actions: classes are leaves.** A world (world.pl) declares no responses: the
actions legal in a state come with it, as a goal that binds an action template to each
(actions(A, Goal), world_actions/3). Every object of a world is in its state (a block
appears in on/2), so no two ground actions share a signature and a class of signatures
would be one action: N blocks on the floor have N(N - 1) moves. What the learner reads
of an action is the leaf of its Q-tree it sorts to, so its classes are the leaves that
some legal action reaches, found without listing the actions (tg_leaf_search/5): a leaf's
path query (its tests on the yes-branches, tg_path_/5) is proved with the action open,
which binds the action's arguments from the state's facts (action(move(B, floor)),
on(B1, floor) ...), the world's goal completes the action (precondition/2 with a partly
bound template), and the action is sorted down the tree (tg_sort_/5, which also holds the
tests of the no-branches). Every action so sorted marks the leaf it reaches, a leaf's search
stops at the first action that reaches it, and a leaf is searched at most once per state
and tree, only when asked about (tg_leaf_reached/3): a greedy choice or a Q-target asks
about the leaves from the largest Q down (tg_leaf_classes/4), a Boltzmann choice about the
leaves it draws (tg.pl). A class is cls(Witness, leaf(...)), scored by its leaf's Q; its
member is drawn uniformly among the legal actions that reach its leaf (tg_class_member/3:
the leaf's path query, the world's goal and the sort enumerate them).

**Cost of a world's classes.** A leaf whose path query binds the action's arguments costs
the solutions of that query; one whose path binds none (below the root's no-branch: the
world's goal alone proposes actions) costs as many legal actions as come before the first
that reaches it, all of them when none does. Drawing a member lists the chosen class
(docs/tg.md, *Classes of a world's actions*).
*/

%!  tg_response_index(+Bias, +Responses:list, -Index) is det.
%
%   Index is the response index of a domain with language bias Bias (tg_bias:tg_bias/2)
%   and Responses (declaration order): rindex(Rs, Known, Groups, GroupOf, Atoms) with
%   Rs = r(R1, ..., Rn), Known an assoc of the constants the bias names, Groups =
%   g(grp(Members, Size), ...) the responses grouped by their signature given Known
%   (Members = m(I1, ...), response positions in increasing order), GroupOf the group of
%   each response, Atoms an assoc from each constant the bias does not name to the
%   positions of the responses it occurs in.

tg_response_index(Bias, Responses, rindex(Rs, Known, Groups, GroupOf, Atoms)) :-
    must_be(list, Responses),
    bias_constants(Bias, Consts),
    list_to_assoc_set(Consts, Known),
    Rs =.. [r|Responses],
    findall(Sig-I, ( nth1(I, Responses, R), tg_signature(R, known(Known, []), Sig) ),
            Pairs),
    group_in_order(Pairs, GroupLists),
    length(GroupLists, K),
    length(Responses, N),
    functor(GroupOf, go, N),
    foldl(fill_group(GroupOf), GroupLists, GroupTerms, 1, _),
    Groups =.. [g|GroupTerms],
    findall(A-I, ( nth1(I, Responses, R), term_constant(R, A),
                   \+ get_assoc(A, Known, _) ), AIs0),
    sort(AIs0, AIs),
    group_pairs_by_key(AIs, ByAtom),
    list_to_assoc(ByAtom, Atoms),
    must_be(nonneg, K).

fill_group(GroupOf, Members, grp(M, Size), G, G1) :-
    G1 is G + 1,
    forall(member(I, Members), nb_setarg(I, GroupOf, G)),
    M =.. [m|Members],
    length(Members, Size).

list_to_assoc_set(Xs, Assoc) :-
    sort(Xs, Set),
    findall(X-true, member(X, Set), Pairs),
    list_to_assoc(Pairs, Assoc).

%   Sig-I pairs grouped by Sig, groups in the order of their first member.
group_in_order(Pairs, Groups) :-
    findall(Sig-(First-Is),
            ( member(Sig0-First, Pairs),
              \+ ( member(S1-I1, Pairs), I1 < First, S1 =@= Sig0 ),
              Sig = Sig0,
              findall(I, ( member(S2-I, Pairs), S2 =@= Sig0 ), Is) ),
            Keyed),
    findall(Is, member(_-(_-Is), Keyed), Groups).

%!  tg_signature(+Response, +Known, -Signature) is det.
%
%   Signature is Response with every constant at an argument position that Known does not
%   name replaced by '$other'(K), K numbering the distinct ones from 1 in order of first
%   occurrence: two responses with the same signature are told apart by no test of the
%   bias. Known is known(Assoc, Extra): the constants of Assoc and of the list Extra.

tg_signature(R, Known, Sig) :-
    (   compound(R)
    ->  R =.. [F|Args],
        foldl(sig_arg(Known), Args, SArgs, [], _),
        Sig =.. [F|SArgs]
    ;   Sig = R
    ).

sig_arg(Known, X, S, Map0, Map) :-
    (   compound(X)
    ->  X =.. [F|Args],
        foldl(sig_arg(Known), Args, SArgs, Map0, Map),
        S =.. [F|SArgs]
    ;   known(Known, X)
    ->  S = X, Map = Map0
    ;   memberchk(X-K, Map0)
    ->  S = '$other'(K), Map = Map0
    ;   length(Map0, L),
        K is L + 1,
        S = '$other'(K),
        Map = [X-K|Map0]
    ).

known(known(Assoc, Extra), X) :-
    (   get_assoc(X, Assoc, _)
    ->  true
    ;   memberchk(X, Extra)
    ).

%!  tg_classes(+Index, +Facts:list, +Allowed:list, +All:boolean, -Classes:list) is det.
%
%   Classes partitions the Allowed responses in the state Facts into classes no test of the
%   bias tells apart: cls(Rep, Pick), Rep the representative the class is scored by, Pick
%   how to draw a member: one (Rep itself), among(Positions) (uniformly) or rest(Group,
%   Excluded) (uniformly among the members of Group not in Excluded). All = true says
%   Allowed are all the responses (no constraint rule forbids one): the classes then come
%   from the index, without a pass over the responses. (A world's actions, which come with
%   each state, are classed by tg_leaf_search/5.) Classes are in a fixed order: the
%   index's groups, then the responses the state names by their first position.

tg_classes(rindex(Rs, Known, Groups, GroupOf, Atoms), Facts, Allowed, All, Classes) :-
    state_atoms(Facts, Known, StateAtoms),
    Known1 = known(Known, StateAtoms),
    (   All == true
    ->  named_positions(StateAtoms, Atoms, Named),
        functor(Groups, _, K),
        rest_classes(1, K, Groups, GroupOf, Rs, Named, Rest),
        maplist(position_sig(Rs, Known1), Named, Pairs),
        sig_classes(Pairs, Rs, NamedClasses),
        append(Rest, NamedClasses, Classes)
    ;   allowed_pairs(Allowed, Rs, 1, Known1, Pairs),
        sig_classes(Pairs, Rs, Classes)
    ).

%   The constants of the state the bias does not name, sorted.
state_atoms(Facts, Known, Atoms) :-
    findall(A, ( member(F, Facts), term_constant(F, A), \+ get_assoc(A, Known, _) ), As),
    sort(As, Atoms).

%   The positions of the responses a constant of the state occurs in, sorted.
named_positions(StateAtoms, Atoms, Named) :-
    findall(I, ( member(A, StateAtoms), get_assoc(A, Atoms, Is), member(I, Is) ), Is0),
    sort(Is0, Named).

%   For each group of the index: the members the state does not name form one class
%   (when there are any).
rest_classes(G, K, Groups, GroupOf, Rs, Named, Classes) :-
    (   G > K
    ->  Classes = []
    ;   arg(G, Groups, grp(Members, Size)),
        include(in_group(GroupOf, G), Named, Excluded),
        length(Excluded, E),
        (   Size > E
        ->  first_free(Members, 1, Excluded, I),
            arg(I, Rs, Rep),
            (   Size - E =:= 1
            ->  Pick = one
            ;   Pick = rest(G, Excluded)
            ),
            Classes = [cls(Rep, Pick)|Classes1]
        ;   Classes = Classes1
        ),
        G1 is G + 1,
        rest_classes(G1, K, Groups, GroupOf, Rs, Named, Classes1)
    ).

in_group(GroupOf, G, I) :-
    arg(I, GroupOf, G).

first_free(Members, J, Excluded, I) :-
    arg(J, Members, I0),
    (   memberchk(I0, Excluded)
    ->  J1 is J + 1,
        first_free(Members, J1, Excluded, I)
    ;   I = I0
    ).

position_sig(Rs, Known, I, Sig-I) :-
    arg(I, Rs, R),
    tg_signature(R, Known, Sig).

%   Sig-Position pairs (positions increasing) grouped into classes, in order of first
%   position.
sig_classes(Pairs, Rs, Classes) :-
    sig_groups(Pairs, Groups),
    maplist(group_class(Rs), Groups, Classes).

sig_groups([], []).
sig_groups([Sig-I|Pairs], [[I|Is]|Groups]) :-
    partition(same_sig(Sig), Pairs, Same, Other),
    pairs_values(Same, Is),
    sig_groups(Other, Groups).

same_sig(Sig, S-_) :-
    S =@= Sig.

group_class(Rs, [I|Is], cls(Rep, Pick)) :-
    arg(I, Rs, Rep),
    (   Is == []
    ->  Pick = one
    ;   Pick = among([I|Is])
    ).

%!  tg_leaf_search(+KB, +Facts, +Necessity, +Actions, -Search) is det.
%
%   Search is a search of the leaves of KB's tree that a world's legal actions reach in
%   the state Facts (Actions = actions(A, Goal), Goal binding A to each legal action,
%   world_actions/3): tg_leaf_reached/3 and tg_leaf_classes/4 ask it about leaves, and a
%   leaf is searched at most once per Search, when first asked about or when an action
%   found for another leaf reaches it.

tg_leaf_search(KB, Facts, N, Actions, search(KB, Facts, Index, N, Actions, Seen)) :-
    must_be(compound, Actions),
    facts_index(Facts, Index),          % the path queries' look-ups (tg_tree:tg_path_/5)
    tg_leaves_(KB, _, Max),
    functor(Seen, seen, Max).           % per leaf: unknown (a variable), w(Witness), empty

%!  tg_leaf_reached(+Search, +LeafId, -Class) is semidet.
%
%   Some legal action reaches leaf LeafId; Class is its class, cls(Witness, leaf(KB,
%   LeafId, Facts, Index, Necessity, Actions)), Witness the first such action found (Index:
%   the search's index of Facts).

tg_leaf_reached(Search, Id, cls(W, leaf(KB, Id, Facts, Index, N, Actions))) :-
    Search = search(KB, Facts, Index, N, Actions, Seen),
    search_leaf(Search, Id),
    arg(Id, Seen, w(W)).

%!  tg_leaf_classes(+Search, +Groups:list, -Classes:list, -LeafIds:list) is det.
%
%   Groups is a list of lists of leaf ids, searched in turn: Classes are the classes of the
%   first group that has any (tg_leaf_reached/3), in the group's order, LeafIds their
%   leaves; [] when no group has one. Every leaf in one group: all the classes; the leaves
%   grouped by their Q, the largest first: the classes of the largest Q, without searching
%   the leaves below it.

tg_leaf_classes(Search, Groups, Classes, Ids) :-
    first_group(Groups, Search, Pairs),
    pairs_keys_values(Pairs, Ids, Classes).

first_group([], _, []).
first_group([Group|Groups], Search, Pairs) :-
    findall(Id-C, ( member(Id, Group), tg_leaf_reached(Search, Id, C) ), Pairs0),
    (   Pairs0 == []
    ->  first_group(Groups, Search, Pairs)
    ;   Pairs = Pairs0
    ).

%   Unless leaf Id was searched or is known to be reached: the candidates of its path
%   query, completed by the world and sorted, each marking the leaf it reaches, until one
%   reaches Id; none: Id is empty.
search_leaf(search(KB, Facts, Index, N, actions(A, Goal), Seen), Id) :-
    arg(Id, Seen, S),
    (   nonvar(S)
    ->  true
    ;   \+ \+ ( tg_path_(KB, Id, Index, A, N),    % (the bindings are undone: \+ \+)
                call(Goal),
                tg_sort_(KB, Facts, A, N, Leaf),
                arg(Leaf, Seen, S1),
                (   var(S1)
                ->  nb_setarg(Leaf, Seen, w(A))
                ;   true
                ),
                Leaf == Id )
    ->  true
    ;   nb_setarg(Id, Seen, empty)
    ).

%!  tg_symmetry(+Index, +Facts, -Symmetry) is det.
%
%   Symmetry is what tg_symmetric/4 needs to tell, in the state Facts, which actions no
%   test of the bias could tell apart: the constants the bias or the state names, and room
%   for the sizes of the classes of one draw's legal actions (counted once, when first
%   needed).

tg_symmetry(rindex(_, Known, _, _, _), Facts, sym(known(Known, StateAtoms), sizes(none))) :-
    state_atoms(Facts, Known, StateAtoms).

%!  tg_symmetric(+Symmetry, +Action, +Actions:list, -Count:integer) is det.
%
%   Count is the number of Actions (a world's legal actions, the same list at every call
%   with one Symmetry) with Action's signature: the actions no test of the bias could tell
%   from Action in the state (they differ only in constants neither the bias nor the state
%   names). 1 without a look at Actions when every constant of Action is named (every block
%   of blocks world is in its state); otherwise the actions' signatures are counted at the
%   first such call, one pass, and looked up afterwards.

tg_symmetric(sym(Known, Sizes), Action, Actions, Count) :-
    (   \+ ( term_constant(Action, C), \+ known(Known, C) )
    ->  Count = 1
    ;   arg(1, Sizes, Counted0),
        (   Counted0 == none
        ->  findall(Sig, ( member(B, Actions), tg_signature(B, Known, Sig) ), Sigs),
            msort(Sigs, Sorted),
            clumped(Sorted, Pairs),
            list_to_assoc(Pairs, Counted),
            nb_setarg(1, Sizes, Counted)
        ;   Counted = Counted0
        ),
        tg_signature(Action, Known, Sig),
        get_assoc(Sig, Counted, Count)
    ).

%!  tg_class_members(+Class, -Actions:list) is det.
%
%   Actions are the members of a leaf class (tg_leaf_search/5), the legal actions that
%   reach its leaf, in standard order: its path query, the world's goal and the sort
%   enumerate them.

tg_class_members(cls(_, Pick), Members) :-
    leaf_members(Pick, Members).

leaf_members(leaf(KB, Id, Facts, Index, N, actions(A, Goal)), Members) :-
    findall(A, ( tg_path_(KB, Id, Index, A, N),
                 call(Goal),
                 tg_sort_(KB, Facts, A, N, Id) ),
            Members0),
    sort(Members0, Members).

%   Sig-Position pairs of the Allowed responses (a sub-list of the responses, in their
%   order: one walk along both).
allowed_pairs([], _, _, _, []).
allowed_pairs([R|Rs0], Rs, I, Known, [Sig-J|Pairs]) :-
    next_position(Rs, R, I, J),
    tg_signature(R, Known, Sig),
    J1 is J + 1,
    allowed_pairs(Rs0, Rs, J1, Known, Pairs).

next_position(Rs, R, I, J) :-
    (   arg(I, Rs, R1)
    ->  (   R1 == R
        ->  J = I
        ;   I1 is I + 1,
            next_position(Rs, R, I1, J)
        )
    ;   domain_error(allowed_response, R)
    ).

%!  tg_class_member(+Index, +Class, -Action) is det.
%
%   Action is a member of Class drawn uniformly (library(random)); of a leaf class
%   (tg_leaf_search/5), uniformly among the legal actions that reach the leaf.

tg_class_member(rindex(Rs, _, Groups, _, _), cls(Rep, Pick), Action) :-
    (   Pick == one
    ->  Action = Rep
    ;   Pick = among(Is)
    ->  random_member(I, Is),
        arg(I, Rs, Action)
    ;   Pick = leaf(_, _, _, _, _, _)
    ->  leaf_members(Pick, Members),
        random_member(Action, Members)
    ;   Pick = rest(G, Excluded),
        arg(G, Groups, grp(Members, Size)),
        draw_free(Members, Size, Excluded, I),
        arg(I, Rs, Action)
    ).

%   Rejection: the excluded members are few (those the state names).
draw_free(Members, Size, Excluded, I) :-
    random_between(1, Size, J),
    arg(J, Members, I0),
    (   memberchk(I0, Excluded)
    ->  draw_free(Members, Size, Excluded, I)
    ;   I = I0
    ).

%!  tg_class_size(+Index, +Class, -Size:integer) is det.
%
%   Size is the number of responses in Class.

tg_class_size(rindex(_, _, Groups, _, _), cls(_, Pick), Size) :-
    (   Pick == one
    ->  Size = 1
    ;   Pick = among(Is)
    ->  length(Is, Size)
    ;   Pick = leaf(_, _, _, _, _, _)
    ->  leaf_members(Pick, Members),
        length(Members, Size)
    ;   Pick = rest(G, Excluded),
        arg(G, Groups, grp(_, GSize)),
        length(Excluded, E),
        Size is GSize - E
    ).
