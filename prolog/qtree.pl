:- module(relrl_qtree,
          [ qtree_new/2,          % +KB, +Tests
            qtree_restore/3,      % +KB, +Tests, +Nodes
            qtree_clear/1,        % +KB
            qtree/2,              % +KB, -Tree
            qtree_tests/2,        % +Tree, -Tests
            qtree_sort/3,         % +Tree, +Description, -Where
            qtree_leaf/4,         % +Tree, ?Id, -Rep, -Entries
            qtree_set_leaf/4,     % +Tree, +Id, +Rep, +Entries
            qtree_grow/6,         % +Tree, +Parent, +Branch, +Rep, +Entries, -Id
            qtree_split/3,        % +Tree, +LeafId, +TestIndex
            qtree_path/3,         % +Tree, +Description, -Path
            qtree_size/4,         % +Tree, -Nodes, -Leaves, -Entries
            qtree_node/3,         % +Tree, ?Id, ?Node
            qtree_format/2,       % +Tree, -Text
            qtree_graph/2,        % +Tree, -Graph
            qtree_put_entry/3,    % +Entries0, +Entry, -Entries
            qtree_entry_q/5,      % +Entries, +Action, +Necessity, +Default, -Q
            test_holds/2,         % +Description, +TestIndex
            first_difference/3    % +Description1, +Description2, -TestIndex
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(kbstate).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

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

A node is test(Index, Goal, Yes, No) or leaf(Rep, Entries); Rep is `none` until the first
example arrives. Id 0 is the root.

A tree is one term, the `tree` part of the record (kbstate.pl) of the knowledge base it
belongs to, qtree(Tests, Next, Nodes, Memo): Next is the next node id and Nodes a compound
nodes(Node0, Node1, ...) whose argument Id+1 holds node Id (`free` beyond the last). Memo
remembers where the last two states sorted went (see qtree_sort/3). The control step reads
nodes in place (arg/3, no copy: sorting a state down the tree is a few argument look-ups)
and replaces a leaf in place (nb_setarg/3, which copies only that leaf); a full Nodes is
copied into one twice its size. What this module gives to callers that may bind variables
(qtree_node/3, qtree_tests/2, the goals of qtree_path/3) is a copy (copy_term/2 shares
ground parts).

qtree_new/2, qtree_restore/3 and qtree_clear/1 make, replace and forget the tree of a
knowledge base; qtree/2 gives its tree term, which every other predicate of this module
takes and reads or changes in place: a learner's hook finds it once (with its own state,
in the same look-up of the knowledge base's record) and sorts, reads and updates it as
often as the step needs.
*/

%!  qtree(+KB, -Tree) is det.
%
%   Tree is KB's tree (the stored term itself).
%
%   @error existence_error(qtree, KB) if KB has no tree.

qtree(KB, Tree) :-
    kb_get(KB, tree, T),
    (   T = qtree(_, _, _, _)
    ->  Tree = T
    ;   existence_error(qtree, KB)
    ).

%   Tree is a tree term (a learner's hook may hold `none`: the tree was never made).
the_tree(Tree) :-
    (   Tree = qtree(_, _, _, _)
    ->  true
    ;   existence_error(qtree, Tree)
    ).

node(Nodes, Id, Node) :-
    I is Id + 1,
    arg(I, Nodes, Node).

%   Node Id of tree T, which must exist.
existing_node(T, Id, Node) :-
    T = qtree(_, Next, Nodes, _),
    (   integer(Id), Id >= 0, Id < Next
    ->  node(Nodes, Id, Node)
    ;   existence_error(qtree_node, Id)
    ).

set_node(T, Id, Node) :-
    arg(3, T, Nodes),
    I is Id + 1,
    nb_setarg(I, Nodes, Node).

%   A new node id in T (Nodes grows when full).
new_id(T, Id) :-
    T = qtree(_, Id, Nodes, _),
    Next is Id + 1,
    functor(Nodes, _, Capacity),
    (   Next =< Capacity
    ->  true
    ;   Bigger is 2 * Capacity,
        nodes_term(Bigger, Nodes1),
        forall(between(1, Capacity, I),
               ( arg(I, Nodes, Node), nb_setarg(I, Nodes1, Node) )),
        nb_setarg(3, T, Nodes1)
    ),
    nb_setarg(2, T, Next).

nodes_term(Capacity, Nodes) :-
    functor(Nodes, nodes, Capacity),
    forall(between(1, Capacity, I), nb_setarg(I, Nodes, free)).

%!  qtree_new(+KB, +Tests:list) is det.
%
%   Make KB's tree a single empty leaf with the candidate Tests (goals, in index order).

qtree_new(KB, Tests) :-
    must_be(list, Tests),
    qtree_restore_(KB, Tests, [0-leaf(none, [])], 1).

%!  qtree_restore(+KB, +Tests, +Nodes:list) is det.
%
%   Make KB's tree the tree given by Nodes, a list of Id-Node pairs as saved by the engine.
%
%   @error domain_error(qtree, Nodes) if there is no root (Id 0).
%   @error domain_error(qtree_node_id, Id) if two nodes have the same Id.

qtree_restore(KB, Tests, Nodes) :-
    must_be(list, Nodes),
    (   memberchk(0-_, Nodes)
    ->  true
    ;   domain_error(qtree, Nodes)
    ),
    aggregate_all(max(Id), member(Id-_, Nodes), Max),
    Next is Max + 1,
    qtree_restore_(KB, Tests, Nodes, Next).

qtree_restore_(KB, Tests, Nodes, Next) :-
    must_be(atom, KB),
    Capacity is max(16, Next),
    nodes_term(Capacity, Term),
    forall(member(Id-Node, Nodes),
           (   node(Term, Id, free)
           ->  I is Id + 1,
               nb_setarg(I, Term, Node)
           ;   domain_error(qtree_node_id, Id)
           )),
    kb_set(KB, tree, qtree(Tests, Next, Term, none)).

%!  qtree_clear(+KB) is det.
%
%   Forget KB's tree.

qtree_clear(KB) :-
    kb_set(KB, tree, none).

%!  qtree_tests(+Tree, -Tests:list) is det.

qtree_tests(Tree, Tests) :-
    the_tree(Tree),
    Tree = qtree(Tests0, _, _, _),
    copy_term(Tests0, Tests).

%!  qtree_node(+Tree, ?Id, ?Node) is nondet.

qtree_node(Tree, Id, Node) :-
    the_tree(Tree),
    Tree = qtree(_, Next, Nodes, _),
    (   integer(Id)
    ->  Id >= 0, Id < Next
    ;   Last is Next - 1,
        between(0, Last, Id)
    ),
    node(Nodes, Id, Node0),
    Node0 \== free,
    copy_term(Node0, Node).

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
%
%   @error existence_error(qtree, Tree) if Tree is not a tree.

qtree_sort(T, D, Where) :-
    the_tree(T),
    T = qtree(_, Version, Nodes, Memo),
    (   Memo = memo(Version, D1, W1, D2, W2)
    ->  (   D1 =:= D
        ->  Where = W1
        ;   D2 =:= D
        ->  Where = W2
        ;   sort_root(Nodes, D, Where),
            nb_setarg(4, T, memo(Version, D, Where, D1, W1))
        )
    ;   sort_root(Nodes, D, Where),
        nb_setarg(4, T, memo(Version, D, Where, -1, none))
    ).

%   The memo: the control step sorts each state three times (to learn, as the next state
%   of the previous example; to choose; then, at the next step, to insert its example).
%   It holds while the tree's shape does: every grow or split takes a new node id, so the
%   next id is the shape's version.

sort_root(Nodes, D, Where) :-
    arg(1, Nodes, Root),
    sort_from(Root, 0, Nodes, D, Where).

sort_from(test(I, _, Yes, No), Id, Nodes, D, Where) :-
    !,
    (   D /\ (1 << I) =\= 0
    ->  down(Yes, yes, Id, Nodes, D, Where)
    ;   down(No, no, Id, Nodes, D, Where)
    ).
sort_from(_, Id, _, _, leaf(Id)).

down(nil, Branch, Id, _, _, null(Id, Branch)) :- !.
down(Next, _, _, Nodes, D, Where) :-
    I is Next + 1,
    arg(I, Nodes, Node),
    sort_from(Node, Next, Nodes, D, Where).

%   Id is a test node; the state described by D takes its Branch (yes or no) to Next.
step_down(Nodes, Id, D, Goal, Branch, Next) :-
    node(Nodes, Id, test(I, Goal, Yes, No)),
    (   test_holds(D, I)
    ->  Branch = yes, Next = Yes
    ;   Branch = no, Next = No
    ).

%!  qtree_path(+Tree, +Description, -Path:list) is det.
%
%   Path lists Goal-Outcome pairs (Outcome true or false) from the root to where the state
%   ends, followed by leaf(Id) or null.

qtree_path(Tree, D, Path) :-
    the_tree(Tree),
    Tree = qtree(_, _, Nodes, _),
    path_from(Nodes, 0, D, Path0),
    copy_term(Path0, Path).

path_from(Nodes, Id, D, Path) :-
    (   step_down(Nodes, Id, D, Goal, Branch, Next)
    ->  ( Branch == yes -> Outcome = true ; Outcome = false ),
        Path = [Goal-Outcome|Rest],
        (   Next == nil
        ->  Rest = [null]
        ;   path_from(Nodes, Next, D, Rest)
        )
    ;   Path = [leaf(Id)]
    ).

%!  qtree_leaf(+Tree, ?Id, -Rep, -Entries) is nondet.
%
%   Leaf Id of Tree. With Id given, Rep and Entries are the tree's own (not copied: the
%   control step reads them every time unit); they are ground.
%
%   @error existence_error(qtree, Tree) if Tree is not a tree (as qtree_node/3).

qtree_leaf(Tree, Id, Rep, Entries) :-
    (   integer(Id),
        Tree = qtree(_, Next, Nodes, _)
    ->  Id >= 0, Id < Next,
        node(Nodes, Id, leaf(Rep, Entries))
    ;   qtree_node(Tree, Id, leaf(Rep, Entries))    % raises for a term that is no tree
    ).

%!  qtree_set_leaf(+Tree, +Id, +Rep, +Entries) is det.
%
%   @error existence_error(qtree_leaf, Id) if node Id is not a leaf.

qtree_set_leaf(T, Id, Rep, Entries) :-
    (   T = qtree(_, Next, Nodes, _),
        integer(Id), Id >= 0, Id < Next,
        node(Nodes, Id, leaf(_, _))
    ->  set_node(T, Id, leaf(Rep, Entries))
    ;   the_tree(T),
        existence_error(qtree_leaf, Id)
    ).

%!  qtree_grow(+Tree, +Parent, +Branch, +Rep, +Entries, -Id) is det.
%
%   Generate a leaf on the empty Branch (yes or no) of the test node Parent.

qtree_grow(T, Parent, Branch, Rep, Entries, Id) :-
    must_be(oneof([yes, no]), Branch),
    the_tree(T),
    existing_node(T, Parent, Node0),
    (   Node0 = test(I, Goal, Yes, No)
    ->  true
    ;   domain_error(qtree_test_node, Parent)
    ),
    (   Branch == yes
    ->  must_be(oneof([nil]), Yes)
    ;   must_be(oneof([nil]), No)
    ),
    new_id(T, Id),
    (   Branch == yes
    ->  Node = test(I, Goal, Id, No)
    ;   Node = test(I, Goal, Yes, Id)
    ),
    set_node(T, Parent, Node),
    set_node(T, Id, leaf(Rep, Entries)).

%!  qtree_split(+Tree, +LeafId, +TestIndex) is det.
%
%   Turn leaf LeafId into a test node on test TestIndex. The leaf moves to the branch its
%   representative takes; the other branch is empty (nil).

qtree_split(T, LeafId, I) :-
    the_tree(T),
    existing_node(T, LeafId, Leaf),
    (   Leaf = leaf(Rep, Entries)
    ->  true
    ;   existence_error(qtree_leaf, LeafId)
    ),
    T = qtree(Tests, _, _, _),
    nth0(I, Tests, Goal),
    new_id(T, Id),
    (   test_holds(Rep, I)
    ->  Node = test(I, Goal, Id, nil)
    ;   Node = test(I, Goal, nil, Id)
    ),
    set_node(T, LeafId, Node),
    set_node(T, Id, leaf(Rep, Entries)).

%!  qtree_size(+Tree, -Nodes, -Leaves, -Entries) is det.
%
%   Nodes counts internal nodes and leaves; Entries the stored (action, Q, necessity)
%   entries. The paper's memory in "positions" is Nodes + Entries.

qtree_size(Tree, Nodes, Leaves, Entries) :-
    aggregate_all(count, qtree_node(Tree, _, _), Nodes),
    aggregate_all(count, qtree_node(Tree, _, leaf(_, _)), Leaves),
    aggregate_all(sum(L), ( qtree_node(Tree, _, leaf(_, Es)), length(Es, L) ), Entries).

%!  qtree_put_entry(+Entries0, +Entry, -Entries) is det.
%
%   Replace the entry for Entry's action and necessity (or add it) and keep the list in
%   decreasing Q (ties keep their order).

qtree_put_entry(Entries0, e(A, Q, N), Entries) :-
    put_entry(Entries0, A, Q, N, Entries).

%   One pass: the entry for (A, N) left out, e(A, Q, N) put before the first remaining
%   entry of smaller Q.
put_entry([], A, Q, N, [e(A, Q, N)]).
put_entry([E0|Es], A, Q, N, Out) :-
    E0 = e(A0, Q0, N0),
    (   A0 == A, N0 == N
    ->  put_entry(Es, A, Q, N, Out)
    ;   Q > Q0
    ->  Out = [e(A, Q, N), E0|Rest],
        drop_key(Es, A, N, Rest)
    ;   Out = [E0|Out1],
        put_entry(Es, A, Q, N, Out1)
    ).

drop_key([], _, _, []).
drop_key([E0|Es], A, N, Out) :-
    E0 = e(A0, _, N0),
    (   A0 == A, N0 == N
    ->  Out = Out1
    ;   Out = [E0|Out1]
    ),
    drop_key(Es, A, N, Out1).

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
    qtree_node(Tree, Id, Node),
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
    qtree_node(Tree, Id, test(_, Goal, _, _)),
    format(string(Label), "~q", [Goal]).
graph_node(Tree, node(Id, leaf, Label)) :-
    qtree_node(Tree, Id, leaf(_, Entries)),
    findall(L, ( member(e(A, Q, N), Entries),
                 format(string(L), "~q ~2f [~q]", [A, Q, N]) ), Lines),
    atomic_list_concat(Lines, '\n', Atom),
    atom_string(Atom, Label).
graph_node(Tree, node(nil(Id, Branch), null, "null")) :-
    qtree_node(Tree, Id, test(_, _, Yes, No)),
    member(Branch-nil, [yes-Yes, no-No]).

graph_edge(Tree, edge(Id, To, Branch)) :-
    qtree_node(Tree, Id, test(_, _, Yes, No)),
    member(Branch-Child, [yes-Yes, no-No]),
    (   Child == nil
    ->  To = nil(Id, Branch)
    ;   To = Child
    ).
