:- module(relrl_qtree,
          [ qtree_new/2,          % +Tree, +Tests
            qtree_tests/2,        % +Tree, -Tests
            qtree_sort/3,         % +Tree, +Description, -Where
            qtree_leaf/4,         % +Tree, ?Id, -Rep, -Entries
            qtree_set_leaf/4,     % +Tree, +Id, +Rep, +Entries
            qtree_grow/6,         % +Tree, +Parent, +Branch, +Rep, +Entries, -Id
            qtree_split/3,        % +Tree, +LeafId, +TestIndex
            qtree_path/3,         % +Tree, +Description, -Path
            qtree_size/4,         % +Tree, -Nodes, -Leaves, -Entries
            qtree_node/3,         % +Tree, ?Id, ?Node
            qtree_clear/1,        % +Tree
            qtree_format/2,       % +Tree, -Text
            qtree_graph/2,        % +Tree, -Graph
            qtree_restore/3,      % +Tree, +Tests, +Nodes
            qtree_put_entry/3,    % +Entries0, +Entry, -Entries
            qtree_entry_q/5,      % +Entries, +Action, +Necessity, +Default, -Q
            test_holds/2,         % +Description, +TestIndex
            first_difference/3    % +Description1, +Description2, -TestIndex
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).

/** <module> Relational Q-trees

The tree shared by relrl's tree learners (ETG now; a full TG learner can use the same
structure). Internal nodes hold first-order tests — goals such as fact(frontal(face)) or
stimulus(toy), taken from a list of candidate tests — and two branches; a branch may be
`nil` (Algorithm 3's *null*: no example has gone that way yet). Leaves hold entries
e(Action, Q, Necessity), kept in decreasing Q, and the description of the first state that
reached them (their representative).

A state is sorted down the tree by its *description*: an integer whose bit i is set when
test i held when the state was perceived. The tests were run as Prolog goals against working
memory at that moment (relrl_engine), so a state can still be sorted after memory has moved
on (to update the previous step's example).

Nodes are node_(Tree, Id, Node) facts with Node = test(Index, Goal, Yes, No) or
leaf(Rep, Entries); Rep is `none` until the first example arrives. Id 0 is the root.
*/

:- dynamic
    node_/3,        % Tree, Id, Node
    next_id_/2,     % Tree, NextId
    tests_/2.       % Tree, Tests

%!  qtree_new(+Tree, +Tests:list) is det.
%
%   Make Tree a single empty leaf with the candidate Tests (goals, in index order).

qtree_new(Tree, Tests) :-
    must_be(list, Tests),
    qtree_clear(Tree),
    assertz(tests_(Tree, Tests)),
    assertz(node_(Tree, 0, leaf(none, []))),
    assertz(next_id_(Tree, 1)).

%!  qtree_restore(+Tree, +Tests, +Nodes:list) is det.
%
%   Make Tree the tree given by Nodes, a list of Id-Node pairs as saved by the engine.
%
%   @error domain_error(qtree, Nodes) if there is no root (Id 0).

qtree_restore(Tree, Tests, Nodes) :-
    must_be(list, Nodes),
    (   memberchk(0-_, Nodes)
    ->  true
    ;   domain_error(qtree, Nodes)
    ),
    qtree_clear(Tree),
    assertz(tests_(Tree, Tests)),
    forall(member(Id-Node, Nodes), assertz(node_(Tree, Id, Node))),
    aggregate_all(max(Id), member(Id-_, Nodes), Max),
    Next is Max + 1,
    assertz(next_id_(Tree, Next)).

%!  qtree_clear(+Tree) is det.
%
%   Forget Tree.

qtree_clear(Tree) :-
    must_be(atom, Tree),
    memo_key(Tree, Key),
    nb_setval(Key, none),
    retractall(node_(Tree, _, _)),
    retractall(next_id_(Tree, _)),
    retractall(tests_(Tree, _)).

%!  qtree_tests(+Tree, -Tests:list) is det.

qtree_tests(Tree, Tests) :-
    tests_(Tree, Tests).

%!  qtree_node(+Tree, ?Id, ?Node) is nondet.

qtree_node(Tree, Id, Node) :-
    (   integer(Id)
    ->  once(node_(Tree, Id, Node))
    ;   node_(Tree, Id, Node)
    ).

%!  test_holds(+Description, +Index) is semidet.

test_holds(D, I) :-
    D /\ (1 << I) =\= 0.

%!  first_difference(+D1, +D2, -Index) is semidet.
%
%   Index is the first test (lowest index) on which two descriptions differ.

first_difference(D1, D2, Index) :-
    X is D1 xor D2,
    X =\= 0,
    Index is lsb(X).

%!  qtree_sort(+Tree, +Description, -Where) is det.
%
%   Sort a state down Tree. Where is leaf(Id), or null(Parent, Branch) when the state
%   reaches an empty branch (Branch is yes or no).

qtree_sort(Tree, D, Where) :-
    memo_key(Tree, Key),
    next_id_(Tree, Version),
    (   nb_current(Key, memo(Version, D1-W1, D2-W2))
    ->  (   D1 =:= D
        ->  Where = W1
        ;   D2 =:= D
        ->  Where = W2
        ;   sort_from(Tree, 0, D, Where),
            nb_setval(Key, memo(Version, D-Where, D1-W1))
        )
    ;   sort_from(Tree, 0, D, Where),
        nb_setval(Key, memo(Version, D-Where, -1-none))
    ).

%   The last two states sorted and where they went, valid while the tree's shape is the
%   same (every grow or split takes a new node id, so the next id is the shape's version):
%   the control step sorts each state twice (to choose, then to learn from it).
memo_key(Tree, Key) :-
    (   memo_key_(Tree, Key0)
    ->  Key = Key0
    ;   atom_concat('$relrl_qsort:', Tree, Key),
        assertz(memo_key_(Tree, Key))
    ).

:- dynamic memo_key_/2.

sort_from(Tree, Id, D, Where) :-
    (   step_down(Tree, Id, D, _, Branch, Next)
    ->  (   Next == nil
        ->  Where = null(Id, Branch)
        ;   sort_from(Tree, Next, D, Where)
        )
    ;   Where = leaf(Id)
    ).

%   Id is a test node; the state described by D takes its Branch (yes or no) to Next.
step_down(Tree, Id, D, Goal, Branch, Next) :-
    once(node_(Tree, Id, test(I, Goal, Yes, No))),
    (   test_holds(D, I)
    ->  Branch = yes, Next = Yes
    ;   Branch = no, Next = No
    ).

%!  qtree_path(+Tree, +Description, -Path:list) is det.
%
%   Path lists Goal-Outcome pairs (Outcome true or false) from the root to where the state
%   ends, followed by leaf(Id) or null.

qtree_path(Tree, D, Path) :-
    path_from(Tree, 0, D, Path).

path_from(Tree, Id, D, Path) :-
    (   step_down(Tree, Id, D, Goal, Branch, Next)
    ->  ( Branch == yes -> Outcome = true ; Outcome = false ),
        Path = [Goal-Outcome|Rest],
        (   Next == nil
        ->  Rest = [null]
        ;   path_from(Tree, Next, D, Rest)
        )
    ;   Path = [leaf(Id)]
    ).

%!  qtree_leaf(+Tree, ?Id, -Rep, -Entries) is nondet.

qtree_leaf(Tree, Id, Rep, Entries) :-
    (   integer(Id)
    ->  once(node_(Tree, Id, leaf(Rep, Entries)))
    ;   node_(Tree, Id, leaf(Rep, Entries))
    ).

%!  qtree_set_leaf(+Tree, +Id, +Rep, +Entries) is det.

qtree_set_leaf(Tree, Id, Rep, Entries) :-
    retract(node_(Tree, Id, leaf(_, _))),
    !,
    assertz(node_(Tree, Id, leaf(Rep, Entries))).
qtree_set_leaf(Tree, Id, _, _) :-
    existence_error(qtree_leaf, Tree-Id).

new_id(Tree, Id) :-
    once(retract(next_id_(Tree, Id))),
    Id1 is Id + 1,
    assertz(next_id_(Tree, Id1)).

%!  qtree_grow(+Tree, +Parent, +Branch, +Rep, +Entries, -Id) is det.
%
%   Generate a leaf on the empty Branch (yes or no) of the test node Parent.

qtree_grow(Tree, Parent, Branch, Rep, Entries, Id) :-
    must_be(oneof([yes, no]), Branch),
    once(retract(node_(Tree, Parent, test(I, Goal, Yes, No)))),
    new_id(Tree, Id),
    (   Branch == yes
    ->  must_be(oneof([nil]), Yes), Node = test(I, Goal, Id, No)
    ;   must_be(oneof([nil]), No), Node = test(I, Goal, Yes, Id)
    ),
    assertz(node_(Tree, Parent, Node)),
    assertz(node_(Tree, Id, leaf(Rep, Entries))).

%!  qtree_split(+Tree, +LeafId, +TestIndex) is det.
%
%   Turn leaf LeafId into a test node on test TestIndex. The leaf moves to the branch its
%   representative takes; the other branch is empty (nil).

qtree_split(Tree, LeafId, I) :-
    once(retract(node_(Tree, LeafId, leaf(Rep, Entries)))),
    tests_(Tree, Tests),
    nth0(I, Tests, Goal),
    new_id(Tree, Id),
    (   test_holds(Rep, I)
    ->  Node = test(I, Goal, Id, nil)
    ;   Node = test(I, Goal, nil, Id)
    ),
    assertz(node_(Tree, LeafId, Node)),
    assertz(node_(Tree, Id, leaf(Rep, Entries))).

%!  qtree_size(+Tree, -Nodes, -Leaves, -Entries) is det.
%
%   Nodes counts internal nodes and leaves; Entries the stored (action, Q, necessity)
%   entries. The paper's memory in "positions" is Nodes + Entries.

qtree_size(Tree, Nodes, Leaves, Entries) :-
    aggregate_all(count, node_(Tree, _, _), Nodes),
    aggregate_all(count, node_(Tree, _, leaf(_, _)), Leaves),
    aggregate_all(sum(L), ( node_(Tree, _, leaf(_, Es)), length(Es, L) ), Entries).

%!  qtree_put_entry(+Entries0, +Entry, -Entries) is det.
%
%   Replace the entry for Entry's action and necessity (or add it) and keep the list in
%   decreasing Q (ties keep their order).

qtree_put_entry(Entries0, e(A, Q, N), Entries) :-
    exclude(same_key(A, N), Entries0, Entries1),
    insert_by_q(Entries1, e(A, Q, N), Entries).

same_key(A, N, e(A1, _, N1)) :-
    A1 == A, N1 == N.

insert_by_q([], E, [E]).
insert_by_q([E0|Es], E, Out) :-
    E = e(_, Q, _),
    E0 = e(_, Q0, _),
    (   Q > Q0
    ->  Out = [E, E0|Es]
    ;   Out = [E0|Out1],
        insert_by_q(Es, E, Out1)
    ).

%!  qtree_entry_q(+Entries, +Action, +Necessity, +Default, -Q) is det.

qtree_entry_q(Entries, A, N, Default, Q) :-
    (   member(e(A1, Q0, N1), Entries), A1 == A, N1 == N
    ->  Q = Q0
    ;   Q = Default
    ).

%!  qtree_format(+Tree, -Text:string) is det.
%
%   Text draws Tree: one line per node, indented by depth; a test node shows its goal and
%   its yes/no branches, a leaf its entries in decreasing Q.

qtree_format(Tree, Text) :-
    with_output_to(string(Text), format_node(Tree, 0, "", "")).

format_node(Tree, Id, Indent, Label) :-
    node_(Tree, Id, Node),
    (   Node = test(_, Goal, Yes, No)
    ->  format("~w~w[~d] ~q ?~n", [Indent, Label, Id, Goal]),
        string_concat(Indent, "    ", Deeper),
        format_branch(Tree, Yes, Deeper, "yes: "),
        format_branch(Tree, No, Deeper, "no:  ")
    ;   Node = leaf(Rep, Entries),
        format("~w~wleaf [~d] state ~w~n", [Indent, Label, Id, Rep]),
        string_concat(Indent, "      ", Deeper),
        forall(member(e(A, Q, N), Entries),
               format("~w~q  Q=~4f  [~q]~n", [Deeper, A, Q, N]))
    ).

format_branch(_, nil, Indent, Label) :-
    !,
    format("~w~wnull~n", [Indent, Label]).
format_branch(Tree, Id, Indent, Label) :-
    format_node(Tree, Id, Indent, Label).

%!  qtree_graph(+Tree, -Graph) is det.
%
%   Graph is graph(Nodes, Edges) for drawing Tree: node(Id, test, Label) for a test node
%   (Label its goal as text), node(Id, leaf, Label) for a leaf (its entries, best first),
%   node(nil(Parent, Branch), null, "null") for an empty branch, and edge(From, To, yes|no).

qtree_graph(Tree, graph(Nodes, Edges)) :-
    findall(N, graph_node(Tree, N), Nodes),
    findall(E, graph_edge(Tree, E), Edges).

graph_node(Tree, node(Id, test, Label)) :-
    node_(Tree, Id, test(_, Goal, _, _)),
    format(string(Label), "~q", [Goal]).
graph_node(Tree, node(Id, leaf, Label)) :-
    node_(Tree, Id, leaf(_, Entries)),
    findall(L, ( member(e(A, Q, N), Entries),
                 format(string(L), "~q ~2f [~q]", [A, Q, N]) ), Lines),
    atomic_list_concat(Lines, '\n', Atom),
    atom_string(Atom, Label).
graph_node(Tree, node(nil(Id, Branch), null, "null")) :-
    node_(Tree, Id, test(_, _, Yes, No)),
    member(Branch-nil, [yes-Yes, no-No]).

graph_edge(Tree, edge(Id, To, Branch)) :-
    node_(Tree, Id, test(_, _, Yes, No)),
    member(Branch-Child, [yes-Yes, no-No]),
    (   Child == nil
    ->  To = nil(Id, Branch)
    ;   To = Child
    ).
